"""Paper `hinf` (003): T. R. Nelson, R. A. Freeman, *Decentralized H-infinity Filtering in a Multi-Agent System*.

Pipeline steps (called by ``workflow/rules/hinf.smk``), figures, claims,
errata and reconstructions. The mathematics lives in
:mod:`netrepro.papers.hinf_core` (re-exported here).

Scenarios (``config['hinf']['scenarios']``; the ``scenario`` column of the tables)
--------------------------------------------------------------------------------
``fig2`` / ``fig3``: ten stationary agents, random-walk target, W = 0.01 I / 0.001 I (Figs 2-3);
``static_fixed`` / ``static_mobile``: stationary target, stationary / mobile agents (Figs 4-5);
``evasive_hinf`` / ``evasive_kalman``: four mobile agents, evasive target, agents driven by decentralized
H-infinity / Kalman filters (Fig 6 and the comparison beyond the paper). Filters: ``local``,
``decentralized``, ``centralized`` and their ``kalman_*`` counterparts (gamma = infinity).

Tables (all under ``results/hinf/``)
------------------------------------
``noise_model.csv``  (Fig 1)
    ``sensor, x, y, r, theta, f_r, f_b, sigma_major, sigma_minor, angle`` — three sensors
    around a target at the origin; ``sigma_*`` are the 1-sigma semi-axes of ``M_i`` (eq (3)-(4)).
``noise_fit.csv``
    ``r, var_range, var_bearing, f_r_model, f_b_model, n_samples`` — empirical variances of
    sampled noise (eq (3)) along and across the line of sight, and the model (4).
``consensus_check.csv``
    ``h, steady_state_error, stable, spectral_radius, h_max`` — eq (5) on the Fig-2 graph
    with constant random inputs: max over agents and components of ``|v_i - mean(u)|`` after
    ``n_iter`` steps (inf/nan when diverged); ``stable`` from the spectral radius (< 1).
``attenuation.csv``
    ``filter, gamma0, gamma_used, margin, exists_at_used, status_below`` — minimum
    attenuation level of eq (6) for the Fig-2 geometry (local: worst agent; centralized),
    and what the simulation reports at ``0.9 gamma0``.
``filter_checks.csv``
    ``check, value, note`` — gamma -> infinity vs Kalman, exact consensus vs centralized.
``sim/<scenario>_*.csv``
    Per-scenario pieces, concatenated into:
``errors.csv``
    ``scenario, filter, k, error_mean, error_lo, error_hi`` — ``|xhat - x|`` mean over runs
    and agents, ``lo``/``hi`` the ``band`` quantiles (default 10 % / 90 %) over runs x agents.
``errors_single.csv``
    ``scenario, filter, run, agent, k, error`` — one agent in one run, as the paper plots.
``trajectories.csv``
    ``scenario, run, k, who, x, y`` — ``who`` is ``target`` or the agent id; first runs only.
``summary.csv``
    ``scenario, filter, late_mean, late_se, late_rmse, settle_k, total_variation, range_error_start,
    range_error_end, connected_fraction, max_degree, fused_trace_late, n_runs`` — ``late_*`` over
    ``k >= late_start`` (``late_se`` standard error over runs), ``settle_k`` first step after which
    the mean error stays below ``settle_threshold``, ``total_variation`` mean over runs x agents
    of ``sum_k |e_k - e_{k-1}| / K``, ``range_error`` mean ``|r_i - a1|`` at k = 0 and K.
``paired.csv``
    ``comparison, scenario_a, filter_a, scenario_b, filter_b, mean_diff, se_diff, z`` — paired
    (same seeds) per-run late-error differences ``a - b``.
``sensitivity.csv``
    ``parameter, value, W, scenario, exists, consensus_stable, local_error, decentralized_error,
    centralized_error, ratio_dec_local, settle_k`` — one-at-a-time sweeps of the main reconstructions
    (late-window mean errors; in mobile scenarios ``decentralized_error`` is the error of the filter driving
    the agents).
``sensitivity_evasive.csv``
    same columns: ``parameter = gamma_evasive``, the H-infinity gamma against the evasive target
    (``value = inf``: the Kalman-driven scenario ``evasive_kalman``).
"""

from __future__ import annotations

import json
import math

import numpy as np
import pandas as pd

from ..claims import claim_row, claims_frame, errata_frame, reconstructions_frame
from ..config import ConfigError, require_matrix, require_pd
from .hinf_core import *  # noqa: F401,F403
from .hinf_core import (FILTER_KINDS, FilterDoesNotExist, NoiseModel, adjacency, consensus_h_max, control_law,
                        decentralized_update, geometry, hinf_update, kalman_update, laplacian, minimum_attenuation,
                        noise_covariance, noise_information, noise_variances, pi_consensus_spectral_radius,
                        printed_control_law, printed_dinfo_dtheta, printed_sigma_gradient, rotation, run_pi_consensus,
                        sample_noise, sigma_gradient, simulate)

PAPER = "hinf"
PAIRED = {  # comparison -> (scenario a, filter a, scenario b, filter b); difference a - b per run
    "fig2_dec_vs_local": ("fig2", "decentralized", "fig2", "local"),
    "fig3_dec_vs_local": ("fig3", "decentralized", "fig3", "local"),
    "fig4_mobile_dec_vs_stationary_local": ("static_mobile", "decentralized", "static_fixed", "local"),
    "fig5_mobile_vs_stationary": ("static_mobile", "decentralized", "static_fixed", "decentralized"),
    "fig2_hinf_vs_kalman_dec": ("fig2", "decentralized", "fig2", "kalman_decentralized"),
    "fig2_hinf_vs_kalman_local": ("fig2", "local", "fig2", "kalman_local"),
    "evasive_hinf_vs_kalman": ("evasive_hinf", "decentralized", "evasive_kalman", "kalman_decentralized"),
    "evasive_hinf_vs_kalman_central": ("evasive_hinf", "centralized", "evasive_kalman", "kalman_centralized"),
}
SCENARIOS = ("fig2", "fig3", "static_fixed", "static_mobile", "evasive_hinf", "evasive_kalman")


# --------------------------------------------------------------------------- configuration
def check_config(section: dict) -> None:
    """Checks the schema cannot express: matrix shapes, positive definiteness, scenario references."""
    f = section["filter"]
    require_matrix("hinf.filter.A", f["A"], shape=(2, 2))
    require_matrix("hinf.filter.L", f["L"], shape=(2, 2))
    require_pd("hinf.filter.Q", f["Q"], semi=True)
    for name, sc in section["scenarios"].items():
        if sc["layout"] not in section["layouts"]:
            raise ConfigError(f"config key 'hinf.scenarios.{name}.layout' = {sc['layout']!r} is not a key of hinf.layouts")
        if sc.get("mobile") and sc.get("driver") not in sc["filters"]:
            raise ConfigError(f"config key 'hinf.scenarios.{name}.driver' = {sc.get('driver')!r} must be one of its filters")
        if sc.get("mobile") and FILTER_KINDS[sc["driver"]][0] != "decentralized":
            raise ConfigError(f"config key 'hinf.scenarios.{name}.driver' must be a decentralized filter")
    if section["consensus_check"]["layout"] not in section["layouts"]:
        raise ConfigError("config key 'hinf.consensus_check.layout' is not a key of hinf.layouts")


def layout_positions(spec: dict) -> np.ndarray:
    """Agent positions on an arc around the origin: ``n`` agents, radius, angular spacing, start angle (deg)."""
    ang = np.deg2rad(spec["start_deg"] + spec["spacing_deg"] * np.arange(spec["n"]))
    return np.stack([spec["radius"] * np.cos(ang), spec["radius"] * np.sin(ang)], -1)


def resolve_scenario(cfg: dict, name: str, **overrides) -> dict:
    """The dict :func:`hinf_core.simulate` takes, from the config section and a scenario name."""
    sc = dict(cfg["scenarios"][name])
    sc.update({k: v for k, v in overrides.items() if k in sc or k in ("runs", "horizon", "seed")})
    f = dict(cfg["filter"])
    f.update(overrides.get("filter", {}))
    cons = dict(cfg["consensus"])
    cons.update(overrides.get("consensus", {}))
    ctrl = dict(cfg["control"])
    ctrl.update(overrides.get("control", {}))
    L = np.asarray(f["L"], dtype=float)
    W = float(sc["W"])
    return {
        "agents0": layout_positions(cfg["layouts"][sc["layout"]]), "target0": np.zeros(2), "target": sc["target"],
        "W_true": W * np.eye(2), "W_filter": float(sc["W_filter"]) * np.eye(2), "A": np.asarray(f["A"], dtype=float),
        "gamma": float(f["gamma"]), "Lbar": L.T @ np.asarray(f["Q"], dtype=float) @ L, "P0": float(f["P0"]),
        "psd_floor": float(f["psd_floor"]), "model": NoiseModel.from_config(cfg["noise"]),
        "radius": float(cfg["comm_radius"]), "consensus": cons, "control": ctrl, "mobile": bool(sc["mobile"]),
        "driver": sc.get("driver", "decentralized"),
        "evader": {"n_headings": cfg["evader"]["n_headings"], "n_iter": cfg["evader"]["n_iter"],
                   "step": cfg["evader"]["step_scale"] * math.sqrt(2 * W)},
        "filters": list(sc["filters"]), "horizon": int(sc["horizon"]), "runs": int(sc["runs"]), "seed": int(sc["seed"]),
    }


# --------------------------------------------------------------------------- noise model (Fig 1)
def noise_model_step(params, inputs, outputs):
    """Fig-1 ellipses and an empirical check of eqs (3)-(4) by sampling."""
    model = NoiseModel.from_config(params["noise"])
    nc = params["noise_check"]
    rows = []
    for i, (r, b) in enumerate(zip(nc["fig1_ranges"], nc["fig1_bearings_deg"])):
        # sensor placed at distance r from a target at the origin, seeing it under bearing theta = angle(x - p)
        th = np.deg2rad(b)
        p = -r * np.array([np.cos(th), np.sin(th)])
        fr, fb = noise_variances(r, model)
        rows.append({"sensor": i, "x": p[0], "y": p[1], "r": r, "theta": th, "f_r": float(fr), "f_b": float(fb),
                     "sigma_major": math.sqrt(max(fr, fb)), "sigma_minor": math.sqrt(min(fr, fb)),
                     "angle": th if fr >= fb else th + np.pi / 2})
    rng = np.random.default_rng(int(nc["seed"]))
    fit = []
    th = float(nc["theta"])
    for r in nc["r_grid"]:
        m = sample_noise(rng, np.full(int(nc["n_samples"]), float(r)), np.full(int(nc["n_samples"]), th), model)
        local = m @ rotation(th)  # rows m^T T = (T^T m)^T: components along / across the line of sight
        fr, fb = noise_variances(r, model)
        fit.append({"r": r, "var_range": local[:, 0].var(), "var_bearing": local[:, 1].var(), "f_r_model": float(fr),
                    "f_b_model": float(fb), "n_samples": int(nc["n_samples"])})
    return {"table": pd.DataFrame(rows), "fit": pd.DataFrame(fit)}


def fit_noise_model(fit: pd.DataFrame) -> dict:
    """Recover ``a0, a1, a2, alpha`` from empirical variances by least squares on eq (4)."""
    r = fit["r"].to_numpy(float)
    c2, c1, c0 = np.polyfit(r, fit["var_range"].to_numpy(float), 2)
    a2 = c2
    a1 = -c1 / (2 * c2)
    a0 = c0 - c2 * a1 ** 2
    alpha = float(np.sum(fit["var_bearing"]) / np.sum(fit["var_range"]))
    return {"a0": a0, "a1": a1, "a2": a2, "alpha": alpha}


# --------------------------------------------------------------------------- consensus (5)
def consensus_check_step(params, inputs, outputs):
    """Stability range of the step h of eq (5) and the steady-state error with constant inputs."""
    cc, cons = params["consensus_check"], params["consensus"]
    ag = layout_positions(params["layouts"][cc["layout"]])
    lap = laplacian(adjacency(ag, params["comm_radius"]))
    rng = np.random.default_rng(int(cc["seed"]))
    u = rng.normal(size=(ag.shape[0], 6))
    target = u.mean(0)
    hmax = consensus_h_max(lap, cons["gamma_c"], cons["K_p"], cons["K_i"])
    rows = []
    for h in cc["h_grid"]:
        rho = pi_consensus_spectral_radius(lap, cons["gamma_c"], h, cons["K_p"], cons["K_i"])
        v = run_pi_consensus(u, lap, cons["gamma_c"], h, cons["K_p"], cons["K_i"], int(cc["n_iter"]))
        err = float(np.max(np.abs(v - target))) if np.all(np.isfinite(v)) else np.inf
        rows.append({"h": h, "steady_state_error": err, "stable": bool(rho < 1.0), "spectral_radius": rho, "h_max": hmax})
    return {"table": pd.DataFrame(rows), "provenance": {"h_max": hmax}}


# --------------------------------------------------------------------------- filters: gamma_0, limits
def _fig2_information(cfg):
    model = NoiseModel.from_config(cfg["noise"])
    ag = layout_positions(cfg["layouts"][cfg["scenarios"]["fig2"]["layout"]])
    r, th = geometry(np.zeros(2), ag)
    return noise_information(r, th, model)


def attenuation_step(params, inputs, outputs):
    """Minimum attenuation level gamma_0 of eq (6), filter existence, and the two filter identities."""
    cfg = params
    f = cfg["filter"]
    at = cfg["attenuation"]
    L = np.asarray(f["L"], float)
    Lbar = L.T @ np.asarray(f["Q"], float) @ L
    A = np.asarray(f["A"], float)
    W = float(cfg["scenarios"]["fig2"]["W_filter"]) * np.eye(2)
    Minv = _fig2_information(cfg)
    K = int(at["horizon"])
    Sig0 = float(f["P0"]) * np.eye(2)
    g_local = minimum_attenuation(np.broadcast_to(Minv, (K,) + Minv.shape), Sig0, A, W, Lbar)
    g_cent = minimum_attenuation(np.broadcast_to(Minv.sum(0), (K, 2, 2)), Sig0, A, W, Lbar)
    rows = []
    for name, g0 in (("local", g_local), ("centralized", g_cent)):
        sc = resolve_scenario(cfg, "fig2")
        sc.update(runs=int(at["runs"]), horizon=K, filters=[name])
        status = {}
        for label, gamma in (("used", float(f["gamma"])), ("below", 0.9 * g0)):
            sc["gamma"] = gamma
            try:
                simulate(sc)
                status[label] = "exists"
            except FilterDoesNotExist:
                status[label] = "does_not_exist"
        rows.append({"filter": name, "gamma0": g0, "gamma_used": float(f["gamma"]), "margin": float(f["gamma"]) / g0,
                     "exists_at_used": status["used"] == "exists", "status_below": status["below"]})
    # identities: gamma -> infinity vs Kalman; exact consensus vs centralized
    rng = np.random.default_rng(int(at["seed"]))
    model = NoiseModel.from_config(cfg["noise"])
    ag = layout_positions(cfg["layouts"][cfg["scenarios"]["fig2"]["layout"]])
    n = ag.shape[0]
    x = np.zeros((at["runs"], 2))
    xh_h, S_h = x + rng.normal(size=x.shape), np.broadcast_to(Sig0, (at["runs"], 2, 2)).copy()
    xh_k, P_k = xh_h.copy(), S_h.copy()
    xh_d, S_d = xh_h.copy(), S_h.copy()
    d_kal = d_dec = 0.0
    for _ in range(50):
        x = x + rng.normal(scale=0.1, size=x.shape)
        r, th = geometry(x, np.broadcast_to(ag, (len(x),) + ag.shape))
        Mi = noise_information(r, th, model)
        M = noise_covariance(r, th, model)
        y = x[:, None, :] + sample_noise(rng, r, th, model)
        yinfo = (Mi @ y[..., None])[..., 0]
        xh_h, S_h, _, _ = hinf_update(xh_h, S_h, yinfo.sum(1), Mi.sum(1), A, W, float(at["gamma_large"]) ** -2, Lbar)
        xh_k, P_k = kalman_update(xh_k, P_k, y, M, A, W)
        xc, Sc, _, _ = hinf_update(xh_d, S_d, yinfo.sum(1), Mi.sum(1), A, W, float(f["gamma"]) ** -2, Lbar)
        xh_d, S_d, _, _ = decentralized_update(xh_d, S_d, yinfo.mean(1), Mi.mean(1), n, A, W, float(f["gamma"]) ** -2, Lbar)
        d_kal = max(d_kal, float(np.max(np.abs(xh_h - xh_k))), float(np.max(np.abs(S_h - P_k))))
        d_dec = max(d_dec, float(np.max(np.abs(xh_d - xc))), float(np.max(np.abs(S_d - Sc))))
    checks = pd.DataFrame([
        {"check": "hinf_vs_kalman_max_abs_diff", "value": d_kal,
         "note": f"eq (6) with gamma={at['gamma_large']:g} vs textbook Kalman filter, 50 steps, {at['runs']} runs"},
        {"check": "decentralized_exact_vs_centralized_max_abs_diff", "value": d_dec,
         "note": "eq (9) fed the exact averages (7)-(8) vs eq (6), same gamma"},
    ])
    return {"table": pd.DataFrame(rows), "checks": checks, "provenance": {"gamma0_local": g_local, "gamma0_central": g_cent}}


# --------------------------------------------------------------------------- simulations (Figs 2-6)
def _late(errors, start):
    return errors[..., start:]


def scenario_tables(name: str, out: dict, sc: dict, cfg: dict) -> dict:
    """Reduce one :func:`simulate` output to the tables of the module docstring."""
    oc, cl = cfg["output"], cfg["claims"]
    lo_q, hi_q = oc["band"]
    K = sc["horizon"]
    start = min(int(cl["late_start"]), K)
    model = sc["model"]
    err_rows, single_rows, summ_rows = [], [], []
    r0, _ = geometry(out["target"][:, 0], out["agents"][:, 0])
    rK, _ = geometry(out["target"][:, -1], out["agents"][:, -1])
    fused = out["fused_trace"]
    for fname, e in out["errors"].items():
        flat = e.reshape(-1, K + 1)
        mean = flat.mean(0)
        lo, hi = np.quantile(flat, [lo_q, hi_q], axis=0)
        err_rows.append(pd.DataFrame({"scenario": name, "filter": fname, "k": np.arange(K + 1), "error_mean": mean,
                                      "error_lo": lo, "error_hi": hi}))
        agent = min(int(oc["single_agent"]), e.shape[1] - 1)
        single_rows.append(pd.DataFrame({"scenario": name, "filter": fname, "run": int(oc["single_run"]), "agent": agent,
                                         "k": np.arange(K + 1), "error": e[int(oc["single_run"]), agent]}))
        per_run = _late(e, start).mean(axis=(1, 2))
        below = mean <= float(cl["settle_threshold"])
        settle = next((k for k in range(K + 1) if below[k:].all()), -1)
        summ_rows.append({
            "scenario": name, "filter": fname, "late_mean": per_run.mean(),
            "late_se": per_run.std(ddof=1) / math.sqrt(len(per_run)) if len(per_run) > 1 else np.nan,
            "late_rmse": math.sqrt(float(np.mean(_late(e, start) ** 2))), "settle_k": settle,
            "total_variation": float(np.abs(np.diff(e, axis=-1)).sum(-1).mean() / K),
            "range_error_start": float(np.abs(r0 - model.a1).mean()), "range_error_end": float(np.abs(rK - model.a1).mean()),
            "connected_fraction": float(out["connected"].mean()), "max_degree": out["max_degree"],
            "fused_trace_late": float(np.nanmean(fused[:, start:])) if np.any(np.isfinite(fused[:, start:])) else np.nan,
            "n_runs": e.shape[0],
        })
    traj = []
    for run in range(min(int(oc["traj_runs"]), sc["runs"])):
        ks = np.arange(K + 1)
        traj.append(pd.DataFrame({"scenario": name, "run": run, "k": ks, "who": "target",
                                  "x": out["target"][run, :, 0], "y": out["target"][run, :, 1]}))
        for i in range(out["agents"].shape[2]):
            traj.append(pd.DataFrame({"scenario": name, "run": run, "k": ks, "who": str(i),
                                      "x": out["agents"][run, :, i, 0], "y": out["agents"][run, :, i, 1]}))
    per_run = {f: _late(e, start).mean(axis=(1, 2)) for f, e in out["errors"].items()}
    return {"errors": pd.concat(err_rows, ignore_index=True), "single": pd.concat(single_rows, ignore_index=True),
            "trajectories": pd.concat(traj, ignore_index=True), "summary": pd.DataFrame(summ_rows),
            "per_run": pd.DataFrame({"scenario": name, **{f: v for f, v in per_run.items()}, "run": np.arange(sc["runs"])})}


def simulate_step(params, inputs, outputs):
    """Simulate one scenario of Section VI (``params['scenario']``) and write its tables."""
    name = params["scenario"]
    cfg = params["cfg"]
    sc = resolve_scenario(cfg, name)
    out = simulate(sc)
    tabs = scenario_tables(name, out, sc, cfg)
    return {**tabs, "provenance": {"scenario": name, "n_psd_fix": out["n_psd_fix"], "runs": sc["runs"],
                                    "horizon": sc["horizon"]}}


def tables_step(params, inputs, outputs):
    """Concatenate the per-scenario tables into errors/trajectories/summary, and the paired comparisons."""
    cat = {}
    for kind in ("errors", "single", "trajectories", "summary", "per_run"):
        files = sorted(p for k, p in inputs.items() if k.startswith(kind + "_"))
        cat[kind] = [pd.read_csv(p) for p in files]
    per_run = {df["scenario"].iloc[0]: df for df in cat["per_run"]}
    rows = []
    for comp, (sa, fa, sb, fb) in PAIRED.items():
        if sa in per_run and sb in per_run and fa in per_run[sa] and fb in per_run[sb]:
            d = per_run[sa][fa].to_numpy() - per_run[sb][fb].to_numpy()
            se = d.std(ddof=1) / math.sqrt(len(d))
            rows.append({"comparison": comp, "scenario_a": sa, "filter_a": fa, "scenario_b": sb, "filter_b": fb,
                         "mean_diff": d.mean(), "se_diff": se, "z": d.mean() / se if se > 0 else np.nan})
    return {"errors": pd.concat(cat["errors"], ignore_index=True),
            "single": pd.concat(cat["single"], ignore_index=True),
            "trajectories": pd.concat(cat["trajectories"], ignore_index=True),
            "summary": pd.concat(cat["summary"], ignore_index=True),
            "paired": pd.DataFrame(rows, columns=["comparison", "scenario_a", "filter_a", "scenario_b", "filter_b",
                                                  "mean_diff", "se_diff", "z"])}


# --------------------------------------------------------------------------- sensitivity
def sensitivity_step(params, inputs, outputs):
    """One-at-a-time sweeps of the main reconstructed parameters (gamma, consensus gains, h, control gain)."""
    return {"table": _sensitivity(params, evasive=False)}


def sensitivity_evasive_step(params, inputs, outputs):
    """Sweep of gamma against the evasive target; the row ``gamma = inf`` is the Kalman-driven scenario."""
    return {"table": _sensitivity(params, evasive=True)}


def _sensitivity(params, evasive):
    cfg, sv = params, params["sensitivity"]
    start = min(int(cfg["claims"]["late_start"]), int(sv["horizon"]) // 2)
    rows = []
    lap = laplacian(adjacency(layout_positions(cfg["layouts"][cfg["scenarios"]["fig2"]["layout"]]), cfg["comm_radius"]))

    def run(parameter, value, scen, overrides):
        sc = resolve_scenario(cfg, scen, runs=int(sv["runs"]), horizon=int(sv["horizon"]), seed=int(sv["seed"]),
                              **overrides)
        sc["filters"] = [f for f in ("local", "decentralized", "centralized") if f in sc["filters"]] or sc["filters"]
        if sc["mobile"]:
            sc["filters"] = [sc["driver"]]
        c = sc["consensus"]
        stable = pi_consensus_spectral_radius(lap, c["gamma_c"], c["h"], c["K_p"], c["K_i"]) < 1.0
        row = {"parameter": parameter, "value": value, "W": float(cfg["scenarios"][scen]["W"]), "scenario": scen,
               "exists": True, "consensus_stable": bool(stable), "local_error": np.nan, "decentralized_error": np.nan,
               "centralized_error": np.nan, "ratio_dec_local": np.nan, "settle_k": -1}
        try:
            with np.errstate(all="ignore"):
                out = simulate(sc)
        except FilterDoesNotExist:
            row["exists"] = False
            rows.append(row)
            return
        for f in ("local", "decentralized", "centralized"):
            key = sc["driver"] if (sc["mobile"] and f == "decentralized") else f
            if key in out["errors"]:
                e = out["errors"][key]
                row[f + "_error"] = float(e[..., start:].mean()) if np.all(np.isfinite(e)) else np.inf
        row["ratio_dec_local"] = row["decentralized_error"] / row["local_error"]
        dec = sc["driver"] if sc["mobile"] else "decentralized"
        mean = out["errors"][dec].reshape(-1, sc["horizon"] + 1).mean(0)
        below = mean <= float(cfg["claims"]["settle_threshold"])
        row["settle_k"] = next((k for k in range(len(mean)) if below[k:].all()), -1)
        rows.append(row)

    if evasive:
        # does H-infinity pay off against the evasive target? gamma sweep; gamma = inf is the Kalman-driven scenario
        for g in sv["gamma"]:
            run("gamma_evasive", g, "evasive_hinf", {"filter": {"gamma": g}})
        run("gamma_evasive", np.inf, "evasive_kalman", {})
        return pd.DataFrame(rows)
    for scen in sv["random_scenarios"]:
        for g in sv["gamma"]:
            run("gamma", g, scen, {"filter": {"gamma": g}})
        for key in ("gamma_c", "K_p", "K_i", "h", "iters"):
            for val in sv[key]:
                run(key, val, scen, {"consensus": {key: val}})
    for key in ("Gamma", "v_max"):
        for val in sv[key]:
            run(key, val, sv["mobile_scenario"], {"control": {key: val}})
    return pd.DataFrame(rows)


# --------------------------------------------------------------------------- errata
def _fd(fun, z, eps=1e-6):
    return (fun(z + eps) - fun(z - eps)) / (2 * eps)


def errata_step(params, inputs, outputs):
    """Equations printed wrong, each with a numerical demonstration against an independent computation."""
    cfg = params
    model = NoiseModel.from_config(cfg["noise"])
    rng = np.random.default_rng(int(cfg["errata"]["seed"]))
    r0, th0 = 27.0, 0.9
    rows = []
    # E1: eq (3) prints a 2x2 matrix for the noise vector
    n = int(cfg["errata"]["n_samples"])
    m = sample_noise(rng, np.full(n, r0), np.full(n, th0), model)
    emp = np.cov(m.T)
    M = noise_covariance(r0, th0, model)
    fr, fb = noise_variances(r0, model)
    printed = rotation(th0) @ np.diag([math.sqrt(fr), math.sqrt(fb)])
    rows.append({"paper": PAPER, "erratum_id": "E1", "location": "eq (3)",
                 "printed": "m_i = T(theta_i) diag(sqrt f_r, sqrt f_b)  (a 2x2 matrix, while m_i is in R^2)",
                 "corrected": "m_i = T(theta_i) diag(sqrt f_r, sqrt f_b) eps_i, eps_i ~ N(0, I_2); cov m_i = T diag(f_r, f_b) T^T",
                 "demonstration": f"relative Frobenius distance to the empirical covariance of {n} sampled m_i at r={r0}, theta={th0}",
                 "residual_printed": float(np.linalg.norm(printed - emp) / np.linalg.norm(emp)),
                 "residual_corrected": float(np.linalg.norm(M - emp) / np.linalg.norm(emp))})
    # E2, E3: eqs (15)-(16) vs finite differences of Sigma = Delta (I + S Delta - g L Delta)^{-1}
    ag = rng.normal(scale=20, size=(4, 2))
    x = np.array([1.0, 2.0])
    r, th = geometry(x, ag)
    g2 = float(cfg["filter"]["gamma"]) ** -2
    Lbar = np.eye(2)
    Delta = np.array([[0.3, 0.05], [0.05, 0.2]])

    def sigma_of(ri):
        rr = r.copy()
        rr[0] = ri
        S = noise_information(rr, th, model).sum(0)
        return Delta @ np.linalg.inv(np.eye(2) + S @ Delta - g2 * Lbar @ Delta)

    Mi, dMr, _ = noise_information(r, th, model, derivatives=True)
    S = Mi.sum(0)
    fd = _fd(sigma_of, r[0])
    _, corr = sigma_gradient(Delta, np.zeros((2, 2)), S, dMr[0], g2, Lbar)
    prin = printed_sigma_gradient(Delta, np.zeros((2, 2)), S, dMr[0], g2, Lbar)
    sig_true = sigma_of(r[0])
    sig_printed = Delta @ np.linalg.inv(np.eye(2) - g2 * Lbar @ Delta - S @ Delta)
    rows.append({"paper": PAPER, "erratum_id": "E2", "location": "eq (16)",
                 "printed": "Omega = I - gamma^-2 L^T Q L Delta - C^T M^-1 C Delta",
                 "corrected": "Omega = I - gamma^-2 L^T Q L Delta + C^T M^-1 C Delta (as in eqs (6) and (11))",
                 "demonstration": "relative distance of Delta Omega^-1 to Sigma of eq (6) (4 sensors, Delta fixed)",
                 "residual_printed": float(np.linalg.norm(sig_printed - sig_true) / np.linalg.norm(sig_true)),
                 "residual_corrected": float(np.linalg.norm(sigma_gradient(Delta, Delta, S, S, g2, Lbar)[0] - sig_true)
                                             / np.linalg.norm(sig_true))})
    rows.append({"paper": PAPER, "erratum_id": "E3", "location": "eq (15)",
                 "printed": "Sigma^z = Delta^z Omega^-1 + Delta Omega^-1 C^T d(M^-1)/dz C Delta Omega^-1 - ...",
                 "corrected": "Sigma^z = Delta^z Omega^-1 - Delta Omega^-1 C^T d(M^-1)/dz C Delta Omega^-1 - ... (minus sign)",
                 "demonstration": "relative distance to the central finite difference of Sigma w.r.t. r_1 (eq (16) as printed for the printed form)",
                 "residual_printed": float(np.linalg.norm(prin - fd) / np.linalg.norm(fd)),
                 "residual_corrected": float(np.linalg.norm(corr - fd) / np.linalg.norm(fd))})
    # E4: eq (17)-(18) bearing derivative
    res_p, res_c = [], []
    for rr in (5.0, 15.625, 27.0, 45.0):
        fdt = _fd(lambda t: noise_information(rr, t, model), th0)
        _, _, dt = noise_information(rr, th0, model, derivatives=True)
        pr = printed_dinfo_dtheta(rr, th0, model)
        res_p.append(np.linalg.norm(pr - fdt) / np.linalg.norm(fdt))
        res_c.append(np.linalg.norm(dt - fdt) / np.linalg.norm(fdt))
    rows.append({"paper": PAPER, "erratum_id": "E4", "location": "eqs (17)-(18)",
                 "printed": "d V^-1/d theta = V^-1 (Psi + Psi^T) V^-1, Psi = J T R^-1 T^T",
                 "corrected": "d V^-1/d theta = Psi + Psi^T with Psi = J T R^-1 T^T (equivalently -V^-1 (Phi + Phi^T) V^-1, Phi = J T R T^T)",
                 "demonstration": "max over r in {5, 15.625, 27, 45} of the relative distance to the central finite "
                                  "difference of M^-1 w.r.t. theta",
                 "residual_printed": float(max(res_p)), "residual_corrected": float(max(res_c))})
    # E5: eq (12) direction
    p0 = ag[0]

    def J_of(p):
        aa = ag.copy()
        aa[0] = p
        rr, tt = geometry(x, aa)
        S_ = noise_information(rr, tt, model).sum(0)
        return np.trace(Delta @ np.linalg.inv(np.eye(2) + S_ @ Delta - g2 * Lbar @ Delta))

    grad = np.array([_fd(lambda s: J_of(p0 + s * e), 0.0) for e in np.eye(2)])
    _, dMt_all = noise_information(r, th, model, derivatives=True)[1:]
    _, sr = sigma_gradient(Delta, np.zeros((2, 2)), S, dMr[0], g2, Lbar)
    _, st = sigma_gradient(Delta, np.zeros((2, 2)), S, dMt_all[0], g2, Lbar)
    Jr, Jt = np.trace(sr), np.trace(st)
    u_c = control_law(Jr, Jt, r[0], th[0], 1.0)
    u_p = printed_control_law(Jr, Jt, r[0], th[0], 1.0)
    desc = -grad / np.linalg.norm(grad)
    rows.append({"paper": PAPER, "erratum_id": "E5", "location": "eq (12)",
                 "printed": "u_i = -Gamma T_i^T [dJ/dr_i; r_i^-1 dJ/dtheta_i]",
                 "corrected": "u_i = +Gamma T_i [dJ/dr_i; r_i^-1 dJ/dtheta_i] for theta_i = angle(x - p_i) and T_i the rotation of eq (3)",
                 "demonstration": "1 - cos(angle) between u_i and the steepest-descent direction -grad_p J (finite differences of J = tr Sigma)",
                 "residual_printed": float(1 - u_p @ desc / np.linalg.norm(u_p)),
                 "residual_corrected": float(1 - u_c @ desc / np.linalg.norm(u_c))})
    return {"table": errata_frame(rows)}


# --------------------------------------------------------------------------- reconstructions
RECON = [
    ("filter.gamma", "H-infinity attenuation level gamma of (6)/(9); not stated. About 1.5 gamma_0 of the weakest "
     "local filter of the Fig-2 geometry (gamma_0 ~ 2.0, set by the worst cross-range information 1/f_b(40)), so every filter "
     "of every scenario exists while the gamma^-2 term still matters.", "gamma"),
    ("filter.L", "weighting L_k of (1)/(6): identity, i.e. z_k = x_k, the target position the paper estimates.", None),
    ("filter.Q", "weighting Q_k of (6): identity (no preferred direction; the paper states none).", None),
    ("filter.A", "target model A = I (random walk, 'driven by a random signal', Section VI), B = I.", None),
    ("filter.P0", "initial covariance Sigma_0 = P0 I and initial estimate error ~ N(0, P0 I), shared by all filters of a run.", None),
    ("filter.psd_floor", "consensus estimates C~ are symmetrised and shifted to a minimum eigenvalue psd_floor before (9).", None),
    ("consensus.gamma_c", "gamma of eq (5) (not the H-infinity gamma). Chosen with K_p, K_i, h so that (5) is stable on every "
     "graph of 10 agents (Laplacian eigenvalues up to 10), since mobile agents change the graph.", "gamma_c"),
    ("consensus.K_p", "proportional gain of (5); see gamma_c.", "K_p"),
    ("consensus.K_i", "integral gain of (5); see gamma_c.", "K_i"),
    ("consensus.h", "sample time h of (5); well inside the stability range reported in consensus_check.csv.", "h"),
    ("consensus.iters", "consensus iterations per filter step: one, as the paper describes ('information its neighbors sent last time step').", "iters"),
    ("control.Gamma", "gain Gamma of (12) (scalar times I); large because dJ/dr is O(Sigma^2), with the speed limit v_max doing the rest.", "Gamma"),
    ("control.v_max", "maximum agent step per time step ('limited motion capabilities'); faster than the evader's step.", "v_max"),
    ("control.recursion", "the gradient recursion (14) is used (local copies Sigma^r_i, Sigma^theta_i carried over time).", None),
    ("evader.n_headings", "the evader picks the best of n_headings equally spaced moves (or standing still) each step, eq (19).", None),
    ("evader.step_scale", "evader step length = step_scale * sqrt(tr W), the RMS step of the random walk with the same W.", None),
    ("evader.n_iter", "iterations of the mirror-descent minimisation over lambda in (24) (smallest over-bounding ellipse).", None),
    ("layouts.ten", "ten agents on an arc of radius 40 about the target's start, 20 deg apart: neighbours 13.9 apart, "
     "next-neighbours 27.4 > r = 20, so the graph is a path (at most two neighbours, connected) as in Figs 2-3. The target "
     "starts at the origin in every scenario; the agents start 40 from it (2.6 a1), so that motion has something to gain.", None),
    ("layouts.four", "four agents on an arc of radius 30, 30 deg apart (a connected path) for Fig 6.", None),
    ("scenarios.*.horizon", "number of time steps (not stated).", None),
    ("scenarios.*.runs", "Monte Carlo runs (the paper shows single runs).", None),
    ("scenarios.static_fixed.W_filter", "design W of the filters for the stationary target of Figs 4-5 (true W = 0): the "
     "Fig-3 value 0.001 I, so the filters keep tracking; with W = 0 the gain would vanish.", None),
    ("claims.late_start", "errors are compared over k >= late_start (after the initial transient).", None),
    ("claims.settle_threshold", "'approaches zero quicker': first step after which the mean error stays below this.", None),
]


def _get(cfg, dotted):
    if "*" in dotted:
        part = dotted.split(".")
        vals = {n: s[part[2]] for n, s in cfg[part[0]].items()}
        return json.dumps(vals, sort_keys=True)
    node = cfg
    for p in dotted.split("."):
        node = node[p]
    return json.dumps(node, sort_keys=True) if isinstance(node, (dict, list)) else node


def sensitivity_text(sens: pd.DataFrame, parameter: str) -> str:
    """A sentence summarising the sweep of ``parameter`` in ``sensitivity.csv``."""
    sub = sens[sens["parameter"] == parameter]
    if sub.empty:
        return ""
    parts = []
    for scen, g in sub.groupby("scenario", sort=False):
        ok = g[g["exists"] & np.isfinite(g["decentralized_error"])]
        bad = g[~(g["exists"] & np.isfinite(g["decentralized_error"]))]
        if parameter in ("Gamma", "v_max", "gamma_evasive"):
            txt = ", ".join(f"{v:g}: dec err {e:.3g}, settle k={s}" for v, e, s in
                            zip(ok["value"], ok["decentralized_error"], ok["settle_k"]))
        else:
            txt = ", ".join(f"{v:g}: dec/local {q:.2f}" for v, q in zip(ok["value"], ok["ratio_dec_local"]))
        if len(bad):
            txt += "; no result (filter does not exist or consensus diverges) at " + ", ".join(f"{v:g}" for v in bad["value"])
        parts.append(f"{scen} [{txt}]")
    return "sweep (results/hinf/sensitivity.csv): " + "; ".join(parts)


def reconstructions_step(params, inputs, outputs):
    """Every parameter the paper leaves unstated: key, value, reason, sensitivity."""
    sens = pd.concat([pd.read_csv(inputs["sensitivity"]), pd.read_csv(inputs["sensitivity_evasive"])], ignore_index=True)
    rows = []
    for key, reason, sweep in RECON:
        sensitivity = sensitivity_text(sens, sweep) if sweep else "not swept; see the reason"
        if sweep == "gamma":
            sensitivity += " | evasive target (gamma = inf: Kalman-driven agents): " + sensitivity_text(sens, "gamma_evasive")
        rows.append({"paper": PAPER, "key": f"hinf.{key}", "value": _get(params, key), "reason": reason,
                     "sensitivity": sensitivity})
    return {"table": reconstructions_frame(rows)}


# --------------------------------------------------------------------------- claims
def claims_step(params, inputs, outputs):
    """Each statement of the paper as a measurable comparison with a computed verdict."""
    cfg = params
    rows = []
    fit = fit_noise_model(pd.read_csv(inputs["noise_fit"]))
    nf = pd.read_csv(inputs["noise_fit"])
    n = int(nf["n_samples"].iloc[0])
    # Monte Carlo tolerances: relative std of a sample variance is sqrt(2/n); the quadratic fit amplifies it
    rel = 4 * math.sqrt(2 / n)
    for key, pv, tol, why in (
        ("a0", 0.3528, 10 * rel, "4 sigma of sampled variances, x10 for the extrapolation of the quadratic fit to its vertex"),
        ("a1", 15.625, 0.1, "vertex of a fitted parabola; 4 sigma sampling error of the variances maps to ~0.05 in r"),
        ("a2", 0.0008, 10 * rel, "curvature of the fit: variance sampling error amplified ~x10"),
        ("alpha", 5.0, 2 * rel, "ratio of two sample variances: 4 sigma of each"),
    ):
        rows.append(claim_row(PAPER, f"noise_{key}", f"noise model (3)-(4) parameter {key} recovered from sampled noise",
                              pv, fit[key], tol, why, relative=key != "a1",
                              note="least-squares fit of f_r to empirical variances of eq-(3) samples (results/hinf/noise_fit.csv)"))
    cc = pd.read_csv(inputs["consensus"])
    stable = cc[cc["stable"]]
    hmax = float(cc["h_max"].iloc[0])
    rows.append(claim_row(PAPER, "consensus_zero_steady_state_error",
                          "PI consensus (5) tracks the average of constant inputs with zero steady-state error (connected graph)",
                          True, bool(len(stable) > 0 and stable["steady_state_error"].max() < 1e-8), 0,
                          "boolean; error threshold 1e-8 after n_iter steps",
                          note=f"max steady-state error over stable h: {stable['steady_state_error'].max():.2e}"))
    small_stable = bool(cc.loc[cc["h"] <= hmax, "stable"].all() and (~cc.loc[cc["h"] > hmax, "stable"]).all()
                        and (cc["h"] > hmax).any())
    rows.append(claim_row(PAPER, "consensus_stable_small_h", "eq (5) is stable as long as the sample time h is small",
                          True, small_stable, 0, "boolean: stable exactly for h in (0, h_max] on the grid",
                          note=f"stability range on the Fig-2 path graph: 0 < h <= {hmax:.4f} (gamma_c={cfg['consensus']['gamma_c']}, "
                               f"K_p={cfg['consensus']['K_p']}, K_i={cfg['consensus']['K_i']}); unstable runs diverge"))
    att = pd.read_csv(inputs["attenuation"]).set_index("filter")
    chk = pd.read_csv(inputs["checks"]).set_index("check")["value"]
    rows.append(claim_row(PAPER, "hinf_to_kalman", "as gamma tends to infinity the H-infinity filter reduces to the Kalman filter",
                          True, bool(chk["hinf_vs_kalman_max_abs_diff"] < 1e-6), 0,
                          "boolean: max |difference| of estimates and covariances < 1e-6 at gamma = gamma_large",
                          note=f"max abs difference {chk['hinf_vs_kalman_max_abs_diff']:.2e}"))
    rows.append(claim_row(PAPER, "below_gamma0_no_filter",
                          "the filter 'will be unstable' (does not exist) if gamma < gamma_0, the minimum attenuation level",
                          True, bool((att["status_below"] == "does_not_exist").all()), 0,
                          "boolean: the simulation at 0.9 gamma_0 reports non-existence for every filter kind",
                          note="gamma_0: " + ", ".join(f"{f} {g:.3f}" for f, g in att["gamma0"].items())
                               + "; at gamma < gamma_0, Sigma^-1 loses positive definiteness (the filter does not exist "
                                 "rather than running unstably)"))
    rows.append(claim_row(PAPER, "decentralized_exact_equals_centralized",
                          "with the exact averages (7)-(8), the decentralized filter (9) is the centralized filter (6)",
                          True, bool(chk["decentralized_exact_vs_centralized_max_abs_diff"] < 1e-9), 0,
                          "boolean: max |difference| < 1e-9",
                          note=f"max abs difference {chk['decentralized_exact_vs_centralized_max_abs_diff']:.2e}"))
    summ = pd.read_csv(inputs["summary"]).set_index(["scenario", "filter"])
    paired = pd.read_csv(inputs["paired"]).set_index("comparison")
    z_sig = float(cfg["claims"]["z_significant"])

    def better(comp):
        z = float(paired.loc[comp, "z"])
        return bool(z < -z_sig), z

    fig2_deg = int(summ.loc[("fig2", "local"), "max_degree"])
    fig2_conn = float(summ.loc[("fig2", "local"), "connected_fraction"])
    rows.append(claim_row(PAPER, "fig2_graph", "ten agents, r = 20: connected, each agent with at most two neighbours",
                          True, bool(fig2_conn == 1.0 and fig2_deg <= 2), 0, "boolean",
                          note=f"max degree {fig2_deg}, connected fraction {fig2_conn:g} (layout is a reconstruction)"))
    mob = [s for s in SCENARIOS if cfg["scenarios"].get(s, {}).get("mobile")]
    conn = {s: float(summ.xs(s, level="scenario")["connected_fraction"].iloc[0]) for s in mob}
    rows.append(claim_row(PAPER, "r20_guarantees_connectivity",
                          "the communication radius r = 20 guarantees the network is connected (mobile scenarios)",
                          True, bool(all(v == 1.0 for v in conn.values())), 0,
                          "boolean: every step of every run connected",
                          note="fraction of (run, step) pairs connected: " + ", ".join(f"{s} {v:.3f}" for s, v in conn.items())))
    for sid, scen in (("fig2", "fig2"), ("fig3", "fig3")):
        b, z = better(f"{sid}_dec_vs_local")
        rows.append(claim_row(PAPER, f"{sid}_decentralized_beats_local",
                              f"{sid}: the decentralized H-infinity filter has a smaller estimation error than the local one "
                              f"(W = {cfg['scenarios'][scen]['W']} I)",
                              True, b, 0, f"boolean: paired late-error difference below -{z_sig} standard errors",
                              note=f"late mean error local {summ.loc[(scen, 'local'), 'late_mean']:.4f}, decentralized "
                                   f"{summ.loc[(scen, 'decentralized'), 'late_mean']:.4f} (z = {z:.1f})"))
    ratio = {s: summ.loc[(s, "local"), "late_mean"] / summ.loc[(s, "decentralized"), "late_mean"] for s in ("fig2", "fig3")}
    rows.append(claim_row(PAPER, "gain_grows_with_speed",
                          "comparing Figs 2 and 3, the performance of the decentralized filter improves as the speed of "
                          "the target increases (read as: its gain over the local filter is larger at W = 0.01 I)",
                          True, bool(ratio["fig2"] > ratio["fig3"]), 0, "boolean",
                          note=f"local/decentralized error ratio: W=0.01 -> {ratio['fig2']:.3f}, W=0.001 -> {ratio['fig3']:.3f}. "
                               "The paper's own explanation (next claim) says the opposite."))
    rows.append(claim_row(PAPER, "gain_grows_as_noise_decreases",
                          "as the process noise decreases, the information passed between agents is more relevant and "
                          "improves the estimates (gain over local larger at W = 0.001 I)",
                          True, bool(ratio["fig3"] > ratio["fig2"]), 0, "boolean",
                          note=f"local/decentralized error ratio: W=0.001 -> {ratio['fig3']:.3f}, W=0.01 -> {ratio['fig2']:.3f}"))
    sl = summ.loc[("static_fixed", "local")]
    md = summ.loc[("static_mobile", "decentralized")]
    sd = summ.loc[("static_fixed", "decentralized")]
    rows.append(claim_row(PAPER, "fig4_mobile_settles_quicker",
                          "Fig 4: the error of the mobile decentralized agent approaches zero quicker than the stationary local one",
                          True, bool(0 <= md["settle_k"] < (sl["settle_k"] if sl["settle_k"] >= 0 else np.inf)), 0,
                          f"boolean: settling step (mean error stays below {cfg['claims']['settle_threshold']})",
                          note=f"settle k: stationary local {int(sl['settle_k'])}, mobile decentralized {int(md['settle_k'])} (-1: never)"))
    rows.append(claim_row(PAPER, "fig4_mobile_smoother", "Fig 4: the error of the mobile agent is smoother",
                          True, bool(md["total_variation"] < sl["total_variation"]), 0,
                          "boolean: mean total variation per step of the error path",
                          note=f"total variation per step: stationary local {sl['total_variation']:.4f}, mobile decentralized "
                               f"{md['total_variation']:.4f}"))
    b, z = better("fig5_mobile_vs_stationary")
    rows.append(claim_row(PAPER, "fig5_mobile_beats_stationary",
                          "Fig 5 / Section IV: moving with the gradient law improves the decentralized estimate (stationary target)",
                          True, b, 0, f"boolean: paired late-error difference below -{z_sig} standard errors",
                          note=f"late mean error stationary {sd['late_mean']:.4f}, mobile {md['late_mean']:.4f} (z = {z:.1f})"))
    ev = summ.loc[("evasive_hinf", "decentralized")]
    rows.append(claim_row(PAPER, "fig6_agents_align",
                          "Fig 6: the agents move to align themselves for better sensor readings (range error |r - a1| shrinks)",
                          True, bool(ev["range_error_end"] < ev["range_error_start"]), 0, "boolean",
                          note=f"mean |r_i - a1|: start {ev['range_error_start']:.2f}, end {ev['range_error_end']:.2f}"))
    b, z = better("evasive_hinf_vs_kalman")
    eh, ek = summ.loc[("evasive_hinf", "decentralized"), "late_mean"], summ.loc[("evasive_kalman", "kalman_decentralized"), "late_mean"]
    rows.append(claim_row(PAPER, "future_hinf_beats_kalman_evasive",
                          "premise (Section VII): the H-infinity filter outperforms the Kalman filter against an evasive target",
                          True, b, 0, f"boolean: paired late-error difference below -{z_sig} standard errors",
                          note=f"decentralized, each filter driving its own agents: H-inf {eh:.4f}, Kalman {ek:.4f} (z = {z:.1f})"))
    return {"table": claims_frame(rows)}


# --------------------------------------------------------------------------- figures
def _plotting():
    from ..plotting import new_figure, save_figure
    return new_figure, save_figure


def figure_noise(params, inputs, outputs):
    """Fig 1: uncertainty ellipses (eq (3)-(4)) of three sensors, drawn at the sensor locations."""
    from matplotlib.patches import Ellipse
    new_figure, save_figure = _plotting()
    t = pd.read_csv(inputs["table"])
    scale = float(params.get("scale", 3.0))
    fig, ax = new_figure(figsize=(6.0, 5.0))
    ax.plot(0, 0, "ks", ms=8, label="target")
    for _, row in t.iterrows():
        fr, fb = row["f_r"], row["f_b"]
        ell = Ellipse((row["x"], row["y"]), 2 * scale * math.sqrt(fr), 2 * scale * math.sqrt(fb),
                      angle=math.degrees(row["theta"]), fill=False, lw=1.5, color=f"C{int(row['sensor'])}")
        ax.add_patch(ell)
        ax.plot(row["x"], row["y"], "o", color=f"C{int(row['sensor'])}",
                label=f"sensor {int(row['sensor'])}: r = {row['r']:g}, f_r = {fr:.3f}, f_b = {fb:.3f}")
        ax.plot([row["x"], 0], [row["y"], 0], ":", color=f"C{int(row['sensor'])}", lw=0.8)
    ax.set_aspect("equal")
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    ax.set_title(f"Measurement uncertainty ellipses ({scale:g}-sigma)")
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.02, 1.0))
    save_figure(fig, outputs["figure"])
    return {}


def figure_errors(params, inputs, outputs):
    """Figs 2-5: estimation error of two (scenario, filter) series, one agent of one run and the Monte Carlo band."""
    new_figure, save_figure = _plotting()
    err = pd.read_csv(inputs["errors"])
    single = pd.read_csv(inputs["single"])
    fig, axes = new_figure(1, 2, figsize=(11, 4), sharey=False)
    for (scen, filt, label), color in zip(params["series"], ("C0", "C3")):
        s = single[(single["scenario"] == scen) & (single["filter"] == filt)]
        axes[0].plot(s["k"], s["error"], color=color, lw=1, label=label)
        e = err[(err["scenario"] == scen) & (err["filter"] == filt)]
        axes[1].plot(e["k"], e["error_mean"], color=color, lw=1.5, label=label + " (mean)")
        axes[1].fill_between(e["k"], e["error_lo"], e["error_hi"], color=color, alpha=0.2, lw=0)
    agent = int(single["agent"].iloc[0])
    axes[0].set_title(f"one agent (agent {agent}, run {int(single['run'].iloc[0])})")
    axes[1].set_title("mean over runs and agents, 10-90 % band")
    for ax in axes:
        ax.set_xlabel("time step k")
        ax.set_ylabel("estimation error |x_hat - x|")
        ax.legend()
    if params.get("log"):
        axes[1].set_yscale("log")
    fig.suptitle(params["title"])
    save_figure(fig, outputs["figure"])
    return {}


def figure_trajectories(params, inputs, outputs):
    """Fig 6: trajectories of the agents (circles) and the evasive target (square), with tails."""
    new_figure, save_figure = _plotting()
    tr = pd.read_csv(inputs["trajectories"], dtype={"who": str})
    tr = tr[(tr["scenario"] == params["scenario"]) & (tr["run"] == int(params.get("run", 0)))]
    fig, ax = new_figure(figsize=(6.5, 6.0))
    for i, (who, g) in enumerate(tr.groupby("who", sort=True)):
        g = g.sort_values("k")
        is_t = who == "target"
        color = "k" if is_t else f"C{i}"
        ax.plot(g["x"], g["y"], "-", color=color, lw=1, alpha=0.7)
        ax.plot(g["x"].iloc[0], g["y"].iloc[0], "s" if is_t else "o", color=color, mfc="none", ms=8)
        ax.plot(g["x"].iloc[-1], g["y"].iloc[-1], "s" if is_t else "o", color=color, ms=8,
                label="target" if is_t else f"agent {who}")
    ax.set_aspect("equal")
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    ax.set_title(params["title"] + " (open: start, filled: end)")
    ax.legend(fontsize=8)
    save_figure(fig, outputs["figure"])
    return {}


def figure_hinf_vs_kalman(params, inputs, outputs):
    """Fig S1: late-window mean error of H-infinity vs Kalman filters in every scenario (beyond the paper)."""
    new_figure, save_figure = _plotting()
    s = pd.read_csv(inputs["summary"])
    fig, ax = new_figure(figsize=(10, 4.5))
    kinds = ["local", "decentralized", "centralized"]
    scen = list(dict.fromkeys(s["scenario"]))
    width = 0.13
    for j, kind in enumerate(kinds):
        for m, (pref, hatch) in enumerate((("", None), ("kalman_", "//"))):
            vals, errs = [], []
            for sc in scen:
                name = pref + kind
                if sc == "evasive_kalman" and pref == "":
                    name = "__none__"
                row = s[(s["scenario"] == sc) & (s["filter"] == name)]
                vals.append(row["late_mean"].iloc[0] if len(row) else np.nan)
                errs.append(2 * row["late_se"].iloc[0] if len(row) else np.nan)
            x = np.arange(len(scen)) + (2 * j + m - 2.5) * width
            ax.bar(x, vals, width, yerr=errs, color=f"C{j}", hatch=hatch, alpha=0.8 if m == 0 else 0.45,
                   label=("Kalman " if m else "H-inf ") + kind)
    ax.set_xticks(np.arange(len(scen)))
    ax.set_xticklabels(scen, fontsize=8)
    ax.set_ylabel("late-window mean error (+- 2 SE)")
    ax.set_title("H-infinity vs Kalman filters (beyond the paper)")
    ax.legend(fontsize=7, ncol=3)
    save_figure(fig, outputs["figure"])
    return {}


def figure_sensitivity(params, inputs, outputs):
    """Fig S2: decentralized/local error ratio against each swept reconstruction."""
    new_figure, save_figure = _plotting()
    s = pd.concat([pd.read_csv(inputs["table"]), pd.read_csv(inputs["evasive"])], ignore_index=True)
    pars = [p for p in ("gamma", "gamma_c", "K_p", "K_i", "h", "iters") if p in set(s["parameter"])]
    ev = s[s["parameter"] == "gamma_evasive"]
    fig, axes = new_figure(1, len(pars) + (len(ev) > 0), figsize=(2.6 * (len(pars) + 1), 3.2), squeeze=False)
    for ax, p in zip(axes[0], pars):
        for i, (scen, g) in enumerate(s[s["parameter"] == p].groupby("scenario", sort=False)):
            g = g.sort_values("value")
            ax.plot(g["value"], g["ratio_dec_local"], "o-", color=f"C{i}", label=f"{scen} (W={g['W'].iloc[0]:g})")
            nx = g[~g["exists"] | ~np.isfinite(g["ratio_dec_local"])]
            ax.plot(nx["value"], np.ones(len(nx)), "x", color=f"C{i}")
        ax.axhline(1.0, color="k", lw=0.8, ls=":")
        ax.set_xlabel(p)
        if p == "gamma":
            ax.set_xscale("log")
    if len(ev):
        ax = axes[0][-1]
        fin = ev[np.isfinite(ev["value"]) & ev["exists"]]
        ax.plot(fin["value"], fin["decentralized_error"], "o-", color="C2", label="H-inf (evasive)")
        nx = ev[np.isfinite(ev["value"]) & ~ev["exists"]]
        ax.plot(nx["value"], np.full(len(nx), np.nanmin(fin["decentralized_error"]) if len(fin) else 1.0), "x", color="C2")
        kal = ev[~np.isfinite(ev["value"])]
        if len(kal):
            ax.axhline(kal["decentralized_error"].iloc[0], color="k", ls="--", label="Kalman (evasive)")
        ax.set_xscale("log")
        ax.set_xlabel("gamma (evasive target)")
        ax.set_ylabel("decentralized late error")
        ax.legend(fontsize=7)
    axes[0][0].set_ylabel("decentralized / local error")
    axes[0][0].legend(fontsize=7)
    fig.subplots_adjust(wspace=0.5)
    fig.suptitle("Sensitivity of the Fig 2-3 comparison (x: no result)")
    save_figure(fig, outputs["figure"])
    return {}


def figure_consensus(params, inputs, outputs):
    """Fig S3: spectral radius and steady-state error of the PI consensus (5) against the step h."""
    new_figure, save_figure = _plotting()
    c = pd.read_csv(inputs["table"])
    fig, axes = new_figure(1, 2, figsize=(10, 3.6))
    axes[0].plot(c["h"], c["spectral_radius"], "o-")
    axes[0].axhline(1.0, color="k", ls=":")
    axes[0].axvline(c["h_max"].iloc[0], color="C3", ls="--", label=f"h_max = {c['h_max'].iloc[0]:.3f}")
    axes[0].set_ylabel("spectral radius of (5)")
    err = c["steady_state_error"].replace(np.inf, np.nan).clip(lower=1e-16, upper=1e6)
    axes[1].semilogy(c["h"], err, "o-")
    axes[1].set_ylabel("steady-state error (clipped)")
    for ax in axes:
        ax.set_xlabel("h")
    axes[0].legend()
    save_figure(fig, outputs["figure"])
    return {}
