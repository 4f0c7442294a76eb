"""Evidence of the `onebit` paper: our side of every claim, erratum, reconstruction and finding.

Table ``results/evidence/onebit.csv`` (``quantity, variant, value, note``), read by the shared
verdict step (:func:`netrepro.judging.verdicts.verdicts_step`) together with the paper's side in
``claims.yaml``, ``errata.yaml``, ``reconstructions.yaml`` and ``findings.yaml`` beside this
module. Assembly only: every value comes from the math modules (:mod:`.randomwalk`,
:mod:`.model`, :mod:`.fisher`, :mod:`.estimators`) or the result tables. Every claim that
depends on a reconstruction is re-judged across that reconstruction's declared range, one key at
a time, and a variant row that does so is labelled ``<key>: ...`` or ``<key>=<value>`` with the
key of ``reconstructions.yaml`` (issue 27, convention 2):

- ``snr_grid_db``: the low-SNR end of the figure axis (lost in extraction): the grid start and
  ``evidence.low_snr_db``;
- ``alpha_to_1``: the configured ``1 - alpha`` values beside the alpha -> 1 limit of Fig 2;
- ``snr_definition``: the other reading (SNR = sigma_z^2 / sigma_eta^2), for the claims that name
  a place on the SNR axis;
- ``low_snr_regime``, ``medium_snr_regime``: the upper ends of 'the low' and 'the low to medium'
  SNR regime (``evidence.low_regime_max_db``, ``evidence.medium_regime_max_db``; first nominal);
- ``estimator``: the other simulated alphas and the two halves of the runs.

Settings of the evidence (which SNRs a note quotes, where an erratum is demonstrated) are the
``at:`` fields of ``claims.yaml``, ``findings.yaml`` and ``errata.yaml`` beside the input
``findings_file``, by id (:meth:`netrepro.judging.paperdata.PaperData.settings`). No statement, paper value
or tolerance is held here; notes are computed.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.special import ndtri

from ...judging.paperdata import load_paper_data
from ...judging.verdicts import erratum_evidence, evidence_frame
from .estimators import binomial_coverage, paired_ratio_interval, pooled_se_ratio
from .fisher import (
    ACHIEVABLE_LIMIT_SNR_MAX_DB,
    achievable_rho_s_crossing_limit,
    achievable_rho_s_limit_db,
    expected_fisher_1bit,
    rho_s_zero_crossing_limit,
)
from .model import axis_shift_db, prior_check, sigma_z2_from_snr, snr_grid, stationary_variance, vector_check
from .randomwalk import (
    ratio_window,
    ratios_at,
    ratios_without_mean_reversion,
    rho_s_threshold_eps,
    rho_s_zero_crossing,
    rw_lag_needed,
    rw_scalar_check,
    snr_shift_deviation,
    variance_sum_check,
)
from .shards import RATIO_DEFS, estimator_cases, merged_runs

__all__ = [
    "alpha_label",
    "variant_label",
    "low_snr_cases",
    "errata_rows",
    "evidence_step",
]

INNOVATION = "innovation"


def alpha_label(eps: float) -> str:
    """``'alpha -> 1'`` for ``eps = 0``, else ``'alpha = 1 - eps'``: how the evidence notes name an alpha.

    Parameters
    ----------
    eps : float
        ``1 - alpha`` of the random walk (21); 0 stands for the alpha -> 1 limit.

    Returns
    -------
    str
        ``"alpha -> 1"``, or ``"alpha = 1 - <eps>"`` with ``eps`` in ``format(eps, 'g')``.
    """
    return "alpha -> 1" if eps == 0 else f"alpha = 1 - {eps:g}"


def variant_label(key: str, text: str) -> str:
    """The label of a variant row inside the declared range of reconstruction ``key``: ``'<key>: <text>'``.

    Parameters
    ----------
    key : str
        The reconstruction's key (``reconstructions.yaml``), e.g. ``"snr_grid_db"``.
    text : str
        What differs from the nominal setting, e.g. ``"alpha = 1 - 0.01, SNR = -10 dB"``.

    Returns
    -------
    str
        ``"<key>: <text>"``.
    """
    return f"{key}: {text}"


def low_snr_cases(nominal_eps: float, grid_start: float, other_ends, other_eps) -> list:
    """(eps, snr) cases of a low-SNR claim: the nominal first, then each other end and each other alpha.

    The nominal alpha and the alpha -> 1 limit (``eps = 0``) are taken at every low-SNR end
    (``grid_start``, then ``other_ends``); every other alpha only at ``grid_start``. ``other_eps``
    should hold 0 for the limit; duplicates of the nominal (and repeated cases) are dropped.

    Parameters
    ----------
    nominal_eps : float
        ``1 - alpha`` of the claim's nominal case (0: the alpha -> 1 limit).
    grid_start : float
        The nominal low-SNR end (dB): the start of ``snr_grid_db``.
    other_ends : iterable of float
        The other low-SNR ends (dB) of the declared range (``evidence.low_snr_db``).
    other_eps : iterable of float
        The other ``1 - alpha`` values the claim is re-judged at.

    Returns
    -------
    list of tuple of float
        ``(eps, snr_db)`` pairs, the nominal ``(nominal_eps, grid_start)`` first, without repeats.
    """
    ends = [grid_start] + [float(x) for x in other_ends if float(x) != grid_start]
    cases = [(nominal_eps, grid_start)]
    for eps in [nominal_eps] + [e for e in other_eps if e != nominal_eps]:
        for snr in (ends if eps in (nominal_eps, 0.0) else [grid_start]):
            if (eps, snr) not in cases:
                cases.append((eps, snr))
    return cases


def _value_rows(quantity: str, cases, fn, note: str = "") -> list:
    """Evidence rows of ``quantity``: the first case is nominal, the others variants of ``alpha_to_1``
    (alpha differs from the nominal) or ``snr_grid_db`` (only the low-SNR end differs)."""
    rows = []
    eps0 = cases[0][0]
    for i, (eps, snr) in enumerate(cases):
        key = "alpha_to_1" if eps != eps0 else "snr_grid_db"
        label = "nominal" if i == 0 else variant_label(key, f"{alpha_label(eps)}, SNR = {snr:g} dB")
        rows.append(dict(quantity=quantity, value=round(float(fn(eps, snr)), 4), variant=label,
                         note=note if i == 0 else ""))
    return rows


def _compact(x: float) -> str:
    """``1e-3`` for a power of ten below 0.01 (as the notes print 1 - alpha), else ``format(x, 'g')``."""
    mantissa, exponent = f"{x:.0e}".split("e")
    return f"{mantissa}e{int(exponent)}" if float(f"{x:.0e}") == x and x < 0.01 else f"{x:g}"


def errata_rows(params) -> list:
    """Residuals ``E<i>.residual_printed`` / ``.residual_corrected`` of each erratum, with the computed demonstration.

    Parameters
    ----------
    params : dict
        The ``onebit`` configuration section with ``_at``: the settings of the claims, findings and
        errata by id (:meth:`netrepro.judging.paperdata.PaperData.settings`); E4 and E5 are demonstrated at
        the settings of their ``at`` fields in ``errata.yaml``.

    Returns
    -------
    list of dict
        Evidence rows (:func:`netrepro.judging.verdicts.erratum_evidence`).
    """
    vc = vector_check(params["vector_check"])
    rows = []

    def add(eid, printed, corrected, note):
        rows.extend(erratum_evidence(eid, printed, corrected, note))

    demo = ("2-D model with non-symmetric A (config onebit.vector_check): max relative Frobenius error of the inverse "
            "BIM against the Kalman/RTS covariance over all k")
    add("E1", vc[("prediction", "(14) as printed")], vc[("prediction", "(14) corrected")], demo + " (P_{k+1|k})")
    add("E2", vc[("smoothing", "(16) as printed")], vc[("smoothing", "(16) corrected")], demo + " (RTS P_{l|K})")
    add("E3", vc[("smoothing", "(17)-(19) as printed")], vc[("smoothing", "(17)-(19) corrected")],
        demo + " (RTS P_{l|K} via (17))")
    at4 = params["_at"]["E4"]  # the settings of the demonstration (errata.yaml, field 'at')
    eps4, s4, k4 = float(at4["one_minus_alpha"]), float(at4["sigma_z2"]), int(at4["K"])
    e4p, e4c = variance_sum_check(eps4, s4, params["sigma_theta0"], k4)
    add("E4", e4p, e4c, f"max relative error over k = 1..{k4} against the recursion Var_k = alpha^2 Var_{{k-1}} + "
        f"sigma_z^2 (alpha = 1 - {_compact(eps4)}, sigma_z^2 = {s4:g}, sigma_0 = {params['sigma_theta0']:g})")
    at5 = params["_at"]["E5"]
    eps5, snr5, se5, k5 = (float(at5["one_minus_alpha"]), float(at5["snr_db"]), float(at5["sigma_eta"]),
                           int(at5["K"]))
    s5 = float(sigma_z2_from_snr(snr5, eps5, se5))
    efq5 = float(expected_fisher_1bit(stationary_variance(eps5, s5) / se5**2)) / se5**2
    r27, r38_unq, _ = rw_scalar_check(eps5, s5, 1.0 / se5**2, k5)
    _, r38, r37q = rw_scalar_check(eps5, s5, efq5, k5)
    add("E5", r37q, max(r38, r38_unq, r27),
        f"scalar random walk (alpha = {1 - eps5:g}, stationary SNR = {snr5:g} dB, sigma_eta = {se5:g}, K = {k5}): max "
        f"relative error of 1/J_{{l|K,q}} against the RTS smoother with noise variance 1/E[F_q] (E[F_q] = {efq5:.6g}). "
        f"(37) read alone: {r37q:.3g}; (36) with (37)x(38) read as one equation: {r38:.3g}; with E[F_q] -> "
        f"1/sigma_eta^2: (38) {r38_unq:.3g}, (27) {r27:.3g}")
    p, c = prior_check(np.asarray(params["vector_check"]["P0"], dtype=float))
    add("E6", p, c, "2-D prior N(0, P0) of onebit.vector_check: relative error of inv(J_{0|0}) against P0")
    return rows


def _regimes(params) -> tuple:
    """``(low_ends, medium_ends)``: the declared upper ends (dB) of the two SNR regimes, nominal first."""
    ev = params["evidence"]
    as_list = lambda v: [float(x) for x in (v if isinstance(v, (list, tuple)) else [v])]  # noqa: E731
    return as_list(ev["low_regime_max_db"]), as_list(ev["medium_regime_max_db"])


def _grid_claim_rows(params, ratios: pd.DataFrame, q: dict) -> list:
    """rho_S > rho_F everywhere, rho_S > 0 at low-medium SNR, the largest rho_S at low SNR; with variants."""
    se = params["sigma_eta"]
    grid = snr_grid(**params["snr_grid_db"])
    low_ends, med_ends = _regimes(params)
    epss = [0.0] + [float(e) for e in params["one_minus_alpha"]]
    rows = []
    # rho_S > rho_F: every (alpha, SNR) of ratios.csv, then per alpha and under the other SNR reading
    gt = ratios["rho_s_db"] > ratios["rho_f_db"]
    margin = (ratios["rho_s_db"] - ratios["rho_f_db"]).min()
    rows.append(dict(quantity="rho_s_gt_rho_f", value=bool(gt.all()),
                     note=f"{int(gt.sum())} of {len(gt)} (alpha, SNR) points of results/onebit/ratios.csv; smallest "
                          f"rho_S - rho_F = {margin:.3g} dB (rho_S/rho_F = 1 + kappa/J_f > 1 for any kappa > 0)"))
    for eps in epss:
        r = ratios_at(grid, eps, se, "stationary", q)
        rows.append(dict(quantity="rho_s_gt_rho_f", variant=variant_label("alpha_to_1", alpha_label(eps)),
                         value=bool(np.all(r["rho_s_db"] > r["rho_f_db"]))))
    for eps in epss[1:]:
        r = ratios_at(grid, eps, se, INNOVATION, q)
        rows.append(dict(quantity="rho_s_gt_rho_f",
                         variant=variant_label("snr_definition", f"SNR = sigma_z^2/sigma_eta^2, {alpha_label(eps)}"),
                         value=bool(np.all(r["rho_s_db"] > r["rho_f_db"]))))
    # rho_S > 0 at every grid SNR <= the medium regime's upper end, one declared range at a time
    cases = [("nominal", 0.0, "stationary", med_ends[0])]
    cases += [(variant_label("alpha_to_1", alpha_label(e)), e, "stationary", med_ends[0]) for e in epss[1:]]
    cases += [(variant_label("snr_definition", f"SNR = sigma_z^2/sigma_eta^2, {alpha_label(e)}"), e, INNOVATION,
               med_ends[0]) for e in epss[1:]]
    cases += [(f"medium_snr_regime={m:g} dB", 0.0, "stationary", m) for m in med_ends[1:]]
    pos_note = []
    first = len(rows)
    for label, eps, definition, smax in cases:
        med = grid[grid <= smax]
        r = ratios_at(med, eps, se, definition, q)["rho_s_db"]
        neg = med[~(r > 0)]
        pos_note.append(f"{label} ({alpha_label(eps)}, SNR <= {smax:g} dB): " + (
            "rho_S > 0 at all" if len(neg) == 0 else f"rho_S <= 0 at {len(neg)} of {len(med)} SNRs (from {neg.min():g} dB)"))
        rows.append(dict(quantity="rho_s_positive", variant=label, value=bool(np.all(r > 0)), note=""))
    cross = [f"{alpha_label(0.0)}: {rho_s_zero_crossing_limit():.2f} dB"] + [
        f"{alpha_label(e)}: {rho_s_zero_crossing(e, se, 'stationary'):.2f} dB" for e in epss[1:]]
    rows[first]["note"] = (f"SNR grid from {grid.min():g} dB: " + "; ".join(pos_note)
                           + ". rho_S crosses 0 dB (stationary SNR) at " + ", ".join(cross))
    # the largest rho_S over the low-SNR regime
    cases = [("nominal", 0.0, low_ends[0])] + [(variant_label("alpha_to_1", alpha_label(e)), e, low_ends[0])
                                                for e in epss[1:]]
    cases += [(f"low_snr_regime={m:g} dB", 0.0, m) for m in low_ends[1:]]
    for label, eps, smax in cases:
        low = grid[grid <= smax]
        r = ratios_at(low, eps, se, "stationary", q)["rho_s_db"]
        j = int(np.argmax(r))
        rows.append(dict(quantity="rho_s_low_snr_max_db", variant=label, value=round(float(r[j]), 4),
                         note=f"largest rho_S over SNR {low.min():g} to {low.max():g} dB, at {low[j]:g} dB"
                         if label == "nominal" else f"at {low[j]:g} dB"))
    return rows


def _threshold_rows(params, threshold: pd.DataFrame) -> list:
    """Whether rho_S > 0 needs alpha close to one, and how close (alpha_threshold.csv), per medium-regime end."""
    se = params["sigma_eta"]
    _, med_ends = _regimes(params)
    eps_tiny = float(params["_at"]["rho_s_alpha_threshold"]["innovation_one_minus_alpha"])
    thr_all = threshold.set_index("snr_db")
    rows = []
    for i, smax in enumerate(med_ends):
        thr = thr_all[thr_all.index <= smax]
        ok = bool(len(thr) > 0 and thr["single_sign_change"].all() and (thr["one_minus_alpha_max"] > 0).all()
                  and thr["one_minus_alpha_max"].notna().all())
        binding = thr["one_minus_alpha_max"].idxmin()
        note = (f"rho_S > 0 dB at every scanned SNR ({thr.index.min():g} to {thr.index.max():g} dB) iff 1 - alpha < "
                f"{thr['one_minus_alpha_max'].min():.3g} (alpha > {1 - thr['one_minus_alpha_max'].min():.4f}, binding "
                f"at {binding:g} dB)")
        if i == 0:
            note += ("; per SNR, largest 1 - alpha: " + ", ".join(
                f"{x:g} dB: {v:.3g}" for x, v in thr_all["one_minus_alpha_max"].items())
                + "; one sign change along the scanned alphas at each SNR (results/onebit/alpha_threshold.csv)")
        rows.append(dict(quantity="rho_s_alpha_threshold", variant="nominal" if i == 0 else
                         f"medium_snr_regime={smax:g} dB", value=ok, note=note))
    thr = thr_all[thr_all.index <= med_ends[0]]
    inno = {float(x): rho_s_threshold_eps(float(x), se, definition=INNOVATION) for x in thr.index}
    tiny = {float(x): float(ratios_at([x], eps_tiny, se, INNOVATION)["rho_s_db"][0]) for x in thr.index}
    inno_ok = all(v > 0 and not math.isnan(v) for v in inno.values())
    rows.append(dict(quantity="rho_s_alpha_threshold", variant=variant_label("snr_definition", "SNR = sigma_z^2/sigma_eta^2"),
                     value=inno_ok, note=f"rho_S at 1 - alpha = {eps_tiny:g}: " + ", ".join(
                         f"{x:g} dB: {v:.2f} dB" for x, v in tiny.items())))
    return rows


def _achievable_rows(params, est_ratios: pd.DataFrame, shards, eps_max: float) -> list:
    """rho_S of the real 1-bit smoother vs the Kalman filter: 95 % paired-bootstrap lower end > 0 at every SNR <= max.

    The first simulated alpha is nominal; the others are variants when ``1 - alpha < eps_max`` (the
    bound's own threshold for rho_S > 0, i.e. inside 'alpha close to one'), else shown in the note.
    Every simulated SNR up to the medium regime's end counts (grid and crossing cases).
    """
    est = params["estimator"]
    _, med_ends = _regimes(params)
    rs_all = est_ratios[est_ratios["quantity"] == "rho_S"]
    eps0 = float(est["one_minus_alpha"][0])

    def judged(eps, smax):
        sub = rs_all[np.isclose(rs_all["alpha"], 1.0 - eps, rtol=0, atol=1e-15) & (rs_all["snr_db"] <= smax)]
        sub = sub.sort_values(["snr_db", "n_runs"])
        value = bool(len(sub) > 0 and (sub["lo_db"] > 0).all())
        # decided: every interval above 0 (true), or one entirely below 0 (false); else some interval straddles 0
        decided = bool(len(sub) > 0 and (value or (sub["hi_db"] < 0).any()))
        note = "; ".join(f"{r.snr_db:g} dB: {r.estimate_db:.2f} [{r.lo_db:.2f}, {r.hi_db:.2f}] (bound {r.bound_db:.2f}, "
                         f"n = {r.n_runs})" for r in sub.itertuples())
        return value, note, decided

    rows, outside = [], []
    for i, eps in enumerate(est["one_minus_alpha"]):
        value, note, decided = judged(float(eps), med_ends[0])
        if i > 0 and not eps < eps_max:
            outside.append(f"{alpha_label(eps)} (outside 'alpha close to one', 1 - alpha >= {eps_max:.3g}): "
                           f"{'significant' if value else 'not significant'} at every SNR <= {med_ends[0]:g} dB; {note}")
            continue
        rows.append(dict(quantity="achievable_rho_s_positive", value=value, note=note, decided=decided,
                         variant="nominal" if i == 0 else variant_label("estimator", alpha_label(eps))))
    for smax in med_ends[1:]:
        value, note, decided = judged(eps0, smax)
        rows.append(dict(quantity="achievable_rho_s_positive", variant=f"medium_snr_regime={smax:g} dB", value=value,
                         note=note, decided=decided))
    if outside:
        rows[0]["note"] += ". Not judged: " + " | ".join(outside)
    # the two halves of the runs at the nominal alpha: other seeds' blocks, half the sample size
    ref, onebit, _ = RATIO_DEFS["rho_S"]
    halves = {0: [], 1: []}
    for case in estimator_cases(params):
        if case.eps != eps0 or case.snr_db > med_ends[0] or case.case_set != "grid":
            continue
        runs = merged_runs(shards, case.key)
        n = len(runs[ref])
        for h, sl in enumerate((slice(0, n // 2), slice(n // 2, n))):
            e, lo, hi = paired_ratio_interval(runs[ref][sl], runs[onebit][sl], est["n_boot"], case.seed)
            halves[h].append((case.snr_db, e, lo, hi, sl.stop - sl.start))
    for h, res in halves.items():
        if not res:
            continue
        label = variant_label("estimator", f"{alpha_label(eps0)}, runs {'first' if h == 0 else 'second'} half "
                                           f"(n = {res[0][4]})")
        rows.append(dict(quantity="achievable_rho_s_positive", variant=label, value=all(r[2] > 0 for r in res),
                         decided=all(r[2] > 0 for r in res) or any(r[3] < 0 for r in res)))
    return rows


def _finding_rows(params, est_mse: pd.DataFrame, lag: pd.DataFrame, ratios: pd.DataFrame) -> list:
    """Evidence of our own findings (settings: the ``at:`` fields of findings.yaml)."""
    se, ev = params["sigma_eta"], params["evidence"]
    at = params["_at"]
    rows = []
    # the BCRB lies below the MSE of near-optimal estimators (Bonferroni over rows, one-sided, 5 % family-wise)
    m = len(est_mse)
    z_family = float(ndtri(1.0 - 0.05 / m))
    se_mse = (est_mse["mse_hi"] - est_mse["mse"]) / float(ndtri(0.975))
    zs = (est_mse["bound"] - est_mse["mse"]) / se_mse
    worst = est_mse.loc[zs.idxmax()]
    rows.append(dict(quantity="bound_below_mse", value=bool((zs <= z_family).all()),
                     note=f"{m} estimator x SNR x alpha rows, {int(est_mse['n_runs'].min())} to "
                          f"{int(est_mse['n_runs'].max())} runs each: no MSE below its "
                          f"bound by more than z = {z_family:.2f} standard errors (one-sided, 5 % family-wise, "
                          f"Bonferroni); largest z = {zs.max():.2f} ({worst['kind']}, alpha = {worst['alpha']:g}, "
                          f"{worst['snr_db']:g} dB)"))
    # how loose the 1-bit bound becomes: the smoother's MSE/BCRB from 0 dB up, per simulated alpha
    grid_mse = est_mse[(est_mse["case_set"] == "grid") & (est_mse["kind"] == "smoother_1bit")]
    lo_snr = float(at["bound_loose_above_0db"]["from_snr_db"])
    for i, (alpha, g) in enumerate(sorted(grid_mse.groupby("alpha"), key=lambda t: -t[0])):
        g = g[g["snr_db"] >= lo_snr].sort_values("snr_db")
        lower = g["mse_lo"] / g["bound"]
        value = bool(len(g) > 1 and (lower > 1).all() and (np.diff(g["mse_over_bound"].to_numpy()) > 0).all())
        # decided: each SNR's interval clear of the bound, and each step's change significant (independent cases)
        ratio, half = g["mse_over_bound"].to_numpy(), ((g["mse_hi"] - g["mse"]) / g["bound"]).to_numpy()
        clear = ((g["mse_lo"] / g["bound"] > 1) | (g["mse_hi"] / g["bound"] < 1)).all()
        steps_sig = (np.abs(np.diff(ratio)) > np.hypot(half[1:], half[:-1])).all()
        decided = bool(len(g) > 1 and clear and steps_sig)
        note = (f"1-bit smoother MSE/BCRB at {alpha_label(1.0 - alpha)}: " + ", ".join(
            f"{r.snr_db:g} dB: {r.mse_over_bound:.2f} (lower 95 % end {r.mse_lo / r.bound:.2f})" for r in g.itertuples()))
        rows.append(dict(quantity="bound_loose_above_0db", value=value, note=note, decided=decided,
                         variant="nominal" if i == 0 else variant_label("alpha_to_1", alpha_label(1.0 - alpha))))
        if i == 0 and len(g):
            # the statement's numbers (issue 37): the ratio at the first and the last simulated SNR from lo_snr up
            for end, r, h in (("first", g.iloc[0], half[0]), ("last", g.iloc[-1], half[-1])):
                rows.append(dict(quantity=f"bound_loose.{end}_snr_db", value=float(r["snr_db"])))
                rows.append(dict(quantity=f"bound_loose.{end}_ratio", value=float(r["mse_over_bound"]),
                                 uncertainty=float(h), note="1-bit smoother MSE/BCRB; uncertainty: its 95 % half-width"))
    # the break-even lag exists exactly where rho_S > 0 (so it is no separate claim), and how long it is
    merged = lag.merge(ratios[["alpha", "snr_db", "rho_s_db"]], on=["alpha", "snr_db"])
    same = (merged["delta_break_even"].notna() == (merged["rho_s_db"] > 0))
    parts = []
    quote = [float(x) for x in at["break_even_lag"]["snr_db"]]
    for alpha, g in lag.groupby("alpha"):
        g = g.set_index("snr_db")["delta_break_even"]
        pts = [x for x in quote if x in g.index]
        parts.append(f"alpha = {alpha:g}: " + ", ".join(
            f"{x:g} dB: {'never' if np.isnan(g[x]) else int(g[x])}" for x in pts))
    rows.append(dict(quantity="break_even_lag", value=bool(same.all()),
                     note=f"a finite break-even lag exists iff rho_S > 0 at {int(same.sum())} of {len(same)} grid points; "
                          "smallest Delta with J_{k|k+Delta,q} > J_{k|k,inf}: " + "; ".join(parts)))
    # the lag needed to be within tol of the Delta -> infinity limit, across tolerances
    grid_start = float(params["snr_grid_db"]["start"])
    pts = np.array([grid_start] + [float(x) for x in at["lag_needed_tolerance"]["snr_db"]])
    parts, lags = [], {}
    for eps in params["one_minus_alpha"]:
        s = sigma_z2_from_snr(pts, eps, se, params["snr_definition"])
        Fq = expected_fisher_1bit(stationary_variance(eps, s) / se**2) / se**2
        for tol in ev["lag_tol_db"]:
            d = rw_lag_needed(Fq, eps, s, tol)
            lags[(eps, tol)] = np.asarray(d, dtype=float)
            parts.append(f"{alpha_label(eps)}, tol {tol:g} dB: " + ", ".join(
                f"{x:g} dB: {int(v)}" for x, v in zip(pts, d)))
    # the finding's assertion: the lag grows as the tolerance shrinks and as alpha -> 1, at every SNR
    tols = sorted(ev["lag_tol_db"], reverse=True)
    epss = sorted(params["one_minus_alpha"], reverse=True)
    grows = all(np.all(lags[(e, t2)] > lags[(e, t1)]) for e in epss for t1, t2 in zip(tols, tols[1:]))
    grows &= all(np.all(lags[(e2, t)] > lags[(e1, t)]) for t in tols for e1, e2 in zip(epss, epss[1:]))
    rows.append(dict(quantity="lag_needed_tolerance", value=bool(grows), note="1-bit smoothing lag within tol of "
                     "its Delta -> infinity value: " + "; ".join(parts)))
    # finite alpha: the prior information lifts rho_F and rho_SL back towards 0 dB at very low SNR
    eps5 = float(params["fig1_one_minus_alpha"])
    very_low = np.array(ev["very_low_snr_db"], dtype=float)
    r = ratios_at(very_low, eps5, se)
    rows.append(dict(quantity="finite_alpha_low_snr", value=round(float(r["rho_sl_db"][0]), 4),
                     note=f"{alpha_label(eps5)}: " + ", ".join(
                         f"{x:g} dB: rho_SL {a:.3f}, rho_F {b:.3f}" for x, a, b in
                         zip(very_low, r["rho_sl_db"], r["rho_f_db"])) + "; " + _fig1_window_note(params)))
    # the stated cause, tested: the same sigma_z^2 and E[F_q] without the mean reversion (no prior information)
    nr = ratios_without_mean_reversion(very_low, eps5, se)
    rows.append(dict(quantity="finite_alpha_low_snr", variant="cause: alpha = 1 in (24)/(27), same sigma_z^2, E[F_q]",
                     value=round(float(nr["rho_sl_db"][0]), 4),
                     note="without the prior information (1 - alpha^2)/sigma_z^2: " + ", ".join(
                         f"{x:g} dB: rho_SL {a:.3f}, rho_F {b:.3f}" for x, a, b in
                         zip(very_low, nr["rho_sl_db"], nr["rho_f_db"]))))
    return rows


def _half_width(estimate: float, lo: float, hi: float) -> float:
    """Half-width of an interval around its estimate: the larger side (a percentile interval is not symmetric)."""
    return float(max(estimate - lo, hi - estimate))


def _crossing_evidence(params, crossing: pd.DataFrame, edge: pd.DataFrame) -> list:
    """Where the achievable rho_S crosses 0 dB (local fit, bootstrap over runs), against the bound (49), the
    alpha -> 1 achievable limit, and the bias of the 5-tau record edges (issue 37).

    Every Monte Carlo value carries its uncertainty: the half-width of its 95 % interval.
    """
    cr = crossing.set_index(["alpha", "curve"])
    at = params["_at"]["rho_s_crossing"]
    effect = float(at["effect_size_db"])
    a_nom = 1.0 - float(at["one_minus_alpha"])
    stated = a_nom in set(crossing["alpha"])
    if not stated:  # a small configuration (config/test.yaml): the simulated alpha closest to one stands in
        a_nom = float(crossing["alpha"].max())
    limit = achievable_rho_s_crossing_limit()
    edge_at = {}
    if len(edge):
        e_rs = edge[edge["quantity"] == "edge_bias_db.rho_S"]
        for a, g in e_rs.groupby("alpha"):
            edge_at[float(a)] = g
    rows, parts = [], []
    first = {}
    for a in sorted(crossing["alpha"].unique(), reverse=True):
        e = cr.loc[(a, "estimate")]
        bound = float(cr.loc[(a, "bound"), "snr_db_crossing"])
        label = "nominal" if a == a_nom else variant_label("estimator", alpha_label(1.0 - a))
        if not np.isfinite(e["snr_db_crossing"]):
            parts.append(f"alpha = {a:g}: achievable: no sign change on the simulated SNRs; bound {bound:.2f} dB")
            rows.append(dict(quantity="rho_s_crossing_far_below_bound", variant=label, value=False, decided=False,
                             note="no achievable crossing on the simulated SNRs" if a == a_nom else ""))
            if a == a_nom:
                rows += [dict(quantity=q, value=np.nan, uncertainty=math.inf, decided=False)
                         for q in ("rho_s_crossing", "rho_s_crossing_gap")]
                rows.append(dict(quantity="rho_s_crossing_bound", value=round(bound, 4), uncertainty=0.0))
            continue
        est, lo, hi = (float(cr.loc[(a, c), "snr_db_crossing"]) for c in ("estimate", "lo", "hi"))
        u = _half_width(est, lo, hi)
        sens = ", ".join(f"{c.replace('_', ' ')} {cr.loc[(a, c), 'snr_db_crossing']:.2f}" for c in
                         ("fit_degree_1", "fit_degree_3", "runs_first_half", "runs_second_half") if (a, c) in cr.index)
        band = ""
        if (a, "replicate_se") in cr.index:
            rse, bse = float(cr.loc[(a, "replicate_se"), "snr_db_crossing"]), float(cr.loc[(a, "bootstrap_se"),
                                                                                          "snr_db_crossing"])
            band = (f"; band check: standard error {bse:.3f} dB from the bootstrap, {rse:.3f} dB from "
                    f"{int(cr.loc[(a, 'replicate_se'), 'n_replicates'])} disjoint replicates (ratio {rse / bse:.2f})")
        shift = ""
        slope = float(e["slope_db_per_db"]) if "slope_db_per_db" in e else float("nan")
        g = edge_at.get(float(a))
        if g is not None and np.isfinite(slope) and slope < 0:
            r = g.iloc[int(np.argmin(np.abs(g["snr_db"].to_numpy() - est)))]
            b, bu = float(r["estimate"]), _half_width(float(r["estimate"]), float(r["lo"]), float(r["hi"]))
            first.setdefault(a, dict(bias=b, bias_u=bu, shift=-b / slope, shift_u=bu / abs(slope), snr=float(r["snr_db"]),
                                     extra=float(r["extra_taus"]), n=int(r["n_runs"])))
            shift = (f"; record edges: rho_S on the standard record minus a record {r['extra_taus']:g} time constants "
                     f"longer at each end, {r['snr_db']:g} dB: {b:+.3f} dB [{r['lo']:+.3f}, {r['hi']:+.3f}] "
                     f"({int(r['n_runs'])} paired runs), so the crossing is moved by {-b / slope:+.3f} dB "
                     f"(+- {bu / abs(slope):.3f}; fit slope {slope:.2f} dB/dB)")
        parts.append(f"alpha = {a:g}: achievable {est:.2f} dB [{lo:.2f}, {hi:.2f}] ({e['method']}, {e['fit_snr_lo']:g} to "
                     f"{e['fit_snr_hi']:g} dB, {int(e['n_points'])} SNRs x {int(e['n_runs'])} runs, "
                     f"{int(e['n_boot'])} bootstrap refits, fit residual {e['fit_residual_rms']:.3f} dB; sensitivity: "
                     f"{sens}{band}{shift}), bound {bound:.2f} dB; former straight line across the grid "
                     f"{cr.loc[(a, 'grid_linear'), 'snr_db_crossing']:.2f} dB")
        # the test: the achievable crossing lies below the bound's by more than the pre-set effect size;
        # decided only when the whole interval is on one side of the threshold
        gap_lo, gap_hi = bound - hi, bound - lo
        rows.append(dict(quantity="rho_s_crossing_far_below_bound", variant=label, value=bool(gap_lo > effect),
                         decided=bool(gap_lo > effect or gap_hi < effect),
                         note=f"bound minus achievable crossing {bound - est:.2f} dB [{gap_lo:.2f}, {gap_hi:.2f}] "
                              f"against the effect size {effect:g} dB" if a == a_nom else ""))
        if a == a_nom:
            rows += [dict(quantity="rho_s_crossing", value=round(est, 4), uncertainty=round(u, 4)),
                     dict(quantity="rho_s_crossing_bound", value=round(bound, 4), uncertainty=0.0,
                          note="the bound (49)'s crossing at the same alpha (Brent's method, exact)"),
                     dict(quantity="rho_s_crossing_gap", value=round(bound - est, 4), uncertainty=round(u, 4))]
    nom_rows = [r for r in rows if r["quantity"] == "rho_s_crossing"]
    nom_rows[0]["note"] = (("" if stated else f"the stated alpha is not simulated here; nominal alpha = {a_nom:g}; ")
                           + "; ".join(parts) + f"; alpha -> 1 bound {rho_s_zero_crossing_limit():.2f} dB (sigma_eta^2 "
                           f"E[F_q] = 1/4), alpha -> 1 achievable {limit:.2f} dB (2/E[(sigma_eta^2 F_q)^(-1/2)] = 1)")
    rows.append(dict(quantity="rho_s_crossing_limit", value=round(limit, 4), uncertainty=0.0,
                     note="the alpha -> 1 limit of the achievable crossing, 2/E[(sigma_eta^2 F_q)^(-1/2)] = 1 "
                          "(quadrature, exact to 1e-8)"))
    ed = first.get(a_nom)
    rows.append(dict(quantity="rho_s_edge_bias_db", value=round(ed["bias"], 4) if ed else np.nan,
                     uncertainty=round(ed["bias_u"], 4) if ed else math.inf, decided=ed is not None,
                     note=(f"{alpha_label(1.0 - a_nom)}, {ed['snr']:g} dB (the edge SNR nearest the crossing): rho_S on "
                           f"the standard record (5 time constants before and after the window) minus rho_S on a record "
                           f"{ed['extra']:g} time constants longer at each end, same {ed['n']} runs; 95 % paired "
                           "bootstrap half-width" if ed else "no edge case at the nominal alpha in this configuration")))
    rows.append(dict(quantity="rho_s_crossing_edge_shift_db", value=round(ed["shift"], 4) if ed else np.nan,
                     uncertainty=round(ed["shift_u"], 4) if ed else math.inf, decided=ed is not None,
                     note="the edge bias over the fit's slope at the crossing: how far the 5-tau records move the "
                          "crossing (negative: too low)"))
    # at Fig 1's alpha, where simulated (config/paper-scale.yaml): context for the verdicts by scale
    a_fig1 = 1.0 - float(params["fig1_one_minus_alpha"])
    fig1 = cr.loc[(a_fig1, "estimate")] if (a_fig1, "estimate") in cr.index else None
    simulated = fig1 is not None and np.isfinite(fig1["snr_db_crossing"])
    lo1, hi1 = ((float(cr.loc[(a_fig1, c), "snr_db_crossing"]) for c in ("lo", "hi")) if simulated else (np.nan, np.nan))
    rows.append(dict(quantity="rho_s_crossing_fig1_alpha",
                     value=round(float(fig1["snr_db_crossing"]), 4) if simulated else np.nan,
                     uncertainty=round(_half_width(float(fig1["snr_db_crossing"]), lo1, hi1), 4) if simulated else math.inf,
                     decided=bool(simulated),
                     note=(f"{alpha_label(1.0 - a_fig1)} (Fig 1): achievable {fig1['snr_db_crossing']:.2f} dB "
                           f"[{lo1:.2f}, {hi1:.2f}], bound {cr.loc[(a_fig1, 'bound'), 'snr_db_crossing']:.2f} dB"
                           if simulated else f"{alpha_label(1.0 - a_fig1)} (Fig 1) not simulated by this configuration "
                           "(config/paper-scale.yaml simulates it)")))
    return rows


def _limit_evidence(params, crossing: pd.DataFrame, est_ratios: pd.DataFrame) -> list:
    """The alpha -> 1 limit of the achievable rho_S, 2/E[(sigma_eta^2 F_q)^(-1/2)] (beyond the paper, issue 37),
    against the bound's limit 2 sqrt(sigma_eta^2 E[F_q]) and the simulated rho_S of the alpha closest to one."""
    snrs = [float(x) for x in params["_at"]["achievable_limit"]["snr_db"]]
    lim = achievable_rho_s_limit_db(snrs)
    blim = 10.0 * np.log10(2.0 * np.sqrt(expected_fisher_1bit(10.0 ** (np.asarray(snrs) / 10.0))))
    rs = est_ratios[(est_ratios["quantity"] == "rho_S")]
    a_top = float(rs["alpha"].max())
    top = rs[rs["alpha"] == a_top].sort_values(["snr_db", "n_runs"]).drop_duplicates("snr_db", keep="last")
    top_lim = achievable_rho_s_limit_db(top["snr_db"].to_numpy())
    sim = "; ".join(f"{r.snr_db:g} dB: {r.estimate_db:.2f} [{r.lo_db:.2f}, {r.hi_db:.2f}] (limit {lv:.2f})"
                    for r, lv in zip(top.itertuples(), top_lim) if -10.0 <= r.snr_db <= 5.0)
    cr = crossing[crossing["curve"] == "estimate"].dropna(subset=["snr_db_crossing"])
    limit = achievable_rho_s_crossing_limit()
    rows = [dict(quantity="achievable_limit_crossing_db", value=round(limit, 4), uncertainty=0.0,
                 note="SNR where 2/E[(sigma_eta^2 F_q)^(-1/2)] = 1 (trapezoid rule on the product-Gaussian form, checked "
                      "against adaptive quadrature to 1e-8); simulated crossings: " + ", ".join(
                          f"{alpha_label(1.0 - a)}: {v:.2f} dB" for a, v in zip(cr["alpha"], cr["snr_db_crossing"]))),
            dict(quantity="achievable_limit_snr_max_db", value=round(ACHIEVABLE_LIMIT_SNR_MAX_DB, 4), uncertainty=0.0,
                 note="from Var[theta]/sigma_eta^2 = 2 on, E[F_q^(-1/2)] diverges: the limit is -inf dB"),
            dict(quantity="bound_limit_crossing_db", value=round(rho_s_zero_crossing_limit(), 4), uncertainty=0.0,
                 note="the alpha -> 1 limit of the bound (49), 2 sqrt(sigma_eta^2 E[F_q]), crosses 0 dB here")]
    for x, lv, bv in zip(snrs, lim, blim):
        rows.append(dict(quantity=f"achievable_limit_db.{x:g}dB", value=round(float(lv), 4), uncertainty=0.0,
                         note=f"bound's limit 2 sqrt(sigma_eta^2 E[F_q]) there: {bv:.2f} dB"))
    rows[0]["note"] += f"; simulated rho_S at {alpha_label(1.0 - a_top)}: {sim}"
    return rows


def _coverage_evidence(params, coverage: pd.DataFrame, est_mse: pd.DataFrame, est_ratios: pd.DataFrame) -> list:
    """Whether the normal 95 % intervals of the MSEs cover: disjoint replicates against exact values (Kalman/RTS:
    the finite-record BCRB they attain) or against the other replicates (1-bit), per simulated alpha (issue 37).

    Per alpha, true iff no estimator's replicate intervals cover significantly less than 95 % (one-sided
    binomial test, Bonferroni over the four estimators); decided when a test rejects or every Clopper-Pearson
    interval of the coverage lies above the pre-set floor (``at: coverage_floor``).
    """
    est = params["estimator"]
    at = params["_at"]["mse_standard_errors_valid"]
    floor = float(at["coverage_floor"])
    heavy_min = float(at["kurtosis_heavy"])
    rows = []
    if not len(coverage):
        return [dict(quantity="mse_standard_errors_valid", value=False, decided=False,
                     note="no case has enough runs for the replicates"),
                dict(quantity="mse_interval_coverage", value=np.nan, uncertainty=math.inf, decided=False)]
    kinds = ("smoother_1bit", "filter_1bit", "kalman_filter", "rts_smoother")
    level = 0.05 / len(kinds)   # one-sided, Bonferroni over the estimators (each kind's replicates are independent)
    for i, eps in enumerate(est["one_minus_alpha"]):
        a = 1.0 - float(eps)
        sub = coverage[np.isclose(coverage["alpha"], a, rtol=0, atol=1e-15)]
        tests, parts = [], []
        for kind in kinds:
            c = sub[sub["kind"] == kind]
            if not len(c):
                continue
            t = binomial_coverage(int(c["covered"].sum()), len(c))
            tests.append(t)
            hv = c[c["kurtosis"] > heavy_min]
            heavy = ""
            if len(hv):
                th = binomial_coverage(int(hv["covered"].sum()), len(hv))
                heavy = f"; kurtosis > {heavy_min:g}: {th['fraction']:.3f} [{th['lo']:.3f}, {th['hi']:.3f}] of {len(hv)}"
            parts.append(f"{kind} (against {c['reference_kind'].iloc[0]}): {t['fraction']:.3f} [{t['lo']:.3f}, "
                         f"{t['hi']:.3f}] of {len(c)} replicate intervals, p(under) = {t['p_under']:.2g}{heavy}")
            if kind == "smoother_1bit" and i == 0:
                rows.append(dict(quantity="mse_interval_coverage", value=round(t["fraction"], 4),
                                 uncertainty=round(_half_width(t["fraction"], t["lo"], t["hi"]), 4),
                                 note=f"{alpha_label(float(eps))}, 1-bit smoother: fraction of the normal 95 % "
                                      "intervals of disjoint replicates that cover the other replicates' mean (Clopper-"
                                      "Pearson 95 % half-width)"))
        value = bool(tests) and all(t["p_under"] >= level for t in tests)
        decided = bool(tests) and (not value or all(t["lo"] >= floor for t in tests))
        n_rep = int(sub["replicate"].max()) + 1 if len(sub) else 0
        rows.append(dict(quantity="mse_standard_errors_valid", value=bool(value), decided=bool(decided and n_rep >= 5),
                         variant="nominal" if i == 0 else variant_label("estimator", alpha_label(float(eps))),
                         note=f"{alpha_label(float(eps))}, {n_rep} disjoint replicates per case, one-sided binomial "
                              f"test at {level:g} per estimator, decided when rejected or when every Clopper-Pearson "
                              f"lower end >= {floor:g}: " + "; ".join(parts)))
    # the ratios' paired bootstrap band: against an exact ratio (Kalman filter over RTS smoother), and, for the
    # heavy-tailed rho_S, against the spread of the ratio over disjoint replicates
    rat = coverage[coverage["kind"].astype(str).str.startswith("ratio_db:")]
    if len(rat):
        t = binomial_coverage(int(rat["covered"].sum()), len(rat))
        rows.append(dict(quantity="ratio_band_exact_coverage", value=round(t["fraction"], 4),
                         uncertainty=round(_half_width(t["fraction"], t["lo"], t["hi"]), 4),
                         note=f"paired bootstrap 95 % intervals of the Kalman filter's MSE over the RTS smoother's (dB), "
                              f"one per case, against the exact ratio of their finite-record bounds: {int(rat['covered'].sum())}"
                              f" of {len(rat)} cover (Clopper-Pearson [{t['lo']:.3f}, {t['hi']:.3f}], p(under) = "
                              f"{t['p_under']:.2g}); largest |z| = {rat['z'].abs().max():.2f}"))
    if "se_rep_db" in est_ratios:
        rs = est_ratios[(est_ratios["quantity"] == "rho_S") & (est_ratios["se_boot_db"] > 0)]
        n_rep = int(est.get("n_replicates", 8))
        pooled, df, b_lo, b_hi = pooled_se_ratio(rs["se_rep_db"] / rs["se_boot_db"], np.full(len(rs), n_rep))
        rows.append(dict(quantity="rho_s_band_ratio", value=round(pooled, 4),
                         uncertainty=round(max(pooled - b_lo, b_hi - pooled), 4),
                         note=f"rho_S: standard error from {n_rep} disjoint replicates over that of the paired bootstrap, "
                              f"pooled over {len(rs)} cases on {df} df: {pooled:.3f} (95 % chi-square band for a correct "
                              f"bootstrap [{b_lo:.3f}, {b_hi:.3f}]; largest case {(rs['se_rep_db'] / rs['se_boot_db']).max():.2f})"))
    # context: the former batch-means check (seed blocks as replicates; same runs, so it shows independence only)
    one = est_mse[est_mse["kind"] == "smoother_1bit"]
    pooled, df, b_lo, b_hi = pooled_se_ratio(one["se_ratio"], one["n_blocks"])
    sm = est_mse[est_mse["kind"].isin(["smoother_1bit", "filter_1bit"])]
    ref = est_mse[est_mse["kind"].isin(["kalman_filter", "rts_smoother"])]
    a0 = est_mse["alpha"].max()
    top = sm[(sm["alpha"] == a0) & (sm["snr_db"] >= 0)]
    nominal = next(r for r in rows if r["quantity"] == "mse_standard_errors_valid")
    nominal["note"] += (f". Per-run kurtosis at alpha = {a0:g}, SNR >= 0 dB (1-bit filter/smoother): "
                        f"{top['kurtosis'].min():.0f} to {top['kurtosis'].max():.0f}, largest run "
                        f"{top['max_over_mean'].min():.0f} to {top['max_over_mean'].max():.0f} times the mean; Kalman/RTS "
                        f"everywhere: kurtosis <= {ref['kurtosis'].max():.1f}. Window "
                        f"{int(top['window_stop'].sub(top['window_start']).min())} to "
                        f"{int(top['window_stop'].sub(top['window_start']).max())} steps against the correlation time "
                        f"1/(1 - alpha) = {1.0 / (1.0 - a0):.0f} steps. Batch means over seed blocks (the same runs: "
                        f"independence, not coverage): pooled ratio {pooled:.3f} on {df} df [{b_lo:.3f}, {b_hi:.3f}]")
    return rows


def _fig1_window_note(params) -> str:
    """Where the Fig 1 curve (alpha = 1 - 1e-5) is within the tolerance of claim rho_sl_fig1's value: a window of SNRs."""
    se = params["sigma_eta"]
    eps5 = float(params["fig1_one_minus_alpha"])
    claim = params["_claims"]["rho_sl_fig1"]
    target, tol = float(claim.paper_value), float(claim.tolerance)
    w = params["_at"]["finite_alpha_low_snr"]["fig1_window_db"]
    fine = np.arange(w["start"], w["stop"] + w["step"] / 2, w["step"])
    lo, hi = ratio_window(fine, eps5, "rho_sl_db", target, tol, se)
    if math.isnan(lo):
        return (f"{alpha_label(eps5)}: rho_SL is nowhere within {tol:g} dB of {target:g} dB on {w['start']:g} to "
                f"{w['stop']:g} dB")
    return (f"{alpha_label(eps5)}: rho_SL within {tol:g} dB of {target:g} dB only for SNR in [{lo:.1f}, {hi:.1f}] dB "
            f"({w['step']:g} dB grid from {w['start']:g} to {w['stop']:g} dB)")


def _reconstruction_rows(params) -> list:
    """``reconstruction.<key>`` rows: configured values and computed sensitivities."""
    se, ref, eps5 = params["sigma_eta"], params["reference_snr_db"], float(params["fig1_one_minus_alpha"])
    at = params["_at"]
    grid = snr_grid(**params["snr_grid_db"])
    shifts = ", ".join(f"{alpha_label(e)}: {axis_shift_db(e):.2f} dB" for e in params["one_minus_alpha"])
    dev = max(snr_shift_deviation(grid, e, se) for e in params["one_minus_alpha"])
    stat = ratios_at([ref], eps5, se, "stationary")
    inno = ratios_at([ref], eps5, se, INNOVATION)
    near = ratios_at(grid, eps5, se)
    lim = ratios_at(grid, 0.0, se)
    hi_from = float(at["finite_alpha_low_snr"]["near_limit_from_snr_db"])
    hi = grid >= hi_from
    gaps = "; ".join(f"{k[:-3]}: {np.max(np.abs(near[k] - lim[k])):.3f} dB over the grid, "
                     f"{np.max(np.abs(near[k] - lim[k])[hi]):.3f} dB for SNR >= {hi_from:g} dB" for k in near)
    est = params["estimator"]
    f = at["finite_alpha_low_snr"]["flat_grid_db"]
    fine = np.arange(f["start"], f["stop"] + f["step"] / 2, f["step"])
    lim0 = 10.0 * math.log10(math.sqrt(2.0 / math.pi))
    tol = params["evidence"]["flat_tol_db"]
    flat_ok = np.abs(ratios_at(fine, 0.0, se)["rho_sl_db"] - lim0) <= tol
    flat = float(fine[flat_ok].max()) if flat_ok.any() else float("nan")
    low_ends, med_ends = _regimes(params)
    cr = est.get("crossing") or {}
    cross = (f"; crossing cases: 1 - alpha in {cr['one_minus_alpha']}, SNR {cr['snr_db']} dB, {cr['n_runs']} runs, "
             f"seed {cr['seed']}, local fit of degree {cr['degree']}" if cr else "")
    return [
        dict(quantity="reconstruction.snr_definition", value=params["snr_definition"],
             note=f"axis shift 10 log10(1 - alpha^2): {shifts}; largest difference between the stationary curves and "
                  f"the innovation curves moved by that shift: {dev:.2g} dB over the grid. At the same label SNR = {ref:g} "
                  f"dB ({alpha_label(eps5)}): rho_F = {stat['rho_f_db'][0]:.3f}, rho_SL = {stat['rho_sl_db'][0]:.3f} dB "
                  f"(stationary) vs rho_F = {inno['rho_f_db'][0]:.3f}, rho_SL = {inno['rho_sl_db'][0]:.3f} dB (innovation)"),
        dict(quantity="reconstruction.alpha_to_1", value="limit at fixed stationary SNR",
             note=f"max |{alpha_label(eps5)} minus limit|: {gaps}"),
        dict(quantity="reconstruction.mu_theta0", value=params["mu_theta0"]),
        dict(quantity="reconstruction.lag_tol_db", value=params["lag_tol_db"]),
        dict(quantity="reconstruction.snr_grid_db", value=str(params["snr_grid_db"]),
             note=f"the alpha -> 1 rho_SL is within {tol:g} dB of its SNR -> 0 value {lim0:.4f} dB for SNR <= {flat:g} dB"),
        dict(quantity="reconstruction.low_snr_regime", value=f"SNR <= {low_ends[0]:g} dB",
             note="declared range of the upper end: " + ", ".join(f"{x:g}" for x in low_ends) + " dB"),
        dict(quantity="reconstruction.medium_snr_regime", value=f"SNR <= {med_ends[0]:g} dB",
             note="declared range of the upper end: " + ", ".join(f"{x:g}" for x in med_ends) + " dB; the bound's "
                  "rho_S threshold on 1 - alpha per end is in the evidence of rho_s_alpha_threshold"),
        dict(quantity="reconstruction.estimator",
             value=f"1 - alpha in {est['one_minus_alpha']}, SNR {est['snr_db']} dB, {est['n_runs']} runs, seed "
                   f"{est['seed']}, {est['n_boot']} bootstrap resamples" + cross),
    ]


def _paper_side(path) -> tuple:
    """``({id: at}, {claim id: ClaimEntry})`` of the claims, findings and errata files beside ``path``
    (default: this package's)."""
    data = load_paper_data("onebit", Path(path).parent if path else None)
    return data.settings(), {c.claim_id: c for c in data.claims}


def evidence_step(params, inputs, outputs):
    """Step of rule ``onebit_evidence``: table ``results/evidence/onebit.csv``.

    Inputs: ``ratios``, ``efq``, ``lag``, ``estimator`` (MSEs), ``estimator_ratios``, ``crossing``,
    ``coverage``, ``edge`` (:func:`.steps.estimator_step`), ``alpha_threshold``, the estimator ``shards`` and (optional) ``findings_file``, whose entries'
    ``at:`` fields (and those of ``claims.yaml`` beside it) give the settings the evidence quotes.
    Low-SNR values are recomputed at each case from (29), (34)/(36) and (47)-(49)
    (:func:`.randomwalk.ratios_at`), the same functions as ``ratios.csv``.

    Parameters
    ----------
    params : dict
        The ``onebit`` configuration's ``sigma_eta``, ``sigma_theta0``, ``mu_theta0``,
        ``snr_definition``, ``one_minus_alpha``, ``fig1_one_minus_alpha``, ``reference_snr_db``,
        ``snr_grid_db``, ``quadrature``, ``lag_tol_db``, ``estimator``, ``evidence`` (the declared
        ranges: ``low_snr_db``, ``low_regime_max_db``, ``medium_regime_max_db``, ...) and
        ``vector_check``.
    inputs : dict
        The paths named above (``results/onebit/*.csv``, the shard files, the paper's
        ``findings.yaml``, ``errata.yaml`` and ``claims.yaml``).
    outputs : dict
        ``table``: ``results/evidence/onebit.csv``.

    Returns
    -------
    dict
        ``{"table": DataFrame}``: the evidence rows (columns ``quantity, variant, value, note``,
        :func:`netrepro.judging.verdicts.evidence_frame`) of every claim, erratum, reconstruction and finding.
    """
    at, claims = _paper_side(inputs.get("findings_file"))
    params = dict(params, _at=at, _claims=claims)
    se, ev, q = params["sigma_eta"], params["evidence"], params["quadrature"]
    ratios = pd.read_csv(inputs["ratios"])
    efq = pd.read_csv(inputs["efq"])
    shards = inputs["shards"]
    shards = [shards] if isinstance(shards, str) else list(shards)
    grid_start = float(params["snr_grid_db"]["start"])
    eps5 = float(params["fig1_one_minus_alpha"])
    other_eps = [0.0] + [float(e) for e in params["one_minus_alpha"]]
    rows = []
    # the 1-bit loss without a state-space model, (29) with var = SNR sigma_eta^2
    e_lo = efq.loc[efq["snr_db"].idxmin()]
    rows.append(dict(quantity="efq_low_snr_db", value=round(float(e_lo["efq_db"]), 4),
                     note=f"10 log10(sigma_eta^2 E[F_q]) at SNR = {e_lo['snr_db']:g} dB (results/onebit/efq.csv)"))
    for snr in [grid_start] + [float(x) for x in ev["low_snr_db"]]:
        if snr != float(e_lo["snr_db"]):
            val = 10.0 * math.log10(float(expected_fisher_1bit(10.0 ** (snr / 10.0), **q)))
            rows.append(dict(quantity="efq_low_snr_db", variant=variant_label("snr_grid_db", f"SNR = {snr:g} dB"),
                             value=round(val, 4)))
    rows.append(dict(quantity="efq_low_snr_db", variant=variant_label("snr_grid_db", "SNR -> 0"),
                     value=round(10.0 * math.log10(2.0 / math.pi), 4)))

    def ratio(col):
        return lambda eps, snr: ratios_at([snr], eps, se, "stationary", q)[col][0]

    rows += _value_rows("rho_f_low_snr_db", low_snr_cases(0.0, grid_start, ev["low_snr_db"], other_eps),
                        ratio("rho_f_db"), note="rho_F (48) at the low-SNR end")
    # Fig 1 states its alpha: re-judged over the low-SNR ends and against the limit its 'asymptotic value' names
    cases5 = low_snr_cases(eps5, grid_start, ev["low_snr_db"], [0.0])
    rows += _value_rows("rho_sl_low_snr_db", cases5, ratio("rho_sl_db"),
                        note="rho_SL (47) at the low-SNR end; " + _fig1_window_note(params))

    def gap(eps, snr):
        r = ratios_at([snr], eps, se, "stationary", q)
        return abs(r["rho_sl_db"][0] - r["rho_f_db"][0])

    rows += _value_rows("same_loss_db", cases5, gap, note="|rho_SL - rho_F| at the low-SNR end")
    rows += _grid_claim_rows(params, ratios, q)
    threshold = pd.read_csv(inputs["alpha_threshold"])
    rows += _threshold_rows(params, threshold)
    _, med_ends = _regimes(params)
    eps_max = float(threshold[threshold["snr_db"] <= med_ends[0]]["one_minus_alpha_max"].min())
    rows += _achievable_rows(params, pd.read_csv(inputs["estimator_ratios"]), shards, eps_max)
    est_mse, crossing = pd.read_csv(inputs["estimator"]), pd.read_csv(inputs["crossing"])
    est_ratios = pd.read_csv(inputs["estimator_ratios"])
    rows += _finding_rows(params, est_mse, pd.read_csv(inputs["lag"]), ratios)
    rows += _crossing_evidence(params, crossing, pd.read_csv(inputs["edge"]))
    rows += _limit_evidence(params, crossing, est_ratios)
    rows += _coverage_evidence(params, pd.read_csv(inputs["coverage"]), est_mse, est_ratios)
    rows += errata_rows(params)
    rows += _reconstruction_rows(params)
    return {"table": evidence_frame(rows)}
