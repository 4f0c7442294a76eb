"""Pipeline steps of the `hinf` paper: read inputs, call the model, return tables.

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
``paired_evasive.csv`` (issue 17)
    ``target, filter_a, filter_b, gamma, runs, mean_diff, se, z, gamma0, gamma_ratio, label_a, driver,
    frac_a_better, error_a, error_b`` — every filter on the same target, agents and measurements;
    ``mean_diff`` = error of a minus error of b over ``late_start <= k <= horizon`` (paired per run).
``per_agent.csv`` (issue 17)
    ``scenario, agent, horizon, local, decentralized, ratio, z, se, K_i, gamma_c, K_p, tag`` — Fig 2-3 per agent and
    horizon (window ``late_start..horizon``), ``<scenario>_ki0`` with ``K_i = 0``, ``<scenario>_gamma_c<v>`` /
    ``<scenario>_K_p<v>`` with that consensus gain (mean over agents only); ``agent = -1`` is the mean over the
    agents; ``ratio`` = decentralized / local; ``se`` the paired standard error of decentralized minus local; ``tag`` holds / not significant / reversed at ``|z| > claims.z_significant``.
``per_agent_errors.csv``
    ``scenario, agent, filter, k, error_mean`` — Monte Carlo mean error of the end and an interior agent.
``consensus_modes.csv``
    ``scenario, K_i, mode, laplacian_eigenvalue, modulus, time_constant_steps`` — modes of eq (5) on the
    Fig-2 graph.
``evader_convergence.csv`` (issue 17)
    ``solver, n_iter, configured, decisions, certified_fraction, same_as_reference, median_gap, max_gap,
    median_margin, median_value, max_loss, mean_loss, loss_above_tolerance_fraction, ...`` — replayed
    evader decisions (mirror descent, pairwise Frank-Wolfe, exact), each candidate's value bracketed by a
    duality-gap certificate; the exact solver is the reference.
``evader_paired.csv``
    ``solver, n_iter, runs, filter_a, filter_b, gamma, mean_diff, se, z, error_a, error_b`` — the H-infinity
    vs Kalman comparison repeated with the configured, the mirror-descent and the pairwise evader.
``fig5_control.csv`` (issue 15)
    ``parameter, value, runs, horizon, start, stationary, mobile, mean_diff, se, z`` — Fig 5 (mobile minus stationary
    decentralized late error, paired over runs: same seed, target and noise stream) across the sweeps of the control
    gain ``Gamma`` and the speed limit ``v_max`` (``sensitivity`` runs, horizon and seed; window ``start..horizon``).
``evasive_network.csv`` (issue 15)
    ``target, run, connected_fraction, local, decentralized`` — the Fig-6 setting (``paired.scenario``) against each
    target model, ``paired.network_runs`` runs, seed ``paired.seed``: per run, the fraction of steps of the late window
    with a connected graph (25) and the late-window mean errors of the local and decentralized H-infinity filters.
``loop_variants.csv``, ``loop_variants_runs.csv`` (issue 28)
    closed-loop consensus variants of the evasive comparison, see :func:`loop_variants_merge_step`.
``loop_swap.csv``, ``loop_swap_runs.csv`` (issue 37)
    the fixed-path swap: every consensus design open loop on each closed loop's recorded paths, same seeds, see
    :func:`swap_comparisons`.
``kalman_best.csv`` (issue 28)
    H-infinity against Kalman filters at their best, see :func:`kalman_best_merge_step`.
``evader_fused.csv`` (issue 37)
    the evader's objective tr Q_fused against the other targets, see :func:`fused_comparisons`.
``network.csv``, ``connectivity.csv``
    ``scenario, run, k, i, j`` links of eq (25) at the time marks; ``scenario, run, steps,
    connected_fraction, min_lambda2, topology_changes`` per trajectory run (steps at which a link appears or
    disappears).
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from .algebra import rotation
from .consensus import (adjacency, consensus_h_max, laplacian, pi_consensus_spectral_radius,
                        pi_consensus_time_constants, run_pi_consensus, topology_changed)
from .evader import evader_decisions, fused_trace_along
from ...errors import InputError
from .filters import decentralized_update, hinf_update, kalman_update, minimum_attenuation
from .model import (FILTER_KINDS, KINDS, FilterDoesNotExist, bonferroni_z, layout_positions, paired_z, resolve_scenario,
                    run_paired, simulate, tag_z, window_means)
from .motion import path_statistics
from .noise import NoiseModel, geometry, noise_covariance, noise_information, noise_variances, sample_noise

__all__ = [
    "PAIRED", "noise_model_step", "consensus_check_step", "attenuation_step", "scenario_tables", "simulate_step",
    "tables_step", "sensitivity_step", "sensitivity_evasive_step", "paired_evasive_step", "fig2_horizon_step",
    "evader_check_step", "network_step", "fig5_control_step", "evasive_network_step", "loop_variants_shard_step",
    "loop_variants_merge_step", "recorded_evader_paths", "kalman_best_shard_step", "fused_comparisons", "kalman_best_merge_step", "fig6_paths_step",
    "design_consensus", "loop_swap_shard_step", "swap_comparisons", "loop_swap_merge_step",
]

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


# --------------------------------------------------------------------------- noise model (Fig 1)
def noise_model_step(params, inputs, outputs):
    """Fig-1 ellipses and an empirical check of eqs (3)-(4) by sampling.

    Fig 1: three sensors at the configured ranges and bearings from a target at the origin, with the
    1-sigma semi-axes of their noise ellipses ``M_i`` (eqs (3)-(4)). Check: at each range of
    ``noise_check.r_grid``, ``noise_check.n_samples`` noise vectors drawn by eq (3) (corrected,
    erratum E1) at bearing ``noise_check.theta``, and their empirical variances along and across the
    line of sight next to ``f_r`` and ``f_b`` of eq (4).

    Parameters
    ----------
    params : dict
        The ``hinf`` configuration; read: ``noise`` (``a0, a1, a2, alpha`` of eq (4)) and
        ``noise_check`` (``fig1_ranges``, ``fig1_bearings_deg`` in degrees, ``r_grid``, ``theta`` in
        radians, ``n_samples``, ``seed``).
    inputs : dict
        Only the step's code (no table is read).
    outputs : dict
        ``table`` and ``fit``: ``results/hinf/noise_model.csv`` and ``noise_fit.csv``.

    Returns
    -------
    dict
        ``{"table": DataFrame, "fit": DataFrame}``: the columns listed in the module docstring.
    """
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



# --------------------------------------------------------------------------- consensus (5)
def consensus_check_step(params, inputs, outputs):
    """Stability range of the step h of eq (5) and the steady-state error with constant inputs.

    On the graph (25) of the layout ``consensus_check.layout``, with constant random inputs (six
    components per agent, standard normal, seed ``consensus_check.seed``): for each ``h`` of
    ``consensus_check.h_grid`` the spectral radius of eq (5) and the largest ``|v_i - mean(u)|`` after
    ``consensus_check.n_iter`` steps (:func:`.consensus.run_pi_consensus`; inf when it diverged), and
    ``h_max``, the largest step for which eq (5) is stable (:func:`.consensus.consensus_h_max`).

    Parameters
    ----------
    params : dict
        The ``hinf`` configuration; read: ``consensus_check`` (``layout``, ``h_grid``, ``n_iter``,
        ``seed``), ``consensus`` (``gamma_c``, ``K_p``, ``K_i``), ``layouts`` and ``comm_radius``.
    inputs : dict
        Only the step's code (no table is read).
    outputs : dict
        ``table``: ``results/hinf/consensus_check.csv``.

    Returns
    -------
    dict
        ``{"table": DataFrame, "provenance": {"h_max": float}}``: one row per ``h`` (columns
        ``h, steady_state_error, stable, spectral_radius, h_max``).
    """
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
    """Minimum attenuation level gamma_0 of eq (6), filter existence, and the two filter identities.

    gamma_0 (:func:`.filters.minimum_attenuation`) of the local filters (worst agent) and of the
    centralized filter, for the Fig-2 agents around a target at the origin over
    ``attenuation.horizon`` steps (``B W B^T = W_filter I`` of scenario ``fig2``); then whether
    scenario ``fig2`` with that filter alone (``attenuation.runs`` runs, ``attenuation.horizon``
    steps) can be simulated, i.e. the filter exists, at the configured gamma and at ``0.9 gamma_0``.
    Identities, over 50 steps of a random-walk target (``attenuation.runs`` runs, seed
    ``attenuation.seed``): eq (6) with ``gamma = attenuation.gamma_large`` against a textbook
    Kalman filter, and eq (9) fed the exact averages (7)-(8) against eq (6) with the same gamma (the
    largest absolute differences of the estimates and covariances).

    Parameters
    ----------
    params : dict
        The ``hinf`` configuration; read: ``filter`` (``L``, ``Q``, ``A``, ``P0``, ``gamma``),
        ``attenuation`` (``horizon``, ``runs``, ``seed``, ``gamma_large``), ``noise``, ``layouts``
        and ``scenarios.fig2`` (and what :func:`.model.resolve_scenario` reads for it).
    inputs : dict
        Only the step's code (no table is read).
    outputs : dict
        ``table`` and ``checks``: ``results/hinf/attenuation.csv`` and ``filter_checks.csv``.

    Returns
    -------
    dict
        ``{"table": DataFrame, "checks": DataFrame, "provenance": {"gamma0_local": float,
        "gamma0_central": float}}``: one row per filter (``local``, ``centralized``) and the two
        identity checks (``check, value, note``).
    """
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
    """Reduce one :func:`simulate` output to the tables of the module docstring.

    The late window is ``k >= min(claims.late_start, horizon)``.

    Parameters
    ----------
    name : str
        The scenario's name (its ``scenario`` column).
    out : dict
        What :func:`.model.simulate` returned for it (``errors``, ``target``, ``agents``,
        ``connected``, ``max_degree``, ``fused_trace``).
    sc : dict
        The resolved scenario (:func:`.model.resolve_scenario`; ``horizon``, ``runs`` and ``model``
        are read).
    cfg : dict
        The ``hinf`` configuration; read: ``output`` (``band``, ``single_agent``, ``single_run``,
        ``traj_runs``) and ``claims`` (``late_start``, ``settle_threshold``).

    Returns
    -------
    dict
        ``{"errors", "single", "trajectories", "summary", "per_run": DataFrame}``: the scenario's
        pieces of ``errors.csv``, ``errors_single.csv``, ``trajectories.csv`` and ``summary.csv``, and
        each run's late-window mean error of every filter (one column per filter, and ``run``), from
        which :func:`tables_step` forms the paired comparisons.
    """
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
    """Simulate one scenario of Section VI (``params['scenario']``) and write its tables.

    Parameters
    ----------
    params : dict
        ``scenario`` (a scenario name of ``hinf.scenarios``) and ``cfg`` (the entries of the ``hinf``
        configuration it reads: ``output``, ``claims``, what :func:`.model.resolve_scenario` reads,
        ``scenarios`` holding this scenario only).
    inputs : dict
        Only the step's code (no table is read).
    outputs : dict
        ``errors``, ``single``, ``trajectories``, ``summary`` and ``per_run``:
        ``results/hinf/sim/<scenario>_<name>.csv``.

    Returns
    -------
    dict
        The tables of :func:`scenario_tables` and ``"provenance"``: ``{"scenario", "n_psd_fix",
        "runs", "horizon"}`` (``n_psd_fix`` from :func:`.model.simulate`).

    Raises
    ------
    FilterDoesNotExist
        If an H-infinity filter of the scenario does not exist at some step (gamma below gamma_0).
    """
    from . import filter_kernels  # noqa: F401  numba: pays its load (~0.3 s) in the 200-run scenarios, even elsewhere
    name = params["scenario"]
    cfg = params["cfg"]
    sc = resolve_scenario(cfg, name)
    out = simulate(sc)
    tabs = scenario_tables(name, out, sc, cfg)
    return {**tabs, "provenance": {"scenario": name, "n_psd_fix": out["n_psd_fix"], "runs": sc["runs"],
                                    "horizon": sc["horizon"]}}


def tables_step(params, inputs, outputs):
    """Concatenate the per-scenario tables into errors/trajectories/summary, and the paired comparisons.

    Paired comparisons: for each entry of :data:`PAIRED` whose scenarios and filters were simulated,
    the per-run differences ``a - b`` of the late-window mean errors (same seeds), their mean, standard
    error and ``z = mean / se``.

    Parameters
    ----------
    params : dict
        Not read (the rule passes ``{}``).
    inputs : dict
        ``<piece>_<scenario>`` for each piece (``errors``, ``single``, ``trajectories``, ``summary``,
        ``per_run``) and scenario: the tables of :func:`simulate_step`.
    outputs : dict
        ``errors``, ``single``, ``trajectories``, ``summary`` and ``paired``:
        ``results/hinf/errors.csv``, ``errors_single.csv``, ``trajectories.csv``, ``summary.csv`` and
        ``paired.csv``.

    Returns
    -------
    dict
        ``{"errors", "single", "trajectories", "summary", "paired": DataFrame}``.
    """
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
    """One-at-a-time sweeps of the main reconstructed parameters (gamma, consensus gains, h, control gain).

    For each scenario of ``sensitivity.random_scenarios``: the H-infinity gamma and each consensus
    parameter of eq (5) (``gamma_c``, ``K_p``, ``K_i``, ``h``, ``iters``) over its values; for
    ``sensitivity.mobile_scenario``: the control gain ``Gamma`` of eq (12) and the speed limit
    ``v_max``; the others at their configured values, with the sensitivity runs, horizon and seed.
    Errors are means over the window ``k >= min(claims.late_start, horizon // 2)``; ``exists`` is
    False (errors NaN) where an H-infinity filter does not exist; ``consensus_stable`` is eq (5)'s
    spectral radius < 1 on the Fig-2 graph.

    Parameters
    ----------
    params : dict
        The ``hinf`` configuration; read: ``sensitivity`` (``runs``, ``horizon``, ``seed``,
        ``random_scenarios``, ``mobile_scenario`` and the value lists), ``claims`` (``late_start``,
        ``settle_threshold``), ``scenarios``, ``layouts``, ``comm_radius`` and what
        :func:`.model.resolve_scenario` reads.
    inputs : dict
        Only the step's code (no table is read).
    outputs : dict
        ``table``: ``results/hinf/sensitivity.csv``.

    Returns
    -------
    dict
        ``{"table": DataFrame}``: one row per parameter value and scenario (columns in the module
        docstring).
    """
    from . import filter_kernels  # noqa: F401  numba: this step runs enough filter updates to pay its load
    return {"table": _sensitivity(params, evasive=False)}


def sensitivity_evasive_step(params, inputs, outputs):
    """Sweep of gamma against the evasive target; the row ``gamma = inf`` is the Kalman-driven scenario.

    Scenario ``evasive_hinf`` at each gamma of ``sensitivity.gamma`` (parameter ``gamma_evasive``),
    and ``evasive_kalman`` as ``gamma = inf``; runs, horizon, seed and window as in
    :func:`sensitivity_step`.

    Parameters
    ----------
    params : dict
        The ``hinf`` configuration (as for :func:`sensitivity_step`).
    inputs : dict
        Only the step's code (no table is read).
    outputs : dict
        ``table``: ``results/hinf/sensitivity_evasive.csv``.

    Returns
    -------
    dict
        ``{"table": DataFrame}``: the columns of ``sensitivity.csv``.
    """
    from . import filter_kernels  # noqa: F401  numba: the evader's exact solver and the filters compiled (~0.7 s less)
    return {"table": _sensitivity(params, evasive=True)}


def _sensitivity(params, evasive):
    cfg, sv = params, params["sensitivity"]
    start = min(int(cfg["claims"]["late_start"]), int(sv["horizon"]) // 2)
    rows = []
    lap = laplacian(adjacency(layout_positions(cfg["layouts"][cfg["scenarios"]["fig2"]["layout"]]), cfg["comm_radius"]))

    def prepare(parameter, value, scen, overrides):
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
        return sc, row

    def fill(row, sc, errors):
        for f in ("local", "decentralized", "centralized"):
            key = sc["driver"] if (sc["mobile"] and f == "decentralized") else f
            if key in errors:
                e = errors[key]
                row[f + "_error"] = float(e[..., start:].mean()) if np.all(np.isfinite(e)) else np.inf
        row["ratio_dec_local"] = row["decentralized_error"] / row["local_error"]
        dec = sc["driver"] if sc["mobile"] else "decentralized"
        mean = errors[dec].reshape(-1, sc["horizon"] + 1).mean(0)
        below = mean <= float(cfg["claims"]["settle_threshold"])
        row["settle_k"] = next((k for k in range(len(mean)) if below[k:].all()), -1)
        rows.append(row)

    def run(parameter, value, scen, overrides):
        sc, row = prepare(parameter, value, scen, overrides)
        try:
            with np.errstate(all="ignore"):
                out = simulate(sc)
        except FilterDoesNotExist:
            row["exists"] = False
            rows.append(row)
            return
        fill(row, sc, out["errors"])

    def run_consensus(scen, sweep):
        """The rows of ``run(key, val, scen, {"consensus": {key: val}})`` for each ``(key, val)`` of ``sweep``, from
        one simulation with a decentralized filter per consensus variant (stationary agents: the same target,
        measurements, local and centralized filters in every variant; the same numbers as one run each)."""
        base, _ = prepare(None, None, scen, {})
        if base["mobile"]:
            return [run(key, val, scen, {"consensus": {key: val}}) for key, val in sweep]
        base["consensus_variants"] = {f"{key}={val!r}": {key: val} for key, val in sweep}
        try:
            with np.errstate(all="ignore"):
                out = simulate(base)
        except FilterDoesNotExist:  # some variant's filter does not exist: each variant on its own
            return [run(key, val, scen, {"consensus": {key: val}}) for key, val in sweep]
        for key, val in sweep:
            sc, row = prepare(key, val, scen, {"consensus": {key: val}})
            fill(row, sc, {**out["errors"], "decentralized": out["errors"][f"{key}={val!r}"]})

    if evasive:
        # does H-infinity pay off against the evasive target? gamma sweep; gamma = inf is the Kalman-driven scenario
        for g in sv["gamma"]:
            run("gamma_evasive", g, "evasive_hinf", {"filter": {"gamma": g}})
        run("gamma_evasive", np.inf, "evasive_kalman", {})
        return pd.DataFrame(rows)
    for scen in sv["random_scenarios"]:
        for g in sv["gamma"]:
            run("gamma", g, scen, {"filter": {"gamma": g}})
        run_consensus(scen, [(key, val) for key in ("gamma_c", "K_p", "K_i", "h", "iters") for val in sv[key]])
    for key in ("Gamma", "v_max"):
        for val in sv[key]:
            run(key, val, sv["mobile_scenario"], {"control": {key: val}})
    return pd.DataFrame(rows)


# --------------------------------------------------------------------------- issue 17: comparisons that can decide
def paired_evasive_step(params, inputs, outputs):
    """Every filter on the same target, agents and measurements; gamma swept relative to each gamma_0.

    For each target model, :func:`~netrepro.papers.hinf.model.run_paired` runs the six filters and the
    gamma-swept H-infinity copies on one set of trajectories (agents moved by the scenario's driver).
    Rows: each H-infinity kind against its Kalman counterpart at the configured gamma and at
    ``factor x gamma_0``; and the structural comparisons (decentralized vs local, centralized vs
    decentralized) for both families. ``mean_diff`` = error of ``filter_a`` minus error of ``filter_b``,
    each the mean over the claims' window ``late_start <= k <= horizon`` and the agents, paired per run.

    Parameters
    ----------
    params : dict
        The ``hinf`` configuration; read: ``paired`` (``scenario``, ``targets``, ``runs``, ``seed``,
        ``gamma_factors``), ``claims.late_start``, ``filter.gamma`` and what
        :func:`.model.resolve_scenario` reads.
    inputs : dict
        Only the step's code (no table is read).
    outputs : dict
        ``table``: ``results/hinf/paired_evasive.csv``.

    Returns
    -------
    dict
        ``{"table": DataFrame, "provenance": {"paired": {target: {"gamma0": ..., "driver": ...}}}}``:
        one row per comparison and target (columns in the module docstring), and each target's
        gamma_0 per filter kind and the driver.
    """
    from . import filter_kernels  # noqa: F401  numba: this step runs enough filter updates to pay its load
    cfg, pc = params, params["paired"]
    start = int(cfg["claims"]["late_start"])
    rows, prov = [], {}
    for target in pc["targets"]:
        sc = resolve_scenario(cfg, pc["scenario"], runs=int(pc["runs"]), seed=int(pc["seed"]))
        sc["target"] = target
        res = run_paired(sc, [float(c) for c in pc["gamma_factors"]])
        per_run = {lab: window_means(e, start) for lab, e in res["out"]["errors"].items()}
        g0 = res["gamma0"]
        prov[target] = {"gamma0": g0, "driver": sc["driver"]}

        def row(a, b, gamma, kind):
            mean, se, z = paired_z(per_run[a], per_run[b])
            return {"target": target, "filter_a": res["base"][a], "filter_b": b, "gamma": gamma, "runs": sc["runs"],
                    "mean_diff": mean, "se": se, "z": z, "gamma0": g0.get(kind, np.nan),
                    "gamma_ratio": gamma / g0[kind] if kind in g0 else np.nan, "label_a": a, "driver": sc["driver"],
                    "frac_a_better": float(np.mean(per_run[a] < per_run[b])),
                    "error_a": float(per_run[a].mean()), "error_b": float(per_run[b].mean())}

        for kind in KINDS:
            labels = [kind] + [f"{kind}@{float(c):g}" for c in pc["gamma_factors"]]
            for lab in sorted(labels, key=lambda s: res["gammas"][s]):
                rows.append(row(lab, "kalman_" + kind, res["gammas"][lab], kind))
        g = float(cfg["filter"]["gamma"])
        for a, b, gam in (("decentralized", "local", g), ("centralized", "decentralized", g),
                          ("kalman_decentralized", "kalman_local", np.inf),
                          ("kalman_centralized", "kalman_decentralized", np.inf)):
            rows.append(row(a, b, gam, a if np.isfinite(gam) else ""))
    return {"table": pd.DataFrame(rows), "provenance": {"paired": prov}}


def fig2_horizon_step(params, inputs, outputs):
    """Fig 2's comparison (decentralized vs local) by horizon, agent and integral gain, and the consensus modes.

    Each scenario of ``fig2_horizon.scenarios`` is simulated once to the longest horizon with its own
    seed and ``fig2_horizon.runs`` runs, with the configured ``K_i`` and
    with ``K_i = 0`` (scenario ``<name>_ki0``); a horizon ``H`` uses the window ``late_start <= k <= H``.
    It is also simulated at each other value of ``gamma_c`` and ``K_p`` of ``sensitivity`` (scenario
    ``<name>_gamma_c<v>`` / ``<name>_K_p<v>``; mean over the agents only). The consensus modes
    (:func:`.consensus.pi_consensus_time_constants`) are those of the first scenario's graph (25),
    with the configured ``K_i`` and with ``K_i = 0``;
    their time constants are converted from consensus iterations to filter steps (``consensus.iters``
    iterations per step).

    Parameters
    ----------
    params : dict
        The ``hinf`` configuration; read: ``fig2_horizon`` (``scenarios``, ``horizons``, ``runs``,
        ``interior_agent``), ``claims`` (``late_start``, ``z_significant``), ``sensitivity``
        (``gamma_c``, ``K_p``), ``consensus`` and what :func:`.model.resolve_scenario` reads.
    inputs : dict
        Only the step's code (no table is read).
    outputs : dict
        ``table``, ``series`` and ``modes``: ``results/hinf/per_agent.csv``, ``per_agent_errors.csv``
        and ``consensus_modes.csv``.

    Returns
    -------
    dict
        ``{"table": DataFrame, "series": DataFrame, "modes": DataFrame}``: the columns listed in the
        module docstring.
    """
    from . import filter_kernels  # noqa: F401  numba: this step runs enough filter updates to pay its load
    cfg, fh = params, params["fig2_horizon"]
    start = int(cfg["claims"]["late_start"])
    z_sig = float(cfg["claims"]["z_significant"])
    K = max(int(h) for h in fh["horizons"])
    rows, series, modes = [], [], []
    interior = int(fh["interior_agent"])
    # issue 28: the consensus gains gamma_c and K_p over their declared ranges (sensitivity), mean over agents only
    gain_variants = [(f"_{key}{float(v):g}", {"consensus": {key: float(v)}}, False)
                     for key in ("gamma_c", "K_p") for v in cfg["sensitivity"][key]
                     if float(v) != float(cfg["consensus"][key])]
    variants = [("", {}, True), ("_ki0", {"consensus": {"K_i": 0.0}}, True)] + gain_variants
    for scen in fh["scenarios"]:
        # one simulation per scenario: the variants differ only in the consensus, so they share the target,
        # the measurements and the local filter; each has its own decentralized filter (same numbers as alone)
        sc = resolve_scenario(cfg, scen, horizon=K, runs=int(fh["runs"]))
        sc["filters"] = ["local", "decentralized"]
        sc["consensus_variants"] = {suffix: over["consensus"] for suffix, over, _ in variants if suffix}
        out = simulate(sc)
        for suffix, over, per_agent in variants:
            e_loc, e_dec = out["errors"]["local"], out["errors"][suffix or "decentralized"]
            c = {**sc["consensus"], **over.get("consensus", {})}
            for H in fh["horizons"]:
                H = int(H)
                agents = list(range(e_loc.shape[1])) if per_agent else []
                for agent in agents + [-1]:  # -1: the mean over the agents (the paper's reading)
                    sl = slice(None) if agent < 0 else slice(agent, agent + 1)
                    a = e_dec[:, sl, start:H + 1].mean(axis=(1, 2))
                    b = e_loc[:, sl, start:H + 1].mean(axis=(1, 2))
                    _, se, z = paired_z(a, b)
                    rows.append({"scenario": scen + suffix, "agent": agent, "horizon": H, "local": b.mean(),
                                 "decentralized": a.mean(), "ratio": a.mean() / b.mean(), "z": z, "se": se,
                                 "K_i": c["K_i"], "gamma_c": c["gamma_c"], "K_p": c["K_p"],
                                 "tag": tag_z(z, z_sig)})
            if not per_agent:
                continue
            for agent in sorted({0, min(interior, e_loc.shape[1] - 1)}):
                for fname, e in (("local", e_loc), ("decentralized", e_dec)):
                    series.append(pd.DataFrame({"scenario": scen + suffix, "agent": agent, "filter": fname,
                                                "k": np.arange(K + 1), "error_mean": e[:, agent].mean(0)}))
            if scen == fh["scenarios"][0]:
                lap = laplacian(adjacency(sc["agents0"], sc["radius"]))
                lam = np.linalg.eigvalsh(lap)
                rho, tau = pi_consensus_time_constants(lam, c["gamma_c"], c["h"], c["K_p"], c["K_i"])
                modes.append(pd.DataFrame({"scenario": scen + suffix, "K_i": c["K_i"], "mode": np.arange(len(lam)),
                                           "laplacian_eigenvalue": lam, "modulus": rho,
                                           "time_constant_steps": tau / int(c["iters"])}))
    return {"table": pd.DataFrame(rows), "series": pd.concat(series, ignore_index=True),
            "modes": pd.concat(modes, ignore_index=True)}


def evader_check_step(params, inputs, outputs):
    """Has the evader's inner minimisation (eq (24), over lambda) converged? Decisions replayed and certified.

    The decisions of the first ``evader_check.runs`` runs of ``evasive_hinf`` are replayed with the
    evader's mirror descent at several iteration counts, with pairwise Frank-Wolfe
    (``evader_check.reference_iterations`` iterations) and with the exact solver
    (:func:`~netrepro.papers.hinf.evader.min_fused_trace_exact`), which is the certified reference: every
    candidate's value is bracketed by its duality gap (:func:`~netrepro.papers.hinf.evader.fused_trace_bounds`),
    at most ``EXACT_TOLERANCE`` relative for the exact solver. A choice is certified when its lower bound
    beats every other candidate's upper bound. The loss of a choice is the reference value of the best
    candidate minus that of the chosen one: a wrong choice matters only if this exceeds the reference's
    tolerance (the candidates are otherwise tied). The configured evader (``evader.solver``, and
    ``evader.n_iter`` for mirror descent) is flagged. Second table: the H-infinity vs Kalman comparison of
    ``paired_evasive`` (configured gamma) repeated on ``paired_runs`` runs with the configured evader, the
    mirror-descent evader (``evader.n_iter`` iterations) and the pairwise evader (``pairwise_iterations``).
    ``n_iter`` is 0 for the exact solver (no iterations).

    Parameters
    ----------
    params : dict
        The ``hinf`` configuration; read: ``evader_check`` (``runs``, ``mirror_iterations``,
        ``reference_iterations``, ``paired_runs``, ``pairwise_iterations``), ``evader``,
        ``paired.seed``, ``claims.late_start`` and what :func:`.model.resolve_scenario` reads.
    inputs : dict
        Only the step's code (no table is read).
    outputs : dict
        ``table`` and ``paired``: ``results/hinf/evader_convergence.csv`` and ``evader_paired.csv``.

    Returns
    -------
    dict
        ``{"table": DataFrame, "paired": DataFrame}``: one row per solver and iteration count, and
        one row per evader and filter kind (columns in the module docstring).
    """
    cfg, ec = params, params["evader_check"]
    sc = resolve_scenario(cfg, "evasive_hinf", runs=int(ec["runs"]))
    sc["filters"] = [sc["driver"]]
    out = simulate(sc)
    N = out["agents"].shape[2]
    x = out["target"][:, :-1].reshape(-1, 2)
    P = out["agents"][:, :-1].reshape(-1, N, 2)
    ev = sc["evader"]
    conf_solver = ev.get("solver", "mirror")
    ref = evader_decisions(x, P, sc["model"], ev["step"], ev["n_headings"], 0, "exact")
    idx = np.arange(len(x))
    best_ref = ref["upper"][idx, ref["choice"]]
    rows = []
    mirror = sorted({int(n) for n in ec["mirror_iterations"]} | {int(ev["n_iter"])})  # the configured one always
    for solver, n_iter in [("mirror", n) for n in mirror] + [("pairwise", int(ec["reference_iterations"])), ("exact", 0)]:
        d = ref if solver == "exact" else evader_decisions(x, P, sc["model"], ev["step"], ev["n_headings"], n_iter, solver)
        loss = best_ref - ref["upper"][idx, d["choice"]]
        tol = ref["gap"]
        configured = solver == conf_solver and (solver == "exact" or n_iter == int(ev["n_iter"]))
        rows.append({"solver": solver, "n_iter": n_iter, "configured": configured,
                     "decisions": len(x), "certified_fraction": float(d["certified"].mean()),
                     "same_as_reference": float(np.mean(d["choice"] == ref["choice"])),
                     "median_gap": float(np.median(d["gap"])), "max_gap": float(d["gap"].max()),
                     "median_margin": float(np.median(d["margin"])),
                     "median_value": float(np.median(best_ref)),
                     "max_loss": float(loss.max()), "mean_loss": float(loss.mean()),
                     "loss_above_tolerance_fraction": float(np.mean(loss > tol)),
                     "reference_certified_fraction": float(ref["certified"].mean()),
                     "reference_max_gap": float(ref["gap"].max())})
    # does the premise's verdict depend on the evader's inner solver? same seeds, each evader
    prows = []
    evaders = [(conf_solver, 0 if conf_solver == "exact" else int(ev["n_iter"]))]
    evaders += [e for e in (("mirror", int(ev["n_iter"])), ("pairwise", int(ec["pairwise_iterations"])))
                if e not in evaders]
    for solver, n_iter in evaders:
        sp = resolve_scenario(cfg, "evasive_hinf", runs=int(ec["paired_runs"]), seed=int(cfg["paired"]["seed"]))
        sp["evader"] = {**sp["evader"], "solver": solver, "n_iter": max(n_iter, 1)}
        res = run_paired(sp, [])
        start = int(cfg["claims"]["late_start"])
        for kind in KINDS:
            a = window_means(res["out"]["errors"][kind], start)
            b = window_means(res["out"]["errors"]["kalman_" + kind], start)
            mean, se, z = paired_z(a, b)
            prows.append({"solver": solver, "n_iter": n_iter, "runs": sp["runs"], "filter_a": kind,
                          "filter_b": "kalman_" + kind, "gamma": float(sp["gamma"]), "mean_diff": mean, "se": se, "z": z,
                          "error_a": float(a.mean()), "error_b": float(b.mean())})
    return {"table": pd.DataFrame(rows), "paired": pd.DataFrame(prows)}


def network_step(params, inputs, outputs):
    """Communication links (eq (25)) at the time marks of Fig 6, and the connected fraction of each run.

    For each scenario and run of the trajectories table: the links of eq (25) at each mark
    ``k <= K``; the fraction of steps with a connected graph (second Laplacian eigenvalue > 1e-9), the
    smallest second eigenvalue, and the number of steps at which the graph changed.

    Parameters
    ----------
    params : dict
        The ``hinf`` configuration; read: ``comm_radius`` and ``network.marks``.
    inputs : dict
        ``trajectories``: ``results/hinf/trajectories.csv``.
    outputs : dict
        ``table`` and ``connectivity``: ``results/hinf/network.csv`` and ``connectivity.csv``.

    Returns
    -------
    dict
        ``{"table": DataFrame, "connectivity": DataFrame}``: columns ``scenario, run, k, i, j`` and
        ``scenario, run, steps, connected_fraction, min_lambda2, topology_changes``.
    """
    tr = pd.read_csv(inputs["trajectories"], dtype={"who": str})
    radius = float(params["comm_radius"])
    marks = [int(m) for m in params["network"]["marks"]]
    links, conn = [], []
    for (scen, run), g in tr[tr["who"] != "target"].groupby(["scenario", "run"], sort=True):
        g = g.sort_values(["k", "who"])
        ids = sorted(g["who"].unique(), key=int)
        K = int(g["k"].max())
        pos = np.stack([g[g["who"] == i].sort_values("k")[["x", "y"]].to_numpy() for i in ids], 1)  # (K+1, N, 2)
        adj = adjacency(pos, radius)
        lam2 = np.linalg.eigvalsh(laplacian(adj))[:, 1]
        conn.append({"scenario": scen, "run": int(run), "steps": K + 1, "connected_fraction": float(np.mean(lam2 > 1e-9)),
                     "min_lambda2": float(lam2.min()),
                     "topology_changes": int(topology_changed(adj[:-1], adj[1:]).sum())})
        for k in [m for m in marks if m <= K]:
            for i, j in zip(*np.nonzero(np.triu(adj[k]))):
                links.append({"scenario": scen, "run": int(run), "k": k, "i": ids[i], "j": ids[j]})
    return {"table": pd.DataFrame(links, columns=["scenario", "run", "k", "i", "j"]), "connectivity": pd.DataFrame(conn)}


def fig5_control_step(params, inputs, outputs):
    """Fig 5 re-judged across the control reconstructions: mobile vs stationary decentralized agents, paired.

    For each value of ``sensitivity.Gamma`` and ``sensitivity.v_max`` (the other at its configured value) the
    mobile scenario is simulated with the sensitivity runs, horizon and seed, and compared run by run with the
    stationary scenario simulated once with the same settings (same seed: same target and noise stream).
    The window is ``min(claims.late_start, horizon // 2) <= k <= horizon``.

    Parameters
    ----------
    params : dict
        The ``hinf`` configuration; read: ``sensitivity`` (``horizon``, ``runs``, ``seed``,
        ``mobile_scenario``, ``Gamma``, ``v_max``), ``claims.late_start`` and what
        :func:`.model.resolve_scenario` reads.
    inputs : dict
        Only the step's code (no table is read).
    outputs : dict
        ``table``: ``results/hinf/fig5_control.csv``.

    Returns
    -------
    dict
        ``{"table": DataFrame}``: one row per parameter value (columns in the module docstring).
    """
    cfg, sv = params, params["sensitivity"]
    horizon, runs, seed = int(sv["horizon"]), int(sv["runs"]), int(sv["seed"])
    start = min(int(cfg["claims"]["late_start"]), horizon // 2)
    mobile = sv["mobile_scenario"]
    fixed = resolve_scenario(cfg, "static_fixed", runs=runs, horizon=horizon, seed=seed)
    fixed["filters"] = ["decentralized"]
    b = window_means(simulate(fixed)["errors"]["decentralized"], start)
    rows = []
    for key in ("Gamma", "v_max"):
        for val in sv[key]:
            sc = resolve_scenario(cfg, mobile, runs=runs, horizon=horizon, seed=seed, control={key: val})
            sc["filters"] = [sc["driver"]]
            a = window_means(simulate(sc)["errors"][sc["driver"]], start)
            m, se, z = paired_z(a, b)
            rows.append({"parameter": key, "value": float(val), "runs": runs, "horizon": horizon, "start": start,
                         "stationary": float(b.mean()), "mobile": float(a.mean()), "mean_diff": m, "se": se, "z": z})
    return {"table": pd.DataFrame(rows)}


def evasive_network_step(params, inputs, outputs):
    """Is the Fig-6 network's disconnection what costs the decentralized filter? Per-run connectivity and errors.

    The scenario ``paired.scenario`` is run against each target of ``paired.targets`` (agents moved by its
    driver), with ``paired.network_runs`` runs and seed ``paired.seed``. Window: ``k >= claims.late_start``.

    Parameters
    ----------
    params : dict
        The ``hinf`` configuration; read: ``paired`` (``scenario``, ``targets``, ``network_runs``,
        ``seed``), ``claims.late_start`` and what :func:`.model.resolve_scenario` reads.
    inputs : dict
        Only the step's code (no table is read).
    outputs : dict
        ``table``: ``results/hinf/evasive_network.csv``.

    Returns
    -------
    dict
        ``{"table": DataFrame}``: one row per target and run (``target, run, connected_fraction,
        local, decentralized``).
    """
    from . import filter_kernels  # noqa: F401  numba: the filters and the evader's exact solver compiled (~0.2 s less)
    cfg, pc = params, params["paired"]
    start = int(cfg["claims"]["late_start"])
    rows = []
    for target in pc["targets"]:
        sc = resolve_scenario(cfg, pc["scenario"], runs=int(pc["network_runs"]), seed=int(pc["seed"]))
        sc["target"] = target
        sc["filters"] = ["local", "decentralized"]
        out = simulate(sc)
        conn = np.asarray(out["connected_runs"], dtype=float)[:, start:].mean(1)
        loc, dec = (window_means(out["errors"][f], start) for f in ("local", "decentralized"))
        rows.append(pd.DataFrame({"target": target, "run": np.arange(len(conn)), "connected_fraction": conn,
                                  "local": loc, "decentralized": dec}))
    return {"table": pd.concat(rows, ignore_index=True)}


# --------------------------------------------------------------------------- issue 28: causes and baselines at their best
def _loop_tasks(lv) -> list[tuple[str, str]]:
    """(target, loop) tasks of the closed-loop consensus variants, in a fixed order (shards split this list)."""
    tasks = [(t, loop) for t in lv["targets"] for loop in list(lv["designs"]) + ["local_loop"]]
    # untested reconstructions varied (evasive target, configured PI consensus): loop "pi|<key>=<label>"
    return tasks + [("evasive", f"pi|{r['key']}={r['label']}") for r in lv.get("reconstructions", [])]


def _loop_scenario(cfg, lv, target, loop):
    """The closed loop of one task: agents moved by the filter judged (``local_loop``: by the local filters)."""
    over = {}
    if "|" in loop:  # a reconstruction's other value: the configuration with that key replaced
        rec = next(r for r in lv["reconstructions"] if loop == f"pi|{r['key']}={r['label']}")
        section, name = rec["key"].split(".")
        cfg = {**cfg, section: {**cfg[section], name: rec["value"]}}
        loop = "pi"
    if loop == "p_only":
        over = {"consensus": {"K_i": 0.0, "design": "pi"}}
    elif loop != "local_loop":
        over = {"consensus": {"design": loop}}
    sc = resolve_scenario(cfg, lv["scenario"], runs=int(lv["runs"]), seed=int(lv["seed"]), **over)
    sc["target"] = target
    sc["filters"] = ["local", "decentralized"]
    sc["driver"] = "local" if loop == "local_loop" else "decentralized"
    return sc


def loop_variants_shard_step(params, inputs, outputs):
    """Step: per-run late errors of the closed-loop consensus variants (issue 28, part 1), one shard of tasks.

    A task is (target, loop): ``loop`` is a consensus design of ``loop_variants.designs`` (``pi`` the
    configured PI consensus (5), ``pi_reset`` its integral states reset at each topology change, ``p_only``
    K_i = 0, ``exact_component`` exact sums over each connected piece, ``complete`` the PI consensus on a
    complete graph), whose decentralized filter moves the agents, or ``local_loop``, where the local filters
    move them. Every task uses seed ``loop_variants.seed``: same target start, measurement-noise stream and
    initial estimates in every loop, so the loops are paired by run. Tasks are split over
    ``n_shards`` contiguous shards (:func:`netrepro.engines.montecarlo.shard_blocks`); each task is computed
    the same way in any shard, so the merged table does not depend on the shard count.

    Parameters
    ----------
    params : dict
        ``cfg`` (the ``hinf`` configuration's entries ``loop_variants``, ``claims`` and what
        :func:`.model.resolve_scenario` reads), ``shard`` (this shard's index) and ``n_shards``.
    inputs : dict
        Only the step's code (no table is read).
    outputs : dict
        ``table`` (``results/hinf/shards/loop_variants_<shard>.csv``).

    Returns
    -------
    dict
        ``{"table": DataFrame, "provenance": {"tasks": [...]}}``: one row per task and run (late
        errors of the local and decentralized filters, connected fraction, topology changes) and
        the task indices of this shard.
    """
    from netrepro.engines.montecarlo import shard_blocks

    from . import filter_kernels  # noqa: F401  numba: enough filter updates to pay its load
    cfg, lv = params["cfg"], params["cfg"]["loop_variants"]
    start = int(cfg["claims"]["late_start"])
    tasks = _loop_tasks(lv)
    mine = shard_blocks(len(tasks), 1, int(params["n_shards"]), int(params["shard"]))
    frames = []
    for t in mine:
        target, loop = tasks[int(t)]
        sc = _loop_scenario(cfg, lv, target, loop)
        out = simulate(sc)
        conn = np.asarray(out["connected_runs"], dtype=float)[:, start:].mean(1)
        frames.append(pd.DataFrame({
            "task": int(t), "target": target, "loop": loop, "driver": sc["driver"], "run": np.arange(sc["runs"]),
            "local": window_means(out["errors"]["local"], start),
            "decentralized": window_means(out["errors"]["decentralized"], start),
            "connected_fraction": conn, "topology_changes": out["topology_changes"]}))
    cols = ["task", "target", "loop", "driver", "run", "local", "decentralized", "connected_fraction",
            "topology_changes"]
    table = pd.concat(frames, ignore_index=True) if frames else pd.DataFrame(columns=cols)
    return {"table": table, "provenance": {"tasks": [int(t) for t in mine]}}


def loop_variants_merge_step(params, inputs, outputs):
    """Step: the closed-loop consensus variants' comparisons (``loop_variants.csv``) from the shards.

    Per target and loop: the connected fraction and the number of topology changes (per run, over the
    horizon; means and their standard errors over runs), and two paired comparisons, each tagged ``holds`` / ``not significant`` / ``reversed`` at the
    Bonferroni-corrected two-sided level ``tests.alpha`` over every comparison of the table (fixed before
    the runs):

    - ``same_paths``: decentralized minus local filter on the loop's own paths (exact pairing: same target,
      agents and measurements);
    - ``vs_local_loop``: the loop's decentralized filter minus the local filter of the loop steered by the
      local filters (the abstract's "system using only local estimates"); the paths differ, so the pairing is
      by seed (same run index: same target start, noise stream and initial estimate), a paired test on the run
      means.

    Parameters
    ----------
    params : dict
        The ``hinf`` configuration (``loop_variants.targets`` and ``tests.alpha`` are read).
    inputs : dict
        ``shards``: the shard tables of :func:`loop_variants_shard_step`.
    outputs : dict
        ``table`` (``results/hinf/loop_variants.csv``) and ``runs``
        (``results/hinf/loop_variants_runs.csv``).

    Returns
    -------
    dict
        ``{"table": DataFrame, "runs": DataFrame}``: one row per target, loop and comparison (means,
        paired difference, standard error, z, ``z_crit`` and ``tag``), and the per-run shard rows
        merged in task order.
    """
    runs = pd.concat([pd.read_csv(p) for p in inputs["shards"]], ignore_index=True)
    runs = runs.sort_values(["task", "run"]).drop(columns="task").reset_index(drop=True)
    lv = params["loop_variants"]
    rows = []
    for target in lv["targets"]:
        g = runs[runs["target"] == target]
        order = list(dict.fromkeys(g["loop"]))
        base = g[g["loop"] == "local_loop"].set_index("run")["local"]
        for loop in order:
            r = g[g["loop"] == loop].set_index("run")
            common = dict(target=target, loop=loop, driver=r["driver"].iloc[0], runs=len(r),
                          connected_fraction=float(r["connected_fraction"].mean()),
                          connected_fraction_se=float(r["connected_fraction"].std(ddof=1) / math.sqrt(len(r))),
                          topology_changes=float(r["topology_changes"].mean()),
                          topology_changes_se=float(r["topology_changes"].std(ddof=1) / math.sqrt(len(r))),
                          topology_changes_min=int(r["topology_changes"].min()),
                          topology_changes_max=int(r["topology_changes"].max()))
            comps = [("same_paths", r["decentralized"], r["local"])]
            if loop != "local_loop" and "|" not in loop:
                comps.append(("vs_local_loop", r["decentralized"], base.reindex(r.index)))
            for comp, a, b in comps:
                m, se, z = paired_z(a.to_numpy(), b.to_numpy())
                rows.append({**common, "comparison": comp, "error_a": float(a.mean()), "error_b": float(b.mean()),
                             "mean_diff": m, "se": se, "z": z, "frac_a_better": float(np.mean(a < b))})
    table = pd.DataFrame(rows)
    zc = bonferroni_z(float(params["tests"]["alpha"]), len(table))
    table["z_crit"] = zc
    table["tag"] = [tag_z(z, zc) for z in table["z"]]
    return {"table": table, "runs": runs}


def _kalman_tasks(kb) -> list[tuple[str, str]]:
    """(target, phase) tasks of the Kalman-at-its-best comparison; phase ``select`` or ``judge``."""
    return [(t, ph) for t in kb["targets"] for ph in ("select", "judge")]


def _displacement(path, lag: int) -> float:
    """Mean distance the target moves in ``lag`` steps, over runs and start steps."""
    p = np.asarray(path, dtype=float)
    return float(np.linalg.norm(p[:, lag:] - p[:, :-lag], axis=-1).mean()) if p.shape[1] > lag else np.nan


def recorded_evader_paths(sc: dict, seed: int):
    """Target paths of the evader (eqs (19)-(24)) recorded in the closed loop of ``sc`` run with another seed.

    Replayed in runs of ``sc``'s own seed, such a path moves exactly as an evader moves (same step, same
    turning) but does not react to these runs' agents: their measurement noise and initial estimates differ
    from those of the recording, so their agents go elsewhere. The control target of ``F_kalman_at_best``.

    Parameters
    ----------
    sc : dict
        A resolved scenario (:func:`.model.resolve_scenario`); its driver moves the agents of the recording.
    seed : int
        Seed of the recording (must differ from ``sc["seed"]``, or the replay is the closed loop itself).

    Returns
    -------
    ndarray, shape ``(runs, horizon + 1, 2)``
        The recorded target paths.

    Raises
    ------
    InputError
        If ``seed`` equals the scenario's seed.
    """
    if int(seed) == int(sc["seed"]):
        raise InputError(f"the recording seed {seed} is the runs' own seed: the replayed evader would still react")
    rec = simulate({**sc, "target": "evasive", "seed": int(seed), "filters": [sc["driver"]]})
    return rec["target"]


def kalman_best_shard_step(params, inputs, outputs):
    """Step: per-run late errors of H-infinity filters (several gamma) and Kalman filters (several design W)
    on the same trajectories, for each target model and phase (issue 28, part 2); one shard of tasks.

    Phase ``select`` (``kalman_best.select_runs`` runs, seed ``select_seed``) picks each family's best setting;
    phase ``judge`` (``judge_runs``, seed ``judge_seed``, separate runs) is where they are compared.
    Targets: ``evasive`` (eqs (19)-(24)), ``evader_replay`` (non-reactive: evader paths recorded in closed
    loops of other seeds, ``kalman_best.replay_seeds[phase]``, replayed; :func:`recorded_evader_paths`),
    ``drift`` (non-reactive, the evader's step length in a fixed heading), ``evasive_noise`` (the evader plus
    white noise W) and ``random``. Shards as in
    :func:`loop_variants_shard_step`.

    Parameters
    ----------
    params : dict
        ``cfg`` (the ``hinf`` configuration's entries ``kalman_best``, ``claims`` and what
        :func:`.model.resolve_scenario` reads), ``shard`` (this shard's index) and ``n_shards``.
    inputs : dict
        Only the step's code (no table is read).
    outputs : dict
        ``table`` (``results/hinf/shards/kalman_best_<shard>.csv``).

    Returns
    -------
    dict
        ``{"table": DataFrame, "provenance": {"tasks": [...]}}``: one row per task, filter and run
        (family, kind, gamma, ``W_factor``, late error, target displacement, ``fused_trace``: the run's
        late-window mean of the evader's objective tr Q_fused, :func:`.evader.fused_trace_along`) and the
        task indices of this shard.
    """
    from netrepro.engines.montecarlo import shard_blocks

    from . import filter_kernels  # noqa: F401
    cfg, kb = params["cfg"], params["cfg"]["kalman_best"]
    start = int(cfg["claims"]["late_start"])
    tasks = _kalman_tasks(kb)
    mine = shard_blocks(len(tasks), 1, int(params["n_shards"]), int(params["shard"]))
    frames = []
    for t in mine:
        target, phase = tasks[int(t)]
        runs, seed = (int(kb["select_runs"]), int(kb["select_seed"])) if phase == "select" else \
            (int(kb["judge_runs"]), int(kb["judge_seed"]))
        sc = resolve_scenario(cfg, kb["scenario"], runs=runs, seed=seed)
        sc["target"] = target
        if target == "evader_replay":
            sc.update(target="replay", target_path=recorded_evader_paths(sc, int(kb["replay_seeds"][phase])))
        res = run_paired(sc, [float(c) for c in kb["gamma_factors"]], [float(f) for f in kb["W_factors"]])
        disp = _displacement(res["out"]["target"], int(kb["displacement_lag"]))
        # the evader's objective (19) along this task's paths, late window (steps start..K of tr Q_fused)
        fz = fused_trace_along(res["out"]["target"], res["out"]["agents"], sc["model"])[:, start - 1:].mean(1)
        for lab, e in res["out"]["errors"].items():
            base = res["base"][lab]
            frames.append(pd.DataFrame({
                "task": int(t), "target": target, "phase": phase, "label": lab, "family": "kalman" if FILTER_KINDS[base][1] else "hinf",
                "kind": FILTER_KINDS[base][0], "gamma": res["gammas"][lab],
                "W_factor": res["w_factor"].get(lab, 1.0), "run": np.arange(runs), "error": window_means(e, start),
                "displacement": disp, "fused_trace": fz}))
    cols = ["task", "target", "phase", "label", "family", "kind", "gamma", "W_factor", "run", "error", "displacement",
            "fused_trace"]
    table = pd.concat(frames, ignore_index=True) if frames else pd.DataFrame(columns=cols)
    return {"table": table, "provenance": {"tasks": [int(t) for t in mine]}}


def kalman_best_merge_step(params, inputs, outputs):
    """Step: H-infinity against Kalman filters at their best (``kalman_best.csv``) from the shards.

    For each target and filter kind of ``kalman_best.kinds`` (judge runs, paired per run: same
    trajectories and measurements): the configured H-infinity filter (gamma = ``filter.gamma``) against the
    Kalman filter at each design W (``W_factor`` x W), and the best H-infinity setting against the best
    Kalman setting, both chosen on the ``select`` runs (smallest mean late error; the judge runs never
    choose). Each row is tagged at the Bonferroni-corrected two-sided level ``tests.alpha`` over every
    row of the table. ``displacement`` is the target's mean ``lag``-step displacement (judge runs).

    Parameters
    ----------
    params : dict
        The ``hinf`` configuration (``kalman_best``, ``filter.gamma`` and ``tests.alpha`` are read).
    inputs : dict
        ``shards``: the shard tables of :func:`kalman_best_shard_step`.
    outputs : dict
        ``table`` (``results/hinf/kalman_best.csv``) and ``fused`` (``results/hinf/evader_fused.csv``).

    Returns
    -------
    dict
        ``{"table": DataFrame, "fused": DataFrame}``: one row per target, kind and comparison (labels, means,
        paired difference, standard error, z, ``z_crit``, ``tag`` and displacement), and the evader's objective
        against the other targets (:func:`fused_comparisons`).
    """
    runs = pd.concat([pd.read_csv(p) for p in inputs["shards"]], ignore_index=True)
    runs = runs.sort_values(["task", "label", "run"], kind="stable").drop(columns="task").reset_index(drop=True)
    cfg, kb = params, params["kalman_best"]
    gamma = float(cfg["filter"]["gamma"])
    rows = []
    for target in kb["targets"]:
        for kind in kb["kinds"]:
            sel = runs[(runs["target"] == target) & (runs["phase"] == "select") & (runs["kind"] == kind)]
            jud = runs[(runs["target"] == target) & (runs["phase"] == "judge") & (runs["kind"] == kind)]
            means = sel.groupby(["family", "label"])["error"].mean()
            best = {fam: means[fam].idxmin() for fam in ("hinf", "kalman")}
            per = {lab: g.sort_values("run")["error"].to_numpy() for lab, g in jud.groupby("label")}
            info = jud.drop_duplicates("label").set_index("label")
            disp = float(jud["displacement"].iloc[0])

            def row(comp, a, b):
                m, se, z = paired_z(per[a], per[b])
                return {"target": target, "kind": kind, "comparison": comp, "label_a": a, "label_b": b,
                        "gamma_a": float(info.loc[a, "gamma"]), "W_factor_b": float(info.loc[b, "W_factor"]),
                        "runs": len(per[a]), "error_a": float(per[a].mean()), "error_b": float(per[b].mean()),
                        "mean_diff": m, "se": se, "z": z, "frac_a_better": float(np.mean(per[a] < per[b])),
                        "displacement": disp}

            kal = info[info["family"] == "kalman"].sort_values("W_factor")
            for lab in kal.index:
                rows.append(row(f"gamma={gamma:g} vs W_f={kal.loc[lab, 'W_factor']:g}", kind, lab))
            rows.append(row("best vs best", best["hinf"], best["kalman"]))
    table = pd.DataFrame(rows)
    zc = bonferroni_z(float(params["tests"]["alpha"]), len(table))
    table["z_crit"] = zc
    table["tag"] = [tag_z(z, zc) for z in table["z"]]
    return {"table": table, "fused": fused_comparisons(runs, float(params["tests"]["alpha"]))}


def fused_comparisons(runs: pd.DataFrame, alpha: float, reference: str = "evasive") -> pd.DataFrame:
    """Does the evader raise its objective? Late-window ``tr Q_fused`` (19)-(24) of the evasive target against the
    other targets of ``kalman_best`` on the judge runs, paired by seed (``evader_fused.csv``).

    Each target's judge runs share the seed, hence the agents' start, noise stream and initial estimates; the paths
    differ (the agents react to the target they see). Tagged at the two-sided Bonferroni level over the rows.

    Parameters
    ----------
    runs : DataFrame
        Merged shard rows of :func:`kalman_best_shard_step` (``target, phase, label, run, fused_trace``).
    alpha : float
        Family-wise two-sided level.
    reference : str
        The target the others are compared with (arm a).

    Returns
    -------
    DataFrame
        ``target_a, target_b, runs, fused_a, fused_b, mean_diff, se, z, frac_a_higher, z_crit, tag`` (``tag``
        ``holds`` here means the reference's value is significantly *lower*; ``reversed``: higher).
    """
    jud = runs[runs["phase"] == "judge"]
    per = {t: g[g["label"] == g["label"].iloc[0]].sort_values("run")["fused_trace"].to_numpy()
           for t, g in jud.groupby("target", sort=False)}
    rows = []
    for t, b in per.items():
        if t == reference or reference not in per:
            continue
        a = per[reference]
        m, se, z = paired_z(a, b)
        rows.append({"target_a": reference, "target_b": t, "runs": len(a), "fused_a": float(a.mean()),
                     "fused_b": float(b.mean()), "mean_diff": m, "se": se, "z": z, "frac_a_higher": float(np.mean(a > b))})
    cols = ["target_a", "target_b", "runs", "fused_a", "fused_b", "mean_diff", "se", "z", "frac_a_higher"]
    table = pd.DataFrame(rows, columns=cols)
    zc = bonferroni_z(float(alpha), max(1, len(table)))
    table["z_crit"] = zc
    table["tag"] = [tag_z(z, zc) for z in table["z"]]
    return table


# --------------------------------------------------------------------------- issue 28: why Fig 6's paths zig-zag
def fig6_paths_step(params, inputs, outputs):
    """Why do Fig 6's agent paths zig-zag? Heading reversals, strokes and their direction under control variants.

    The scenario ``fig6_paths.scenario`` (agents moved by its driver) is run with the configured
    control law and with each variant of ``fig6_paths.variants``, which replaces keys of ``control``:
    ``steer_on_truth`` (each agent steers by the true target position instead of its estimate),
    a smaller gain ``Gamma`` of eq (12), a smaller speed limit ``v_max``, ``recursion: false`` (the
    gradient of Sigma without the recursion (14): dDelta = 0). Every variant uses the same seeds, so its
    per-run statistics are compared run by run (:func:`.model.paired_z`) with its ``baseline`` (default
    ``nominal``; another variant's label, e.g. steering by the truth with and without (14)); each ``family``
    (default ``control``) is Bonferroni-corrected over its own variants at ``tests.alpha``. Where both arms
    are the same in every run (steering by the truth: nothing random moves agents or target) the difference
    is exact, its ``z`` infinite or NaN and its tag ``exact``.

    Parameters
    ----------
    params : dict
        The ``hinf`` configuration; read: ``fig6_paths`` (``scenario``, ``runs``, ``seed``,
        ``variants``), ``tests.alpha``, ``claims.late_start`` and what :func:`.model.resolve_scenario` reads.
    inputs : dict
        Only the step's code (no table is read).
    outputs : dict
        ``table``: ``results/hinf/fig6_paths.csv``; ``paths``: ``results/hinf/fig6_paths_run0.csv``.

    Returns
    -------
    dict
        ``{"table": DataFrame, "paths": DataFrame}``. ``table``: one row per variant (``variant``, ``family``,
        ``baseline``, ``runs``, ``reversal_fraction``, ``reversal_se``, ``clipped_fraction``, ``mean_step``,
        ``stroke_median`` (median over runs of the runs' median stroke length, steps), ``one_step_strokes``,
        ``tangential_share``, ``tangential_se``, ``topology_changes``, ``connected_fraction``, ``error_late``, and
        against the baseline run by run ``reversal_diff``, ``reversal_diff_se``, ``z``, ``z_crit``, ``tag``).
        ``paths``: run 0's agent and target positions (``variant, k, who, x, y``; ``who`` is the agent index
        or ``target``).
    """
    cfg, fp = params, params["fig6_paths"]
    start = int(cfg["claims"]["late_start"])
    variants = [{"label": "nominal", "control": {}, "family": ""}] + [
        {"family": "control", "baseline": "nominal", **v} for v in fp["variants"]]
    fam_size = {}
    for v in variants[1:]:
        fam_size[v["family"]] = fam_size.get(v["family"], 0) + 1
    rows, paths, rev_of = [], [], {}
    for v in variants:
        sc = resolve_scenario({**cfg, "control": {**cfg["control"], **v["control"]}}, fp["scenario"],
                              runs=int(fp["runs"]), seed=int(fp["seed"]))
        sc["filters"] = [sc["driver"]]
        out = simulate(sc)
        stats = path_statistics(out["agents"], float(sc["control"]["v_max"]), out["target"])
        rev = stats["reversal_fraction"]
        rev_of[v["label"]] = rev
        tang = stats["tangential_share"]
        row = {"variant": v["label"], "family": v["family"], "baseline": v.get("baseline", ""), "runs": len(rev),
               "reversal_fraction": float(rev.mean()), "reversal_se": float(rev.std(ddof=1) / math.sqrt(len(rev))),
               "clipped_fraction": float(stats["clipped_fraction"].mean()), "mean_step": float(stats["mean_step"].mean()),
               "stroke_median": float(np.nanmedian(stats["stroke_median"])) if np.isfinite(stats["stroke_median"]).any() else np.nan,
               "one_step_strokes": float(np.nanmean(stats["one_step_strokes"])) if np.isfinite(stats["one_step_strokes"]).any() else np.nan,
               "tangential_share": float(tang.mean()), "tangential_se": float(tang.std(ddof=1) / math.sqrt(len(tang))),
               "topology_changes": float(np.mean(out["topology_changes"])),
               "connected_fraction": float(np.asarray(out["connected_runs"], dtype=float).mean()),
               "error_late": float(window_means(out["errors"][sc["driver"]], start).mean())}
        if v["label"] == "nominal":
            row.update(reversal_diff=0.0, reversal_diff_se=0.0, z=np.nan, z_crit=np.nan, tag="")
        else:
            z_crit = bonferroni_z(float(cfg["tests"]["alpha"]), fam_size[v["family"]])
            mean, se, z = paired_z(rev, rev_of[v["baseline"]])
            exact = bool(np.ptp(rev) == 0 and np.ptp(rev_of[v["baseline"]]) == 0)
            row.update(reversal_diff=mean, reversal_diff_se=se, z=z, z_crit=z_crit,
                       tag="exact" if exact else tag_z(z, z_crit))
        rows.append(row)
        ags, tgt = np.asarray(out["agents"])[0], np.asarray(out["target"])[0]
        k = np.arange(ags.shape[0])
        for i in range(ags.shape[1]):
            paths.append(pd.DataFrame({"variant": v["label"], "k": k, "who": str(i), "x": ags[:, i, 0], "y": ags[:, i, 1]}))
        paths.append(pd.DataFrame({"variant": v["label"], "k": k, "who": "target", "x": tgt[:, 0], "y": tgt[:, 1]}))
    return {"table": pd.DataFrame(rows), "paths": pd.concat(paths, ignore_index=True)}


# --------------------------------------------------------------------------- issue 37: the fixed-path swap
def design_consensus(design: str) -> dict:
    """The consensus entries of a design of ``loop_swap.designs`` (``p_only``: the PI consensus (5) with K_i = 0).

    Parameters
    ----------
    design : str
        ``pi``, ``pi_reset``, ``p_only``, ``exact_component`` or ``complete``.

    Returns
    -------
    dict
        The entries of the ``consensus`` section this design replaces.
    """
    return {"K_i": 0.0, "design": "pi"} if design == "p_only" else {"design": design}


def _setting_cfg(cfg: dict, setting: dict) -> dict:
    """The configuration of one setting of ``loop_swap.settings``: ``key`` (``section.name``) replaced by ``value``."""
    if "key" not in setting:
        return cfg
    section, name = setting["key"].split(".")
    return {**cfg, section: {**cfg[section], name: setting["value"]}}


def _swap_tasks(ls) -> list[tuple[int, str]]:
    """(setting index, loop) tasks of the fixed-path swap, in a fixed order (shards split this list)."""
    return [(i, loop) for i, s in enumerate(ls["settings"]) for loop in list(s["loops"]) + ["local_loop"]]


def loop_swap_shard_step(params, inputs, outputs):
    """Step: the fixed-path swap (issue 37), one shard of its closed loops.

    A task is (setting, loop). The loop is closed by the decentralized filter of one consensus design
    (``loop`` in ``loop_swap.designs``) or by the local filters (``local_loop``) and its agents' paths are
    recorded; on those same paths, target path and measurement-noise draws, every design of
    ``loop_swap.designs`` runs open loop beside the local filters (a decentralized filter per design on its own
    consensus (5), :func:`.model.simulate`'s ``consensus_variants``: only the driver moves the agents). Every task
    uses seed ``loop_swap.seed`` (same target start, noise stream and initial estimates), so every design is
    paired with every other on one loop's paths exactly and across loops by seed. A setting replaces one
    configuration key (the evader's step, the four-agent layout).

    Parameters
    ----------
    params : dict
        ``cfg`` (the ``hinf`` configuration's entries ``loop_swap``, ``claims`` and what
        :func:`.model.resolve_scenario` reads), ``shard`` and ``n_shards``.
    inputs : dict
        Only the step's code.
    outputs : dict
        ``table`` (``results/hinf/shards/loop_swap_<shard>.csv``).

    Returns
    -------
    dict
        ``{"table": DataFrame, "provenance": {"tasks": [...]}}``: one row per task, filter and run (``setting,
        loop, driver, filter`` = ``local`` or a design, ``run``, late ``error``, ``connected_fraction``,
        ``topology_changes`` of the loop's paths).
    """
    from netrepro.engines.montecarlo import shard_blocks

    from . import filter_kernels  # noqa: F401
    cfg, ls = params["cfg"], params["cfg"]["loop_swap"]
    start = int(cfg["claims"]["late_start"])
    tasks = _swap_tasks(ls)
    mine = shard_blocks(len(tasks), 1, int(params["n_shards"]), int(params["shard"]))
    frames = []
    for t in mine:
        i, loop = tasks[int(t)]
        setting = ls["settings"][i]
        own = "pi" if loop == "local_loop" else loop  # the design of the filter named "decentralized"
        sc = resolve_scenario(_setting_cfg(cfg, setting), ls["scenario"], runs=int(ls["runs"]), seed=int(ls["seed"]),
                              consensus=design_consensus(own))
        sc["target"] = "evasive"
        sc["filters"] = ["local", "decentralized"]
        sc["driver"] = "local" if loop == "local_loop" else "decentralized"
        base = dict(_setting_cfg(cfg, setting)["consensus"])  # every entry: a variant does not inherit own's K_i
        sc["consensus_variants"] = {f"design:{d}": {**base, **design_consensus(d)} for d in ls["designs"] if d != own}
        out = simulate(sc)
        conn = np.asarray(out["connected_runs"], dtype=float)[:, start:].mean(1)
        errs = {"local": out["errors"]["local"], own: out["errors"]["decentralized"],
                **{d: out["errors"][f"design:{d}"] for d in ls["designs"] if d != own}}
        for name in ["local"] + list(ls["designs"]):
            frames.append(pd.DataFrame({
                "task": int(t), "setting": setting["label"], "loop": loop, "driver": sc["driver"], "filter": name,
                "run": np.arange(sc["runs"]), "error": window_means(errs[name], start), "connected_fraction": conn,
                "topology_changes": out["topology_changes"]}))
    cols = ["task", "setting", "loop", "driver", "filter", "run", "error", "connected_fraction", "topology_changes"]
    table = pd.concat(frames, ignore_index=True) if frames else pd.DataFrame(columns=cols)
    return {"table": table, "provenance": {"tasks": [int(t) for t in mine]}}


def swap_comparisons(runs: pd.DataFrame, designs, alpha: float) -> pd.DataFrame:
    """The paired comparisons of the fixed-path swap (``loop_swap.csv``), Bonferroni-tagged over all of them.

    Per setting (``a - b``, per-run late errors; ``pairing`` ``exact`` on one loop's paths, ``seed`` across
    loops):

    - ``fixed_paths``: on loop L's paths, design d's decentralized filter minus the local filters (every L, d);
    - ``fixed_paths_vs_pi``: on loop L's paths, design d minus the PI design (d != pi);
    - ``system``: design d's decentralized filter in the loop it closes minus the local filters of the loop the
      local filters close (the abstract's comparison of systems);
    - ``system_vs_pi``: design d in its own loop minus PI in its own loop (d != pi): the designs ranked as systems;
    - ``steering_local``: the local filters in the loop d closes minus the local filters in the local loop: what
      steering by d's fused estimate does to the local filters' own error.

    Parameters
    ----------
    runs : DataFrame
        The merged shard rows of :func:`loop_swap_shard_step` (``setting, loop, filter, run, error,
        connected_fraction, topology_changes``).
    designs : sequence of str
        The designs of ``loop_swap.designs`` (PI among them).
    alpha : float
        Family-wise two-sided level; each row is tagged at ``bonferroni_z(alpha, number of rows)``.

    Returns
    -------
    DataFrame
        ``setting, comparison, loop, design, pairing, runs, error_a, error_b, mean_diff, se, z, frac_a_better,
        connected_fraction, topology_changes, z_crit, tag``.
    """
    rows = []
    for setting in dict.fromkeys(runs["setting"]):
        g = runs[runs["setting"] == setting]
        loops = list(dict.fromkeys(g["loop"]))
        e = {(lp, f): h.sort_values("run")["error"].to_numpy() for (lp, f), h in g.groupby(["loop", "filter"])}
        net = g.groupby("loop")[["connected_fraction", "topology_changes"]].mean()

        def add(comp, loop, design, pairing, a, b):
            m, se, z = paired_z(a, b)
            rows.append({"setting": setting, "comparison": comp, "loop": loop, "design": design, "pairing": pairing,
                         "runs": len(a), "error_a": float(a.mean()), "error_b": float(b.mean()), "mean_diff": m,
                         "se": se, "z": z, "frac_a_better": float(np.mean(a < b)),
                         "connected_fraction": float(net.loc[loop, "connected_fraction"]),
                         "topology_changes": float(net.loc[loop, "topology_changes"])})

        for lp in loops:
            for d in designs:
                add("fixed_paths", lp, d, "exact", e[(lp, d)], e[(lp, "local")])
            for d in designs:
                if d != "pi":
                    add("fixed_paths_vs_pi", lp, d, "exact", e[(lp, d)], e[(lp, "pi")])
        closed = [lp for lp in loops if lp != "local_loop"]
        for d in closed:
            add("system", d, d, "seed", e[(d, d)], e[("local_loop", "local")])
        for d in closed:
            if d != "pi" and "pi" in closed:
                add("system_vs_pi", d, d, "seed", e[(d, d)], e[("pi", "pi")])
        for d in closed:
            add("steering_local", d, d, "seed", e[(d, "local")], e[("local_loop", "local")])
    table = pd.DataFrame(rows)
    zc = bonferroni_z(float(alpha), max(1, len(table)))
    table["z_crit"] = zc
    table["tag"] = [tag_z(z, zc) for z in table["z"]]
    return table


def loop_swap_merge_step(params, inputs, outputs):
    """Step: the fixed-path swap's comparisons (``loop_swap.csv``) from the shards (see :func:`swap_comparisons`).

    Parameters
    ----------
    params : dict
        The ``hinf`` configuration (``loop_swap.designs`` and ``tests.alpha`` are read).
    inputs : dict
        ``shards``: the tables of :func:`loop_swap_shard_step`.
    outputs : dict
        ``table`` (``results/hinf/loop_swap.csv``) and ``runs`` (``results/hinf/loop_swap_runs.csv``).

    Returns
    -------
    dict
        ``{"table": DataFrame, "runs": DataFrame}``.
    """
    runs = pd.concat([pd.read_csv(p) for p in inputs["shards"]], ignore_index=True)
    runs = runs.sort_values(["task", "filter", "run"], kind="stable").drop(columns="task").reset_index(drop=True)
    table = swap_comparisons(runs, list(params["loop_swap"]["designs"]), float(params["tests"]["alpha"]))
    return {"table": table, "runs": runs}
