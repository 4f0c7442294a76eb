"""Claims, errata and reconstructions of the `hinf` paper: the paper's side of each check next to ours."""

from __future__ import annotations

import json
import math

import numpy as np
import pandas as pd

from ...claims import claim_row, claims_frame, errata_frame, reconstructions_frame
from .algebra import rotation
from .model import SCENARIOS
from .motion import control_law, printed_control_law, printed_sigma_gradient, sigma_gradient
from .noise import (NoiseModel, fit_noise_model, geometry, noise_covariance, noise_information, noise_variances,
                    printed_dinfo_dtheta, sample_noise)

__all__ = ["PAPER", "RECON", "errata_step", "sensitivity_text", "evader_text", "evader_robustness", "reconstructions_step", "claims_step"]

PAPER = "hinf"


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


def evader_robustness(inputs) -> str:
    """Note on the premise: the H-infinity vs Kalman z-scores with the configured and the better-converged evader."""
    if "evader_paired" not in inputs:
        return ""
    ep = pd.read_csv(inputs["evader_paired"])
    parts = []
    for (solver, n_iter, runs), g in ep.groupby(["solver", "n_iter", "runs"], sort=False):
        parts.append(f"{solver} x{n_iter} ({runs} runs): " + ", ".join(f"{r.filter_a} {r.z:.1f}" for r in g.itertuples()))
    return " Evader's inner solver (results/hinf/evader_paired.csv, z at the configured gamma): " + "; ".join(parts) + "."


def evader_text(ev: pd.DataFrame) -> str:
    """A sentence summarising ``evader_convergence.csv``: is the evader's inner minimisation converged?"""
    parts = []
    for r in ev.itertuples():
        parts.append(f"{r.solver} x{r.n_iter}{' (configured)' if r.configured else ''}: choice certified in "
                     f"{r.certified_fraction:.1%} of {r.decisions} decisions, same as the certified reference in "
                     f"{r.same_as_reference:.1%}, objective lost mean {r.mean_loss:.2g} / max {r.max_loss:.2g} "
                     f"(median value {r.median_value:.3g})")
    conf = ev[ev["configured"]]
    verdict = ""
    if len(conf):
        c = conf.iloc[0]
        state = "converged" if c["certified_fraction"] >= 0.99 else "NOT converged"
        verdict = (f". The configured solver is {state}: its certified tolerance (median duality gap {c['median_gap']:.2g}) "
                   f"is far above the median difference {c['median_margin']:.2g} between the best and second-best candidate "
                   f"steps, so {1 - c['certified_fraction']:.1%} of its choices are uncertified and "
                   f"{c['loss_above_tolerance_fraction']:.0%} lose more than the reference's tolerance; raising the "
                   f"mirror-descent iterations tenfold does not fix it (see the rows above)")
    return "convergence check (results/hinf/evader_convergence.csv): " + "; ".join(parts) + verdict


def reconstructions_step(params, inputs, outputs):
    """Every parameter the paper leaves unstated: key, value, reason, sensitivity."""
    sens = pd.concat([pd.read_csv(inputs["sensitivity"]), pd.read_csv(inputs["sensitivity_evasive"])], ignore_index=True)
    rows = []
    for key, reason, sweep in RECON:
        sensitivity = sensitivity_text(sens, sweep) if sweep else "not swept; see the reason"
        if sweep == "gamma":
            sensitivity += " | evasive target (gamma = inf: Kalman-driven agents): " + sensitivity_text(sens, "gamma_evasive")
        if key == "evader.n_iter" and "evader" in inputs:
            sensitivity = evader_text(pd.read_csv(inputs["evader"]))
        rows.append({"paper": PAPER, "key": f"hinf.{key}", "value": _get(params, key), "reason": reason,
                     "sensitivity": sensitivity})
    return {"table": reconstructions_frame(rows)}


# --------------------------------------------------------------------------- claims
def claims_step(params, inputs, outputs):
    """Each statement of the paper as a measurable comparison with a computed verdict."""
    cfg = params
    rows = []
    nf = pd.read_csv(inputs["noise_fit"])
    fit = fit_noise_model(nf["r"], nf["var_range"], nf["var_bearing"])
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
                          note=f"settle k: stationary local {int(sl['settle_k'])}, mobile decentralized {int(md['settle_k'])} (-1: never); "
                               f"separating motion from decentralization (Fig 4, green): stationary decentralized settles at "
                               f"k = {int(sd['settle_k'])}, so the quicker settling comes from decentralization; motion lowers "
                               f"the late error ({sd['late_mean']:.3f} -> {md['late_mean']:.3f})"))
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
    # the premise, decided on one set of trajectories (results/hinf/paired_evasive.csv)
    pe = pd.read_csv(inputs["paired_evasive"])
    hk = pe[pe["filter_b"] == "kalman_" + pe["filter_a"]]
    ev_rows, rnd_rows = hk[hk["target"] == "evasive"], hk[hk["target"] == "random"]
    used = float(cfg["filter"]["gamma"])

    def zs(df):
        return ", ".join(f"{r.filter_a} {r.z:.1f}" for r in df[df["label_a"] == df["filter_a"]].itertuples())

    runs = int(ev_rows["runs"].iloc[0]) if len(ev_rows) else 0
    rows.append(claim_row(PAPER, "future_hinf_beats_kalman_evasive",
                          "premise (Section VII): the H-infinity filter outperforms the Kalman filter against an evasive target",
                          True, bool(len(ev_rows) and (ev_rows["z"] < -z_sig).all()), 0,
                          f"boolean: for every filter kind and every swept gamma, the paired difference (H-inf minus Kalman, "
                          f"same trajectories and measurements, {runs} runs) is below -{z_sig} standard errors",
                          note=f"all filters on the same trajectories (agents moved by {ev_rows['driver'].iloc[0] if len(ev_rows) else '?'}); "
                               f"z at gamma = {used:g}: {zs(ev_rows)}; over gamma/gamma_0 in "
                               f"[{ev_rows['gamma_ratio'].min():.2f}, {ev_rows['gamma_ratio'].max():.2f}] the largest z is "
                               f"{ev_rows['z'].max():.1f}. Against the random-walk target (same agents' driver): z at gamma = "
                               f"{used:g}: {zs(rnd_rows)}, i.e. H-infinity pays off only against the evasive target. "
                               "(The earlier unpaired design, each filter driving its own agents, gave z = -1.6: undecided.)"
                               + evader_robustness(inputs)))
    # Fig 2 by horizon, agent and integral gain (results/hinf/per_agent.csv)
    pa = pd.read_csv(inputs["per_agent"])
    modes = pd.read_csv(inputs["modes"])
    f2 = pa[pa["scenario"] == "fig2"]
    f2k = pa[pa["scenario"] == "fig2_ki0"]
    slow = modes[(modes["scenario"] == "fig2") & (modes["laplacian_eigenvalue"] > 1e-9)]["time_constant_steps"].max()
    by_h = "; ".join(f"H={h}: ratio dec/local {g['ratio'].min():.2f}..{g['ratio'].max():.2f}, "
                     f"{int((g['z'] < -z_sig).sum())}/{len(g)} agents better" for h, g in f2.groupby("horizon"))
    by_hk = "; ".join(f"H={h}: {g['ratio'].min():.2f}..{g['ratio'].max():.2f}, {int((g['z'] < -z_sig).sum())}/{len(g)}"
                      for h, g in f2k.groupby("horizon"))
    rows.append(claim_row(PAPER, "fig2_decentralized_beats_local_every_agent_horizon",
                          "Fig 2 read robustly: the decentralized filter beats the local one for every agent, not only on "
                          "average over the first 200 steps",
                          True, bool(len(f2) and (f2["z"] < -z_sig).all()), 0,
                          f"boolean: paired per-agent difference below -{z_sig} standard errors at every agent and horizon "
                          f"(window late_start..H)",
                          note=f"PI consensus (K_i = {cfg['consensus']['K_i']}): {by_h}. The slow mode of (5) on the path graph "
                               f"has time constant {slow:.0f} steps, so the consensus estimates drift over the horizon and the end "
                               f"agents lose first. With K_i = 0: {by_hk}."))
    return {"table": claims_frame(rows)}


