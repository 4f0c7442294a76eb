"""Evidence of the `markov` paper (issue 15): every value, variant, residual and computed note that
its claims, errata, reconstructions and findings (the YAML files beside this module) are judged on.

Nothing here states a claim, a paper value or a tolerance; this module only computes.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from ...verdicts import erratum_evidence, evidence_frame
from .certificates import parity_growth, parity_structure
from .lmis import schur_residual
from .model import (
    H_matrix, L_operator, LinearSystem, gilbert_elliott_stationary_loss, h_radius, observability_index,
    parity_bound_example2, phi_lyapunov, prop1_bound, riccati_g, riccati_h, spectral_abs,
)
from .steps import load_moments

__all__ = ["evidence_step", "enumerate_norms", "transition_codes", "path_weights", "mean_norm_enumerated",
           "monotonicity_violation", "prop1_closed_form", "single_transition"]


# ----------------------------------------------------------------------------- helpers (pure)
def prop1_closed_form(lam_abs: float, q):
    """The closed form printed in Section 5.1: ``(1 - |lambda|^2 (1-q)) / (|lambda|^4 q)``.

    Parameters
    ----------
    lam_abs : float
        ``|lambda_A|``.
    q : array_like
        Recovery rates.

    Returns
    -------
    ndarray
        The printed bound on ``p``.
    """
    q = np.asarray(q, dtype=float)
    return (1.0 - lam_abs ** 2 * (1.0 - q)) / (lam_abs ** 4 * q)


def enumerate_norms(system: LinearSystem, Sigma0, k_max: int):
    """``||P_k||`` on every channel path ``gamma_1..gamma_{k-1}``, ``k = 1..k_max`` (recursion under eq. 3).

    ``P_{k+1} = g(P_k)`` if ``gamma_k = 1`` else ``h(P_k)`` (eqs. 4-5, the model's maps). Brute force
    over all ``2^(k-1)`` paths, independent of :mod:`.exact` (which groups paths by transition counts).

    Parameters
    ----------
    system : LinearSystem
        ``A, C, Q, R``.
    Sigma0 : array_like
        ``P_1``.
    k_max : int
        Largest ``k``.

    Returns
    -------
    list of (ndarray, ndarray)
        Per ``k``: the paths ``(2^(k-1), k-1)`` of 0/1 and ``||P_k||`` on each.
    """
    A, C, Q, R = (np.asarray(x, float) for x in (system.A, system.C, system.Q, system.R))
    P = np.asarray(Sigma0, float)[None]
    G = np.zeros((1, 0), dtype=int)
    out = [(G, np.linalg.eigvalsh(P)[:, -1])]
    for _ in range(1, k_max):
        P = np.concatenate([riccati_h(P, A, Q), riccati_g(P, A, C, Q, R)])
        G = np.concatenate([np.c_[G, np.zeros(len(G), int)], np.c_[G, np.ones(len(G), int)]])
        out.append((G, np.linalg.eigvalsh(P)[:, -1]))
    return out


def transition_codes(G) -> np.ndarray:
    """Transition of every step of each path ``G``: 0 for 1 -> 1, 1 for 1 -> 0, 2 for 0 -> 1, 3 for 0 -> 0.

    Parameters
    ----------
    G : ndarray
        ``(N, t)`` paths of 0/1, ``t >= 1``.

    Returns
    -------
    ndarray
        ``(N, t - 1)`` integer codes (independent of ``p, q``: computed once per set of paths).
    """
    a, b = G[:, :-1], G[:, 1:]
    return np.where(a == 1, np.where(b == 1, 0, 1), np.where(b == 1, 2, 3))


def path_weights(G, p: float, q: float, gamma1: int, codes=None) -> np.ndarray:
    """Probability of each path ``G`` (rows ``gamma_1..gamma_t``) given ``gamma_1``, under eq. (3).

    Parameters
    ----------
    G : ndarray
        ``(N, t)`` paths of 0/1.
    p, q : float
        Failure and recovery rates.
    gamma1 : int
        The conditioning initial state.
    codes : ndarray, optional
        :func:`transition_codes` of ``G`` (computed here if not given).

    Returns
    -------
    ndarray
        ``(N,)`` weights (zero for paths starting elsewhere).
    """
    if G.shape[1] == 0:
        return np.ones(len(G))
    if codes is None:
        codes = transition_codes(G)
    step = np.array([1 - p, p, q, 1 - q], dtype=float)[codes]  # the step probabilities of eq. (3)
    return np.where(G[:, 0] == gamma1, 1.0, 0.0) * np.prod(step, axis=1)


def mean_norm_enumerated(paths, p: float, q: float, start: str = "gamma1", codes=None) -> np.ndarray:
    """``E||P_k||``, ``k = 1..k_max``, from :func:`enumerate_norms`.

    Parameters
    ----------
    paths : list
        From :func:`enumerate_norms`.
    p, q : float
        Failure and recovery rates.
    start : {"gamma1", "stationary"}
        ``gamma_1 = 1`` (the paper's convention below eq. 3) or ``gamma_1`` drawn from the
        stationary law ``P(gamma = 1) = q / (p + q)`` (the proof of Proposition 2).
    codes : list, optional
        :func:`transition_codes` of each ``G`` of ``paths`` (for many ``p, q`` on the same paths).

    Returns
    -------
    ndarray
        ``(k_max,)``.
    """
    codes = codes if codes is not None else [None] * len(paths)
    one = np.array([w @ n for w, n in ((path_weights(G, p, q, 1, c), n) for (G, n), c in zip(paths, codes))])
    if start == "gamma1":
        return one
    zero = np.array([w @ n for w, n in ((path_weights(G, p, q, 0, c), n) for (G, n), c in zip(paths, codes))])
    zero[0] = one[0]
    pi1 = q / (p + q)
    return pi1 * one + (1 - pi1) * zero


def monotonicity_violation(means, ps, rtol: float = 0.0):
    """Largest ``(E_{p2}||P_k|| - E_{p1}||P_k||) / E_{p1}||P_k||`` over ``p2 < p1`` on a grid (proof of Prop. 2).

    Parameters
    ----------
    means : ndarray
        ``(len(ps), K)``: ``E_p||P_k||`` for increasing ``ps``.
    ps : array_like
        Increasing failure rates.
    rtol : float
        Relative excesses up to this are rounding and count as none (``markov.prop2.rtol``).

    Returns
    -------
    dict
        ``violation`` (0 means monotone to ``rtol``), ``p1``, ``p2``, ``k``, ``e_p1``, ``e_p2``.
    """
    ps = np.asarray(ps, float)
    runmax = np.maximum.accumulate(means, axis=0)
    arg = np.zeros(means.shape, dtype=int)
    for i in range(1, len(ps)):  # index of the running maximum (small grids)
        arg[i] = np.where(means[i] >= runmax[i - 1], i, arg[i - 1])
    viol = (runmax - means) / means
    viol = np.where(viol > rtol, viol, 0.0)
    i, k = np.unravel_index(np.argmax(viol), viol.shape)
    j = arg[i, k]
    return {"violation": float(viol[i, k]), "p1": float(ps[i]), "p2": float(ps[j]), "k": int(k + 1),
            "e_p1": float(means[i, k]), "e_p2": float(means[j, k])}


def single_transition(smap: pd.DataFrame):
    """Whether, at every ``q`` of the certified map, every bounded ``p`` lies below every unbounded ``p`` (Prop. 2).

    Parameters
    ----------
    smap : DataFrame
        ``stability_map.csv`` (columns ``example, p, q, verdict``).

    Returns
    -------
    (bool, str)
        The property over all examples and ``q``, and a note with the counts.
    """
    bad, n_cols, parts = 0, 0, []
    for name, s in smap.groupby("example", sort=True):
        b = s[s.verdict == "bounded"].groupby("q").p.max()
        u = s[s.verdict == "unbounded"].groupby("q").p.min()
        both = b.index.intersection(u.index)
        viol = int((b[both] >= u[both]).sum())
        bad, n_cols = bad + viol, n_cols + s.q.nunique()
        parts.append(f"Example {name}: {viol} of {s.q.nunique()} q with a bounded p above an unbounded p, "
                     f"{int((s.verdict == 'undecided').sum())} undecided points")
    return bool(bad == 0), "; ".join(parts)


# ----------------------------------------------------------------------------- evidence blocks
def _section51_rows(ex1, checks, curves):
    A1, C1 = np.asarray(ex1["A"], float), np.asarray(ex1["C"], float)
    lam1 = spectral_abs(A1)
    lo1 = observability_index(A1, C1)
    p_prop1 = float(prop1_bound(lam1, np.array([0.65]), lo1)[0])
    closed = float(prop1_closed_form(lam1, 0.65))
    rho0 = h_radius(A1, C1, [np.zeros((A1.shape[0], C1.shape[0]))], p_prop1, 0.65)
    st = gilbert_elliott_stationary_loss
    ck = checks
    pth = float(np.interp(0.65, curves[curves.example == "I"].q, curves[curves.example == "I"].p_thm5_uncapped))
    rows = [
        dict(quantity="exI.p_prop1_q065", value=p_prop1,
             note=f"eq. (8) with the computed observability index l_o = {lo1} (Definition 2, rank test); the printed "
                  f"closed form gives {closed:.10f} (difference {abs(closed - p_prop1):.1e})"),
        dict(quantity="exI.loss_rate_p004", value=st(0.04, 0.65), note="stationary law p / (p + q) of eq. (3)"),
        dict(quantity="exI.loss_rate_prop1", value=st(p_prop1, 0.65),
             note=f"at the exact bound p = {p_prop1:.5f}; at the rounded p = 0.22 it is {st(0.22, 0.65):.5f}"),
        dict(quantity="exI.rho_H0_at_prop1", value=rho0,
             note="rho(H(K = 0)) (eq. 7) times p at the Proposition 1 bound: Proposition 1 is Theorem 1 with K = 0"),
    ]
    for name, check in (("exI.thm2_feasible_p1", "exI_thm2_p1"), ("exI.fig3_certified", "exI_fig3_p05"),
                        ("exI.fig4_certified", "exI_thm2_p099")):
        r = ck.loc[check]
        note = (f"(p, q) = ({r.p:g}, {r.q:g}): {r.evidence}; rho(H(K)) = {r.rho_H:.4f} at the solver's K; solver "
                f"status {r.status} (information only)")
        if check == "exI_thm2_p1":
            note += f"; Theorem 5 bound at q = 0.65 (uncapped, interpolated) ~ {pth:.3f} > 1, so every eps works"
        if check == "exI_fig3_p05":
            note += f"; Proposition 1 bound at q = 0.65 is {p_prop1:.4f} < 0.5 (it does not cover Fig 3)"
        rows.append(dict(quantity=name, value=bool(r.certified and r.verdict == "feasible"), note=note))
    return rows


def _section52_rows(ex2, checks, tight, moments, growth_margins, growth_margin):
    lam2 = spectral_abs(ex2["A"])
    A2, C2 = np.asarray(ex2["A"], float), np.asarray(ex2["C"], float)
    lo2 = observability_index(A2, C2)
    ck = checks
    lower, upper = float(ck.loc["exII_q05_tight_lower", "p"]), float(ck.loc["exII_q05_tight_upper", "p"])
    analytic = float(parity_bound_example2(lam2, 0.5))
    rows = [
        dict(quantity="exII.not_one_step_observable", value=bool(lo2 > 1),
             note=f"observability index l_o = {lo2} (Definition 2); |lambda_i| = {np.abs(np.linalg.eigvals(A2)).round(6)}"),
        dict(quantity="exII.p_thm5_q05", value=lower,
             note=f"certified bisection bracket [{lower:.9f}, {upper:.9f}] (lower end: "
                  f"{ck.loc['exII_q05_tight_lower', 'evidence']}; upper end: {ck.loc['exII_q05_tight_upper', 'evidence']}); "
                  f"closed form of the true critical value (1 - (|l|^2 (1-q))^2) / (|l|^4 q) = {analytic:.9f} lies "
                  f"{'inside' if lower <= analytic <= upper else 'OUTSIDE'} the bracket"),
    ]
    for t in tight[tight.check == "exII_q05"].itertuples():
        rows.append(dict(quantity="exII.p_thm5_q05", variant=f"tight_tol={t.tol:g}", value=float(t.p_lower)))
    r = ck.loc["exII_thm5_p0465"]
    rows.append(dict(quantity="exII.p0465_certified", value=bool(r.certified and r.verdict == "feasible"),
                     note=f"at p = {r.p:g} the LMI is certified {r.verdict} ({r.evidence}); p_underline = {lower:.6f}"))
    r = ck.loc["exII_thm2_p1"]
    rows.append(dict(quantity="exII.lmi_p1_infeasible", value=bool(r.verdict == "infeasible"),
                     note=f"{r.evidence}; solver status {r.status} (information only)"))
    r = ck.loc["exII_fig5_p045"]
    rows.append(dict(quantity="exII.fig5_certified", value=bool(r.certified and r.verdict == "feasible"),
                     note=f"{r.evidence}; {r.p:g} < p_underline = {lower:.6f}"))
    st = parity_structure(ex2["A"], ex2["C"], ex2["Q"])
    rate = float(parity_growth(st["lam"], 0.99, 0.5)) if st is not None else np.nan
    em2 = load_moments(moments, "II")
    ex = em2.mean(0.99, 0.5, "norm")
    note = (f"certified parity lower bound on E||P_k|| grows at {rate:.4f} per step (x {np.exp(2 * rate):.4f} every 2 "
            f"steps = |lambda|^4 (pq + (1-q)^2)); exact E||P_k|| at k = {len(ex)}: {ex[-1]:.4g}; verdict = rate > "
            f"growth_margin (map.certify.growth_margin = {growth_margin:g})")
    rows.append(dict(quantity="exII.fig6_diverges", value=bool(rate > growth_margin), note=note))
    for m in growth_margins:
        rows.append(dict(quantity="exII.fig6_diverges", variant=f"growth_margin={m:g}", value=bool(rate > m)))
    return rows, lower, analytic


def _curve_rows(curves, params):
    rows = []
    c = curves
    less = float((c.p_thm5_uncapped - c.p_prop1_uncapped).min())
    worst = c.loc[(c.p_thm5_uncapped - c.p_prop1_uncapped).idxmin()]
    rows.append(dict(quantity="thm2_vs_prop1.min_gap", value=bool(less >= 0.0),
                     note=f"min over {len(c)} (example, q) of p_thm5 (certified-feasible end) - p_prop1 = {less:.4g} "
                          f"(Example {worst.example}, q = {worst.q:.4f})"))
    gap = c.p_reference - c.p_thm5
    bad = int((gap < 0).sum())
    rows.append(dict(quantity="thm5.lower_bound_holds", value=bool(bad == 0),
                     note=f"p_thm5 <= p_c (reference curve) at {len(c) - bad} of {len(c)} (example, q); min p_c - p_thm5 "
                          f"= {gap.min():.3g}; Example I p_c = 1 (non-degenerate [18]), Example II p_c from the parity "
                          "derivation"))
    c2 = c[c.example == "II"]
    inside = (c2.p_reference >= c2.p_thm5) & (c2.p_reference <= c2.p_thm5_upper)
    dev = float((c2.p_reference - c2.p_thm5).abs().max())
    rows.append(dict(quantity="thm5.exII_equals_reference", value=dev,
                     note=f"max over {len(c2)} q in ({c2.q.min():.4f}, {c2.q.max():.4f}) of |p_c - p_thm5|; p_c lies "
                          f"inside the certified bracket [p_thm5, p_thm5_upper] at {int(inside.sum())} of {len(c2)} q "
                          f"(bracket width <= {float((c2.p_thm5_upper - c2.p_thm5).max()):.2g}, bisection tolerance "
                          f"{params['curves']['bisection_tol']:g}); all brackets certified: "
                          f"{bool(c2.thm5_certified.astype(str).str.lower().eq('true').all())}"))
    c1 = c[c.example == "I"]
    rows.append(dict(quantity="thm5.exI_gap", value=float((1.0 - c1.p_thm5).max()),
                     note=f"Example I (p_c = 1 for q > q_necessary): Theorem 5 below 1 for q < "
                          f"{float(c1[c1.p_thm5_uncapped >= 1].q.min()):.4f} (largest gap at q = {c1.q.min():.4f})"))
    return rows


def _iid_rows(iid, tol):
    r1, r2 = iid.loc["I"], iid.loc["II"]
    d1 = float(r1.lambda_lmi_upper - r1.q_thm5_on_iid_line)
    tol_text = f"bisection tolerance iid.tol = {tol:g}"
    note = "; ".join(
        f"Example {n}: Sinopoli LMI certifies arrival rate q >= {r.lambda_lmi_upper:.6f}, Theorem 5 certifies "
        f"q >= {r.q_thm5_on_iid_line:.6f} (on p = 1 - q), true lambda_c = {r.lambda_c_reference:.6f}; Theorem 5 "
        f"certifies {r.lambda_lmi_upper - r.q_thm5_on_iid_line:+.6f} more"
        for n, r in (("I", r1), ("II", r2))) + f"; {tol_text}"
    return [dict(quantity="iid.sinopoli_minus_thm5", value=d1, note=note)]


def _map_rows(smap, curves, params):
    far = params["map"]["far"]
    contra, und, far_und, est_wrong, notes = 0, 0, 0, 0, []
    for name in ("I", "II"):
        s = smap[smap.example == name]
        ref = curves[curves.example == name]
        lam = spectral_abs(params["examples"][name]["A"])
        nec = lam ** 2 * (1 - s.q) < 1
        p_thm5 = np.interp(s.q, ref.q, ref.p_thm5, left=0.0)
        c = int((((s.verdict == "unbounded") & nec & (s.p < p_thm5 - 0.01)) | ((s.verdict == "bounded") & ~nec)).sum())
        u = int((s.verdict == "undecided").sum())
        f = int(((s.verdict == "undecided") & (s.dist_critical.astype(float) >= far)).sum())
        est = s.verdict_estimator
        w = int((((est == "bounded") & (s.verdict == "unbounded")) | ((est == "unbounded") & (s.verdict == "bounded"))).sum())
        contra, und, far_und, est_wrong = contra + c, und + u, far_und + f, est_wrong + w
        notes.append(f"Example {name}: {c} contradictions, {u} of {len(s)} undecided ({f} at distance >= {far:g}), "
                     f"estimator contradicts at {w} and leaves {int((est == 'undecided').sum())} undecided")
    single, detail = single_transition(smap)
    return [dict(quantity="map.single_transition", value=single, note=detail),
            dict(quantity="map.contradictions", value=contra + far_und, note="; ".join(notes)),
            dict(quantity="map.estimator_contradictions", value=est_wrong, note="; ".join(notes))]


def _prop2_rows(params, moments):
    """Finite-k monotonicity in p (proof of Proposition 2), gamma_1 = 1 and stationary start."""
    cfg = params["prop2"]
    ps = np.linspace(cfg["p_min"], cfg["p_max"], cfg["p_points"])
    rows, worst, worst_stat = [], None, None
    for name in cfg["examples"]:
        ex = params["examples"][name]
        em = load_moments(moments, name)
        paths = enumerate_norms(LinearSystem.from_config(ex), ex["Sigma0"], cfg["k_max"])
        codes = [transition_codes(G) if G.shape[1] else None for G, _ in paths]
        for q in cfg["q"]:
            g1 = monotonicity_violation(em.mean(ps, q, "norm"), ps, cfg["rtol"])
            stat = monotonicity_violation(np.array([mean_norm_enumerated(paths, p, q, "stationary", codes) for p in ps]), ps, cfg["rtol"])
            g1.update(example=name, q=q, K=em.depth + 1)
            stat.update(example=name, q=q, K=cfg["k_max"])
            worst = g1 if worst is None or g1["violation"] > worst["violation"] else worst
            worst_stat = stat if worst_stat is None or stat["violation"] > worst_stat["violation"] else worst_stat

    def txt(w, what):
        return (f"{what}: Example {w['example']}, q = {w['q']:g}, k = {w['k']}: E_p2||P_k|| = {w['e_p2']:.6g} at p2 = "
                f"{w['p2']:.4g} > E_p1||P_k|| = {w['e_p1']:.6g} at p1 = {w['p1']:.4g} (relative {w['violation']:.3g}; "
                f"p2 + q = {w['p2'] + w['q']:.3g})")
    grid = (f"grid p = {cfg['p_min']:g}..{cfg['p_max']:g} ({cfg['p_points']} points), q in {cfg['q']}, examples "
            f"{cfg['examples']}")
    note1 = (txt(worst, f"gamma_1 = 1, exact E||P_k|| for k <= {worst['K']}") if worst["violation"] > 0
             else f"gamma_1 = 1: no violation for k <= {worst['K']}") + f"; {grid}; rounding tolerance {cfg['rtol']:g}"
    note2 = (txt(worst_stat, f"stationary gamma_1, enumerated k <= {cfg['k_max']}") if worst_stat["violation"] > 0
             else f"stationary gamma_1 (all 2^(k-1) paths, k <= {cfg['k_max']}): no decrease in p beyond the "
                  f"rounding tolerance {cfg['rtol']:g} (relative)") + f"; {grid}"
    # the coupled chain of Fig. 1 has the weight 1 - q - p2 on (0,1) -> (0,1): negative iff p2 + q > 1
    rows.append(dict(quantity="prop2.violation_gamma1", value=worst["violation"], note=note1))
    rows.append(dict(quantity="prop2.violation_stationary", value=worst_stat["violation"], note=note2))
    rows += erratum_evidence(
        "E10_prop2_signed_measure", worst["violation"], max(worst_stat["violation"], 0.0),
        f"largest relative excess of E_p2 over E_p1 (p2 < p1) that the signed-measure ordering would "
        f"exclude; the coupled chain's weight (0,1) -> (0,1) is 1 - q - p2 = "
        f"{1 - worst['q'] - worst['p2']:.3g} < 0 there. {note1}")
    return rows


def _errata_rows(ex1, lower, analytic, seed, printed_p):
    A1, C1 = np.asarray(ex1["A"], float), np.asarray(ex1["C"], float)
    rng = np.random.default_rng(seed)
    schur = schur_residual(A1, C1, 0.5, 0.65, rng)
    K = [rng.standard_normal((2, 1))]
    Xr, Pr = np.eye(2) + 0.1, np.diag([2.0, 0.5])
    lhs = np.trace(L_operator(A1, C1, K, 0.5, 0.65, Xr) @ Pr)
    HP = (H_matrix(A1, C1, K, 0.5, 0.65) @ Pr.reshape(-1, order="F")).real.reshape(2, 2, order="F")
    adj = abs(lhs - np.trace(Xr @ HP))
    m = C1.shape[0]
    phi0 = phi_lyapunov(A1, np.zeros_like(A1), 0.65)
    return [
        dict(quantity="E1_C_i_undefined.residual_corrected", value=max(schur, adj),
             note=f"Schur residual {schur:.1e}, adjoint residual {adj:.1e}"),
        *erratum_evidence("E2_eq11_last_block", float(m), 0.0, f"row mismatch of the printed block: m = {m}"),
        *erratum_evidence("E3_exII_0465", printed_p - lower, abs(analytic - lower),
                          f"{printed_p:g} - certified p_underline; closed form {analytic:.9f}"),
        *erratum_evidence("E7_phi_definite", float(np.linalg.eigvalsh(phi0)[0]), None,
                          "smallest eigenvalue of Phi_X at X = 0 (Example I, q = 0.65): not positive definite"),
    ]


def _reconstruction_rows(params, sens, tight):
    ex, sp, xc, mp = params["examples"], params["paths"], params["expectations"], params["map"]
    mc, mr, es = mp["certify"], mp["refine"], params["estimator"]

    def changed(threshold):
        s = sens[sens.threshold == threshold]
        return "map_sensitivity.csv: points changed per value: " + "; ".join(
            f"{r.example} {r.value:g}: {int(r.n_changed)}" for r in s.itertuples())
    vals = {
        "examples.Sigma0": (f"{ex['I']['Sigma0']} / {ex['II']['Sigma0']}", ""),
        "checks.eps": (params["checks"]["eps"], ""),
        "checks.tight_tol": (params["checks"]["tight_tol"], "tight_variants.csv: certified bracket per tolerance: " + "; ".join(
            f"{t.check} tol {t.tol:g}: [{t.p_lower:.9f}, {t.p_upper:.9f}]" for t in tight.itertuples())),
        "paths.horizon": (sp["horizon"], ""),
        "paths.seed": (sp["seed"], ""),
        "paths.n_paths": (f"{sp['n_paths']} / {sp['rb_paths']} (rb_paths, horizon {sp['rb_horizon']})", ""),
        "exact.depth": (params["exact"]["depth"], ""),
        "expectations.split_depth": (xc["split_depth"], ""),
        "expectations.estimator": (f"n_paths {xc['n_paths']}, z_max {xc['z_max']}, rel_tol {xc['rel_tol']}, "
                                   f"seed {xc['seed']}", ""),
        "expectations.backtest_k0": (xc["backtest_k0"], ""),
        "estimator.interval_z": (es["interval_z"], ""),
        "estimator.deterministic_rtol": (es["deterministic_rtol"], ""),
        "map.certify.rho_margin": (mc["rho_margin"], changed("certify.rho_margin")),
        "map.certify.growth_margin": (mc["growth_margin"], changed("certify.growth_margin")),
        "map.certify.n_gaps": (mc["n_gaps"], changed("certify.n_gaps")),
        "map.far": (mp["far"], ""),
        "map.estimator_tol": (f"{mp['bounded_tol']} / {mp['unbounded_tol']}",
                              changed("bounded_tol") + "; " + changed("unbounded_tol")),
        "map.refine": (", ".join(f"{k}={v}" for k, v in mr.items()),
                       changed("refine.bounded_tol") + "; " + changed("refine.unbounded_tol") + "; " + changed("refine.rel_tol")),
        "curves.p_uncapped_max": (params["curves"]["p_uncapped_max"], ""),
        "prop2.grid": (f"p {params['prop2']['p_min']}..{params['prop2']['p_max']} ({params['prop2']['p_points']}), "
                       f"q {params['prop2']['q']}, k_max {params['prop2']['k_max']}", ""),
    }
    return [dict(quantity=f"reconstruction.{k}", value=str(v), note=n) for k, (v, n) in vals.items()]


def evidence_step(params, inputs, outputs):
    """Step of rule ``markov_evidence``: ``results/evidence/markov.csv``.

    ``params``: the ``markov`` configuration (examples, checks, curves, iid, paths, exact, expectations,
    map, estimator, prop2, errata_seed); ``inputs``: ``checks, tight, curves, iid, map, sensitivity, moments``.
    """
    ex1, ex2 = params["examples"]["I"], params["examples"]["II"]
    checks = pd.read_csv(inputs["checks"]).set_index("check")
    curves = pd.read_csv(inputs["curves"])
    iid = pd.read_csv(inputs["iid"]).set_index("example")
    smap = pd.read_csv(inputs["map"], keep_default_na=False)
    sens = pd.read_csv(inputs["sensitivity"])
    moments = pd.read_csv(inputs["moments"])
    rows = _section51_rows(ex1, checks, curves)
    tight = pd.read_csv(inputs["tight"])
    r52, lower, analytic = _section52_rows(ex2, checks, tight, moments, params["map"]["sensitivity"]["growth_margin"],
                                           params["map"]["certify"]["growth_margin"])
    rows += r52
    rows += _curve_rows(curves, params)
    rows += _iid_rows(iid, params["iid"]["tol"])
    rows += _map_rows(smap, curves, params)
    rows += _prop2_rows(params, moments)
    # the printed p_underline(0.5) is the configured check point exII_thm5_p0465 (not typed here)
    rows += _errata_rows(ex1, lower, analytic, params["errata_seed"], float(checks.loc["exII_thm5_p0465", "p"]))
    rows += _reconstruction_rows(params, sens, tight)
    return {"table": evidence_frame(rows)}
