"""Pipeline steps of the `onebit` paper: read inputs, call the model, return tables.

Tables written (``results/onebit/``)
------------------------------------
``efq.csv``
    ``snr_db, var_ratio, efq, efq_db, efq_quad, rel_err`` -- (29) against
    ``snr_db = 10 log10(var_ratio)``, ``var_ratio = Var[theta]/sigma_eta^2``
    (the stationary SNR), by the trapezoid rule on the product-Gaussian form and
    by adaptive quadrature; ``rel_err`` is their relative difference.
``ratios.csv``
    ``alpha, snr_db, efq_db, rho_sl_db, rho_f_db, rho_s_db`` then
    ``one_minus_alpha, sigma_z2, j_f_inf, j_f_q, j_s_inf, j_s_q, rho_s_achievable_db`` -- steady-state
    fixed points; ``alpha = 1.0`` rows are the alpha -> 1 limit
    (``one_minus_alpha = 0``, BIM columns empty), with the limit of the achievable rho_S.
``lag.csv``
    ``alpha, snr_db, delta_needed`` then ``delta_q, delta_inf, delta_q_iterated,
    delta_inf_iterated, tol_db, delta_scaled, delta_break_even`` -- smallest smoothing lag at which
    both the 1-bit and the unquantized smoothing BIM are within ``tol_db`` of
    their Delta -> infinity values (closed form of the Moebius iteration,
    checked by iterating (27)/(37)-(38)); ``delta_scaled = delta_q *
    sqrt(E[F_q] sigma_z^2)`` tends to a constant as alpha -> 1; ``delta_break_even`` is the
    smallest lag with J_{k|k+Delta,q} > J_{k|k,inf} in steady state (empty: never).
``convergence.csv``
    ``alpha, snr_db, quantity, fixed_point, iterated, rel_diff, n_steps,
    k_converged`` -- each steady state (variance (33), filtering (24)/(34)
    started from sigma_theta0 with the transient E[F_q(theta_k)], smoothing
    gain (27)/(37)-(38)) against a long iteration; ``k_converged`` is the last
    step at which the iterate was farther than ``rtol`` from the fixed point, + 1
    (for ``var_theta`` the "iterate" is the corrected (32) at ``n_steps``, equal
    to the recursion Var_k = alpha^2 Var_{k-1} + sigma_z^2, and ``k_converged``
    its closed form).
``transient.csv``
    ``alpha, snr_db, k, var_ratio, efq_ratio, j_f_q_ratio, j_f_inf_ratio`` --
    trajectories (iterate / fixed point) at log-spaced steps (Fig S2).
``shards/estimator_<i>.npz``
    Per-run window MSEs of shard ``i``'s Monte Carlo blocks (merged in block order).
``estimator_mse.csv``
    ``alpha, snr_db, kind, mse, mse_lo, mse_hi, bound`` then ``bound_steady,
    mse_over_bound, n_runs, steady_dev, tau, window_start, window_stop, horizon, stride,
    n_eval, start_over_tau`` -- ``kind`` in ``filter_1bit, smoother_1bit, kalman_filter,
    rts_smoother``; banded grid filter/smoother on 1-bit data and Kalman/RTS on the
    unquantized data of the same paths and noise, 95 % intervals over runs, ``bound`` = BCRB
    over the evaluation steps, ``steady_dev`` its largest relative distance from the steady
    state there.
``estimator_ratios.csv``
    ``alpha, snr_db, quantity, estimate_db, lo_db, hi_db, bound_db, n_runs`` then the design
    columns -- rho_F, rho_S, rho_SL from the MSEs with paired-bootstrap 95 % intervals, next to
    the steady-state bound (47)-(49).
``estimator_crossing.csv``
    ``alpha, curve, snr_db_crossing`` -- where rho_S crosses 0 dB (estimate, lo, hi, bound).
``estimator_coverage.csv``
    ``alpha, snr_db, kind, case_set, replicate, reference_kind, kurtosis, n, mean, se, reference,
    reference_se, z, covered`` -- the normal 95 % interval of each MSE on disjoint replicates against
    the exact value (Kalman/RTS) or the other replicates (1-bit estimators).
``estimator_edge.csv``
    ``alpha, snr_db, quantity, estimate, lo, hi, unit, n_runs, extra_taus, tau`` -- the bias of the
    5-tau record edges, standard record minus a long record around it (same runs), in dB.
``alpha_scan.csv``, ``alpha_threshold.csv``
    rho_S and the break-even lag over alpha; the largest 1 - alpha with rho_S > 0 per SNR.
``vector_check.csv``
    ``quantity, form, max_rel_err`` -- general vector recursions on a 2-D
    non-symmetric model against the Kalman filter / RTS smoother.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from scipy.special import ndtri

from .estimators import (
    db_zero_crossing,
    downward_root,
    downward_roots,
    grid_smoother_at,
    kalman_rts,
    local_crossing_fit,
    paired_db_contrasts,
    paired_ratio_intervals,
    replicate_coverage,
    run_tail_statistics,
    simulate_block,
    window_mse,
)
from .fisher import achievable_rho_s_limit_db, expected_fisher_1bit, expected_fisher_1bit_quad
from .model import sigma_z2_from_snr, snr_grid, stationary_variance, vector_check
from .shards import EDGE_KINDS, ESTIMATOR_KINDS, RATIO_DEFS, estimator_cases, merged_runs
from .randomwalk import (
    bound_paths,
    estimator_design,
    information_ratios,
    information_ratios_limit,
    iterate_transient,
    rho_s_threshold_eps,
    rho_s_zero_crossing,
    rw_break_even_lag,
    rw_filtering_fixed_point,
    rw_lag_iterated,
    rw_lag_needed,
    rw_smoothing_gain_fixed_point,
    rw_smoothing_gain_iterated,
)

__all__ = [
    "efq_step",
    "ratios_step",
    "lag_step",
    "convergence_step",
    "estimator_shard_step",
    "estimator_step",
    "run_estimator",
    "alpha_scan_step",
    "vector_check_step",
]


def _db(x):
    return 10.0 * np.log10(x)


def efq_step(params, inputs, outputs):
    """Table ``efq.csv``: (29) on a fine SNR grid by the trapezoid form and by adaptive quadrature.

    At each SNR of the grid, ``var_ratio = 10^(snr_db/10) = Var[theta]/sigma_eta^2`` (the stationary
    SNR) and theta has mean zero; ``efq = sigma_eta^2 E[F_q]`` (dimensionless) by
    :func:`.fisher.expected_fisher_1bit` and ``efq_quad`` by :func:`.fisher.expected_fisher_1bit_quad`
    (an independent computation of the same integral).

    Parameters
    ----------
    params : dict
        The ``onebit`` configuration's ``quadrature`` (``half_width``, ``step``: the trapezoid
        range in standard deviations and its spacing) and ``efq_grid_db`` (``start``, ``stop``,
        ``step``, in dB).
    inputs : dict
        Only the step's code (no table is read).
    outputs : dict
        ``table``: ``results/onebit/efq.csv``.

    Returns
    -------
    dict
        ``{"table": DataFrame, "provenance": {"max_rel_err": float}}``: columns ``snr_db,
        var_ratio, efq, efq_db, efq_quad, rel_err`` (``rel_err = |efq/efq_quad - 1|``), and the largest
        ``rel_err``.
    """
    q = params["quadrature"]
    g = params["efq_grid_db"]
    snr_db = np.arange(g["start"], g["stop"] + g["step"] / 2, g["step"])
    v = 10.0 ** (snr_db / 10.0)  # stationary SNR = Var[theta] / sigma_eta^2
    e = expected_fisher_1bit(v, half_width=q["half_width"], step=q["step"])
    quad = np.array([expected_fisher_1bit_quad(float(vi))[0] for vi in v])
    frame = pd.DataFrame(dict(snr_db=snr_db, var_ratio=v, efq=e, efq_db=_db(e), efq_quad=quad,
                              rel_err=np.abs(e / quad - 1.0)))
    return {"table": frame, "provenance": {"max_rel_err": float(frame["rel_err"].max())}}


def ratios_step(params, inputs, outputs):
    """Table ``ratios.csv``: steady-state (47)-(49) for each alpha and the alpha -> 1 limit.

    For each ``1 - alpha`` the steady-state filtering and smoothing BIMs, unquantized (24)/(26) and
    1-bit (34)/(36), with E[F_q] (29) under the stationary law of theta (mean 0, variance (33)), and
    their ratios rho_SL (47), rho_F (48), rho_S (49) in dB (:func:`.randomwalk.information_ratios`).
    With the stationary SNR definition the alpha -> 1 limit is added (``alpha = 1``,
    :func:`.randomwalk.information_ratios_limit`; its BIM columns are NaN), with the alpha -> 1 limit of
    the achievable rho_S, ``rho_s_achievable_db`` (:func:`.fisher.achievable_rho_s_limit_db`; -inf from
    3.01 dB on; NaN on the finite-alpha rows).

    Parameters
    ----------
    params : dict
        The ``onebit`` configuration's ``snr_grid_db`` (``start``, ``stop``, ``step`` in dB),
        ``quadrature`` (``half_width``, ``step``), ``one_minus_alpha`` (list of ``1 - alpha``),
        ``sigma_eta`` (noise standard deviation) and ``snr_definition`` (``"stationary"`` or
        ``"innovation"``).
    inputs : dict
        Only the step's code (no table is read).
    outputs : dict
        ``table``: ``results/onebit/ratios.csv``.

    Returns
    -------
    dict
        ``{"table": DataFrame}``: one row per alpha and SNR, columns ``alpha, snr_db, efq_db,
        rho_sl_db, rho_f_db, rho_s_db, one_minus_alpha, sigma_z2, j_f_inf, j_f_q, j_s_inf, j_s_q,
        rho_s_achievable_db``.
    """
    snr_db = snr_grid(**params["snr_grid_db"])
    q = params["quadrature"]
    frames = []
    for eps in params["one_minus_alpha"]:
        s = sigma_z2_from_snr(snr_db, eps, params["sigma_eta"], params["snr_definition"])
        e = expected_fisher_1bit(stationary_variance(eps, s) / params["sigma_eta"] ** 2,
                                 half_width=q["half_width"], step=q["step"])
        res = information_ratios(snr_db, eps, params["sigma_eta"], params["snr_definition"], efq=e)
        frames.append(pd.DataFrame(dict(
            alpha=1.0 - eps, snr_db=snr_db, efq_db=_db(res["efq"]), rho_sl_db=res["rho_sl_db"],
            rho_f_db=res["rho_f_db"], rho_s_db=res["rho_s_db"], one_minus_alpha=eps, sigma_z2=res["sigma_z2"],
            j_f_inf=res["j_f_inf"], j_f_q=res["j_f_q"], j_s_inf=res["j_s_inf"], j_s_q=res["j_s_q"])))
    if params["snr_definition"] == "stationary":
        lim = information_ratios_limit(snr_db)
        frames.append(pd.DataFrame(dict(
            alpha=1.0, snr_db=snr_db, efq_db=_db(lim["efq"]), rho_sl_db=lim["rho_sl_db"], rho_f_db=lim["rho_f_db"],
            rho_s_db=lim["rho_s_db"], one_minus_alpha=0.0, sigma_z2=0.0, j_f_inf=np.nan, j_f_q=np.nan,
            j_s_inf=np.nan, j_s_q=np.nan, rho_s_achievable_db=achievable_rho_s_limit_db(snr_db))))
    return {"table": pd.concat(frames, ignore_index=True)}


def lag_step(params, inputs, outputs):
    """Table ``lag.csv``: the smoothing lag Delta each SNR needs (closed form, checked by iteration).

    For each ``1 - alpha`` and SNR: the smallest lag at which the steady-state smoothing BIM is within
    ``lag_tol_db`` of its Delta -> infinity value, 1-bit (information E[F_q] of (29) under the
    stationary law) and unquantized (``1/sigma_eta^2``, (23)), in closed form
    (:func:`.randomwalk.rw_lag_needed`) and, when both closed-form lags are at most
    ``lag_iterate_max``, by iterating (27)/(37)-(38) (:func:`.randomwalk.rw_lag_iterated`; else
    -1); and the break-even lag, the smallest with J_{k|k+Delta,q} > J_{k|k,inf}
    (:func:`.randomwalk.rw_break_even_lag`; NaN: never).

    Parameters
    ----------
    params : dict
        The ``onebit`` configuration's ``snr_grid_db`` (``start``, ``stop``, ``step`` in dB),
        ``lag_tol_db`` (tolerance in dB), ``lag_iterate_max`` (largest lag checked by iteration),
        ``one_minus_alpha``, ``sigma_eta`` and ``snr_definition``.
    inputs : dict
        Only the step's code (no table is read).
    outputs : dict
        ``table``: ``results/onebit/lag.csv``.

    Returns
    -------
    dict
        ``{"table": DataFrame}``: columns ``alpha, snr_db, delta_needed, delta_q, delta_inf,
        delta_q_iterated, delta_inf_iterated, tol_db, delta_scaled, delta_break_even``
        (``delta_needed`` is the larger of ``delta_q`` and ``delta_inf``).
    """
    snr_db = snr_grid(**params["snr_grid_db"])
    tol = params["lag_tol_db"]
    se = params["sigma_eta"]
    frames = []
    for eps in params["one_minus_alpha"]:
        s = sigma_z2_from_snr(snr_db, eps, se, params["snr_definition"])
        Fq = expected_fisher_1bit(stationary_variance(eps, s) / se**2) / se**2
        Fi = np.full_like(s, 1.0 / se**2)
        dq, di = rw_lag_needed(Fq, eps, s, tol), rw_lag_needed(Fi, eps, s, tol)
        be = rw_break_even_lag(Fq, Fi, eps, s)
        if max(dq.max(), di.max()) <= params["lag_iterate_max"]:
            dq_it, di_it = rw_lag_iterated(Fq, eps, s, tol), rw_lag_iterated(Fi, eps, s, tol)
        else:
            dq_it = di_it = np.full(len(s), -1)
        frames.append(pd.DataFrame(dict(alpha=1.0 - eps, snr_db=snr_db, delta_needed=np.maximum(dq, di),
                                        delta_q=dq, delta_inf=di, delta_q_iterated=dq_it, delta_inf_iterated=di_it,
                                        tol_db=tol, delta_scaled=dq * np.sqrt(Fq * s),
                                        delta_break_even=np.where(be < 0, np.nan, be.astype(float)))))
    return {"table": pd.concat(frames, ignore_index=True)}


def convergence_step(params, inputs, outputs):
    """Tables ``convergence.csv`` and ``transient.csv``: fixed points against long iterations.

    For each ``1 - alpha`` and SNR: the stationary variance (33) against the recursion (32) after
    ``n_steps``; the filtering BIMs (24) and (34) iterated from the prior ``J_{0|0} = 1/sigma_theta0^2``
    with the transient E[F_q(theta_k)] (mean (31), variance (32)) against their fixed points
    (:func:`.randomwalk.iterate_transient`); and the smoothing gains kappa (27) and kappa_q
    (37)-(38), with the stationary E[F_q], iterated ``n_lag_steps`` times from 0 against their fixed
    points. ``k_converged`` is the last step farther than ``rtol`` from the fixed point, + 1.

    Parameters
    ----------
    params : dict
        The ``onebit`` configuration's ``convergence`` (``snr_db``: SNRs in dB; ``n_steps`` and
        ``n_lag_steps``: one per ``one_minus_alpha``; ``rtol``: relative convergence tolerance;
        ``n_record``: number of log-spaced steps recorded), ``one_minus_alpha``, ``sigma_eta``,
        ``sigma_theta0`` (prior standard deviation), ``mu_theta0`` (prior mean) and
        ``snr_definition``.
    inputs : dict
        Only the step's code (no table is read).
    outputs : dict
        ``table`` and ``transient``: ``results/onebit/convergence.csv`` and ``transient.csv``.

    Returns
    -------
    dict
        ``{"table": DataFrame, "transient": DataFrame, "provenance": {"n_filter_steps": int}}``:
        ``table`` has one row per alpha, SNR and quantity (``var_theta, j_f_q, j_f_inf, kappa_q,
        kappa_inf``) with ``fixed_point, iterated, rel_diff, n_steps, k_converged``; ``transient``
        the trajectories over fixed point at the recorded steps; ``n_filter_steps`` the number of
        filter steps iterated (``n_steps`` times the number of SNRs, summed over alpha).
    """
    c = params["convergence"]
    se, sig0 = params["sigma_eta"], params["sigma_theta0"]
    rows, trace_frames = [], []
    n_total = 0
    for eps, n_steps in zip(params["one_minus_alpha"], c["n_steps"]):
        snr_db = np.asarray(c["snr_db"], dtype=float)
        record = np.unique(np.concatenate([[0], np.round(np.logspace(0, math.log10(n_steps), c["n_record"]))]))
        out = iterate_transient(snr_db, eps, sig0, params["mu_theta0"], se, n_steps, c["rtol"], record=record,
                                definition=params["snr_definition"])
        n_total += n_steps * len(snr_db)
        s = out["sigma_z2"]
        Fq = expected_fisher_1bit(out["var_inf"] / se**2) / se**2
        Fi = np.full_like(s, 1.0 / se**2)
        # smoothing gain: Delta steps of (27)/(38) with the stationary E[F_q]
        n_lag = c["n_lag_steps"][params["one_minus_alpha"].index(eps)]
        kq_star = rw_smoothing_gain_fixed_point(Fq, eps, s)
        ki_star = rw_smoothing_gain_fixed_point(Fi, eps, s)
        kq, last_q = rw_smoothing_gain_iterated(Fq, eps, s, kq_star, n_lag, c["rtol"])
        ki, last_i = rw_smoothing_gain_iterated(Fi, eps, s, ki_star, n_lag, c["rtol"])
        for i, snr in enumerate(snr_db):
            base = dict(alpha=1.0 - eps, snr_db=snr)
            for qty, fp, it, n, kc in (
                ("var_theta", out["var_inf"][i], out["var_final"][i], n_steps, out["k_conv_var"][i]),
                ("j_f_q", out["j_f_q_star"][i], out["j_f_q"][i], n_steps, out["k_conv_q"][i]),
                ("j_f_inf", out["j_f_inf_star"][i], out["j_f_inf"][i], n_steps, out["k_conv_inf"][i]),
                ("kappa_q", kq_star[i], kq[i], n_lag, last_q[i] + 1),
                ("kappa_inf", ki_star[i], ki[i], n_lag, last_i[i] + 1),
            ):
                rows.append(dict(base, quantity=qty, fixed_point=fp, iterated=it, rel_diff=abs(it / fp - 1.0),
                                 n_steps=n, k_converged=kc))
        tr = out["trace"]
        for i, snr in enumerate(snr_db):
            trace_frames.append(pd.DataFrame(dict(
                alpha=1.0 - eps, snr_db=snr, k=out["record"], var_ratio=tr["var_ratio"][:, i],
                efq_ratio=tr["efq_ratio"][:, i], j_f_q_ratio=tr["j_f_q_ratio"][:, i],
                j_f_inf_ratio=tr["j_f_inf_ratio"][:, i])))
    return {"table": pd.DataFrame(rows), "transient": pd.concat(trace_frames, ignore_index=True),
            "provenance": {"n_filter_steps": int(n_total)}}


def _estimator_design(params, eps, snr):
    """Noise variance, 1-bit information and run design (window after >= burn_in_taus time constants)."""
    est, se = params["estimator"], params["sigma_eta"]
    s = float(sigma_z2_from_snr(snr, eps, se, params["snr_definition"]))
    Fq = float(expected_fisher_1bit(float(stationary_variance(eps, s)) / se**2)) / se**2
    design = estimator_design((Fq, 1.0 / se**2), eps, s, est["burn_in_taus"], est["window_taus"], est["tail_taus"],
                              est["evals_per_tau"])
    return s, Fq, design


def _estimator_simulator(params, eps, snr):
    """``fn(rng, n)``: per-run MSEs over the evaluation steps of the four estimators, on the same paths and noise."""
    est, se = params["estimator"], params["sigma_eta"]
    s, _, design = _estimator_design(params, eps, snr)
    ev = design["eval_idx"]

    def fn(rng, n):
        theta, y, r = simulate_block(rng, n, design["horizon"], eps, s, se)   # r = sign(y): one noise draw
        filt, smooth = grid_smoother_at(r, eps, s, se, ev, est["grid_half_width"], est["points_per_sigma_z"],
                                        est["band_sigmas"])
        kf, rts = kalman_rts(y, eps, s, se)
        th = theta[:, ev]
        return {"filter_1bit": window_mse(filt, th), "smoother_1bit": window_mse(smooth, th),
                "kalman_filter": window_mse(kf[:, ev], th), "rts_smoother": window_mse(rts[:, ev], th)}

    return fn


def _edge_simulator(params, eps, snr):
    """``fn(rng, n)``: per-run MSEs of the four estimators on the standard record and on a long record around it.

    The long record adds ``estimator.edge.extra_taus`` time constants before and after the standard
    record (:func:`.randomwalk.estimator_design`); the standard record is its middle part, started
    from the stationary prior (theta there is stationary), so both see the same states and noise
    at the same evaluation steps and differ only in the data beyond the 5-tau edges.
    """
    est, se = params["estimator"], params["sigma_eta"]
    s, _, design = _estimator_design(params, eps, snr)
    ev, K = design["eval_idx"], design["horizon"]
    extra = int(math.ceil(float(est["edge"]["extra_taus"]) * design["tau"]))
    grid = (est["grid_half_width"], est["points_per_sigma_z"], est["band_sigmas"])

    def fn(rng, n):
        theta, y, r = simulate_block(rng, n, K + 2 * extra, eps, s, se)
        th = theta[:, ev + extra]
        out = {}
        for suffix, yy, rr, idx in (("", y[:, extra:extra + K], r[:, extra:extra + K], ev),
                                    ("_long", y, r, ev + extra)):
            filt, smooth = grid_smoother_at(rr, eps, s, se, idx, *grid)
            kf, rts = kalman_rts(yy, eps, s, se)
            out.update({f"filter_1bit{suffix}": window_mse(filt, th), f"smoother_1bit{suffix}": window_mse(smooth, th),
                        f"kalman_filter{suffix}": window_mse(kf[:, idx], th),
                        f"rts_smoother{suffix}": window_mse(rts[:, idx], th)})
        return out

    return fn


def estimator_shard_step(params, inputs, outputs):
    """Step: per-run window MSEs of one shard's blocks, for every case; block ``b`` has its own generator.

    For every case of :func:`.shards.estimator_cases` (``1 - alpha``, SNR, seed, number of runs), the
    shard's blocks of ``estimator.block_size`` runs are simulated, block ``b`` with the generator
    :func:`netrepro.engines.montecarlo.block_rng` of the case's seed and ``b``: random-walk paths, one noise draw per path giving both the unquantized
    data y and the 1-bit data ``r = sign(y)``; the banded grid filter and smoother on r, the Kalman
    filter and RTS smoother on y; each run's mean squared error over the evaluation steps of the
    design (:func:`.randomwalk.estimator_design`). The results do not depend on the number of shards.

    Parameters
    ----------
    params : dict
        The ``onebit`` configuration's ``estimator`` (cases, ``block_size``, ``seed``, the run design
        ``burn_in_taus``, ``window_taus``, ``tail_taus``, ``evals_per_tau`` and the grid filter's
        ``grid_half_width``, ``points_per_sigma_z``, ``band_sigmas``), ``sigma_eta`` and
        ``snr_definition``, plus ``shard`` (this shard, 0-based) and ``n_shards``.
    inputs : dict
        Only the step's code (no table is read).
    outputs : dict
        ``runs``: ``results/onebit/shards/estimator_<shard>.npz``, written by the step (atomically):
        per case key ``<key>|blocks`` and ``<key>|counts`` (block indices and their run counts) and
        ``<key>|<kind>`` (per-run MSEs) for each kind of :data:`.shards.ESTIMATOR_KINDS` (of
        :data:`.shards.EDGE_KINDS` for an edge case: :func:`_edge_simulator`).

    Returns
    -------
    dict
        ``{"provenance": {"blocks": list of int, "seed": int}}``: the block indices of the first
        case (every grid case has the same) and ``estimator.seed``; no table.
    """
    from ...engines.montecarlo import block_rng, shard_blocks
    from ...pipeline.io import atomic_path

    est = params["estimator"]
    arrays, used = {}, {}
    for case in estimator_cases(params):
        blocks = shard_blocks(case.n_runs, est["block_size"], params["n_shards"], params["shard"])
        sizes = [min(est["block_size"], case.n_runs - b * est["block_size"]) for b in blocks]
        edge = case.case_set == "edge"
        fn = (_edge_simulator if edge else _estimator_simulator)(params, case.eps, case.snr_db)
        per_block = [fn(block_rng(case.seed, b), n) for b, n in zip(blocks, sizes)]
        arrays[f"{case.key}|blocks"] = np.asarray(blocks, dtype=np.int64)
        arrays[f"{case.key}|counts"] = np.asarray(sizes, dtype=np.int64)
        used[case.key] = [int(b) for b in blocks]
        for kind in EDGE_KINDS if edge else ESTIMATOR_KINDS:
            arrays[f"{case.key}|{kind}"] = np.concatenate([v[kind] for v in per_block]) if per_block else np.empty(0)
    with atomic_path(outputs["runs"]) as tmp:
        with open(tmp, "wb") as fh:
            np.savez(fh, **arrays)
    grid_blocks = next(iter(used.values()), [])
    return {"provenance": {"blocks": grid_blocks, "seed": est["seed"]}}


def _half_ratios_db(num, den) -> tuple:
    """The MSE ratio (dB) on the first and on the second half of the runs (disjoint seed blocks)."""
    n = len(num) // 2
    return tuple(float(10.0 * np.log10(num[sl].mean() / den[sl].mean())) for sl in (slice(0, n), slice(n, 2 * n)))


def _replicate_ratios_db(num, den, n_replicates: int) -> np.ndarray:
    """The MSE ratio (dB) on each of ``n_replicates`` disjoint contiguous replicates of the runs."""
    return np.array([10.0 * np.log10(a.mean() / b.mean())
                     for a, b in zip(np.array_split(np.asarray(num), n_replicates),
                                     np.array_split(np.asarray(den), n_replicates))])


def _crossing_rows(params, ratio_rows, boot) -> pd.DataFrame:
    """Rows of ``estimator_crossing.csv`` for every simulated alpha: local fit with a bootstrap interval, and the bound.

    Where the configuration has crossing cases for an alpha, the fit uses those SNRs; otherwise
    the grid points around the first sign change of the grid estimate (one on each side of the
    two bracketing points, when they exist). ``fit_degree_<d>`` and ``runs_first_half`` /
    ``runs_second_half`` are point estimates of the same fit with another degree or on half the runs
    (sensitivity). ``replicate_se`` checks the bootstrap interval (``bootstrap_se``: its width over
    2 x 1.96) against an independent estimate of the same standard error: the standard deviation of
    the crossings fitted on ``estimator.n_replicates`` disjoint replicates of the runs, over
    sqrt(replicates). ``grid_linear`` is the straight line between the two bracketing grid estimates
    (the former estimate, for comparison only).
    """
    est, se = params["estimator"], params["sigma_eta"]
    degree = int(est.get("crossing", {}).get("degree", 2))
    rs = [r for r in ratio_rows if r["quantity"] == "rho_S"]
    rows = []
    for eps in est["one_minus_alpha"]:
        a = 1.0 - float(eps)
        mine = [r for r in rs if r["alpha"] == a]
        grid = sorted((r for r in mine if r["case_set"] == "grid"), key=lambda r: r["snr_db"])
        cross = sorted((r for r in mine if r["case_set"] == "crossing"), key=lambda r: r["snr_db"])
        gx = np.array([r["snr_db"] for r in grid])
        gy = np.array([r["estimate_db"] for r in grid])
        lin = db_zero_crossing(gx, gy)
        if len(cross) > degree:
            pts, method = cross, "local fit, crossing SNRs"
        else:
            idx = np.flatnonzero((gy[:-1] > 0) & (gy[1:] <= 0))
            pts, method = [], "local fit, grid SNRs"
            if len(idx):
                i = int(idx[0])
                pts = grid[max(0, i - 1):min(len(grid), i + 3)]
        base = dict(alpha=a, method=method, degree=degree)
        if len(pts) > degree:
            x = np.array([r["snr_db"] for r in pts])
            y = np.array([r["estimate_db"] for r in pts])
            yb = np.column_stack([boot[r["key"]] for r in pts])
            fit = local_crossing_fit(x, y, yb, degree)
            info = dict(fit_snr_lo=float(x.min()), fit_snr_hi=float(x.max()), n_points=len(x),
                        n_runs=int(min(r["n_runs"] for r in pts)), n_boot=int(yb.shape[0]),
                        boot_fail_frac=fit["fail_frac"], fit_residual_rms=fit["residual_rms"])
            slope = float(np.polyval(np.polyder(fit["coefs"]), fit["estimate"])) if np.isfinite(fit["estimate"]) \
                else float("nan")
            for curve in ("estimate", "lo", "hi"):
                rows.append(dict(base, curve=curve, snr_db_crossing=fit[curve], **info))
            rows[-3]["slope_db_per_db"] = slope
            # the fitted curve itself (Fig S4): its coefficients, highest power first
            rows[-3]["coefs"] = " ".join(f"{c:.12g}" for c in fit["coefs"])
            # sensitivity (point estimates): the fit's degree, and each half of the runs at the configured degree
            for deg in sorted({1, 3} - {degree}):
                if len(x) > deg:
                    rows.append(dict(base, degree=deg, curve=f"fit_degree_{deg}", **info,
                                     snr_db_crossing=downward_root(np.polyfit(x, y, deg), x.min(), x.max())))
            for h, name in enumerate(("runs_first_half", "runs_second_half")):
                yh = np.array([r["half_db"][h] for r in pts])
                rows.append(dict(base, curve=name, **dict(info, n_runs=info["n_runs"] // 2),
                                 snr_db_crossing=downward_root(np.polyfit(x, yh, degree), x.min(), x.max())))
            # the bootstrap band checked against disjoint replicates: the spread of the replicates' crossings
            # over sqrt(R) is an estimate of the full-sample standard error independent of the bootstrap
            yr = np.column_stack([r["rep_db"] for r in pts])          # (R, points)
            rep_roots = downward_roots(np.polyfit(x, yr.T, degree).T, x.min(), x.max())
            n_rep = yr.shape[0]
            ok = np.isfinite(rep_roots)   # a replicate whose fit has no root in the window is left out (counted)
            se_rep = float(np.std(rep_roots[ok], ddof=1) / math.sqrt(n_rep)) if ok.sum() > 2 else float("nan")
            rows.append(dict(base, curve="replicate_se", **dict(info, n_runs=info["n_runs"] // n_rep),
                             snr_db_crossing=se_rep, n_replicates=n_rep,
                             n_replicates_crossing=int(np.isfinite(rep_roots).sum())))
            rows.append(dict(base, curve="bootstrap_se", **info, n_replicates=n_rep,
                             snr_db_crossing=(fit["hi"] - fit["lo"]) / (2.0 * float(ndtri(0.975)))))
        else:
            for curve in ("estimate", "lo", "hi"):
                rows.append(dict(base, curve=curve, snr_db_crossing=float("nan")))
        rows.append(dict(alpha=a, curve="grid_linear", snr_db_crossing=lin, method="straight line between the "
                         "bracketing grid estimates (former estimate; comparison only)", degree=1))
        rows.append(dict(alpha=a, curve="bound", snr_db_crossing=rho_s_zero_crossing(eps, se, params["snr_definition"]),
                         method="steady-state bound (49), Brent's method"))
    cols = ["alpha", "curve", "snr_db_crossing", "method", "degree", "fit_snr_lo", "fit_snr_hi", "n_points", "n_runs",
            "n_boot", "boot_fail_frac", "fit_residual_rms", "slope_db_per_db", "coefs", "n_replicates",
            "n_replicates_crossing"]
    return pd.DataFrame(rows).reindex(columns=cols)


def estimator_step(params, inputs, outputs):
    """Step: tables ``estimator_mse.csv``, ``estimator_ratios.csv`` and ``estimator_crossing.csv`` from the shards.

    ``estimator_mse.csv``: each estimator's MSE (95 % normal interval over runs) next to the BCRB
    (34)/(36) or (24)/(26) over the same evaluation steps of the finite record (``bound``) and its
    steady state (``bound_steady``); ``steady_dev`` is the largest relative distance of the
    finite-record bound from its steady state over the evaluation steps (the window is in steady
    state when it is small); ``kurtosis``, ``max_over_mean`` and ``se_ratio`` describe the per-run
    MSEs' tails and check the normal standard error against the seed blocks as independent
    replicates (:func:`.estimators.run_tail_statistics`). ``estimator_ratios.csv``: rho_F, rho_S,
    rho_SL from the MSEs with a paired bootstrap interval, next to the bound (49)-(47).
    ``case_set`` is ``grid`` or ``crossing`` (:mod:`.runs`). ``estimator_crossing.csv``: the SNR
    at which the achievable rho_S crosses 0 dB by a local polynomial fit with a bootstrap interval
    over runs (:func:`.estimators.local_crossing_fit`; the estimate's row also holds the fit's slope
    there and its coefficients), the former straight-line estimate, and the bound's crossing.
    ``estimator_coverage.csv`` (issue 37): every grid and crossing case's runs cut into
    ``estimator.n_replicates`` disjoint replicates; per replicate and estimator the normal 95 %
    interval of the MSE against the exact value (Kalman/RTS: the finite-record BCRB, which they
    attain) or, for the 1-bit estimators, against the other replicates' mean
    (:func:`.estimators.replicate_coverage`); and, per case (``replicate = -1``), the paired bootstrap 95 %
    interval of the Kalman filter's MSE over the RTS smoother's (dB) against its exact value, the ratio
    of their finite-record bounds. ``estimator_ratios.csv`` also checks each ratio's bootstrap band against
    the replicates: ``se_boot_db`` (interval width over 2 x 1.96) and ``se_rep_db`` (standard deviation of
    the ratio over ``estimator.n_replicates`` disjoint replicates, over sqrt(replicates)). ``estimator_edge.csv`` (issue 37): for the edge
    cases, the bias of the 5-tau record edges: each MSE on the standard record over the MSE on
    the long record around it, and rho_S, rho_F, rho_SL on the standard minus the long record, in dB
    with paired bootstrap intervals (:func:`_edge_rows`).

    Parameters
    ----------
    params : dict
        The ``onebit`` configuration's ``estimator`` (cases, run design, ``n_boot``: bootstrap
        resamples, ``n_replicates``, ``crossing``: the crossing cases and fit ``degree``, ``edge``:
        the edge cases and ``extra_taus``), ``sigma_eta`` and ``snr_definition``.
    inputs : dict
        ``shards``: the files written by :func:`estimator_shard_step` (any number of shards).
    outputs : dict
        ``table``, ``ratios``, ``crossing``, ``coverage`` and ``edge``: ``results/onebit/estimator_mse.csv``,
        ``estimator_ratios.csv``, ``estimator_crossing.csv``, ``estimator_coverage.csv`` and
        ``estimator_edge.csv``.

    Returns
    -------
    dict
        ``{"table", "ratios", "crossing", "coverage", "edge": DataFrame}``: the five tables above.
    """
    est, se = params["estimator"], params["sigma_eta"]
    mse_rows, ratio_rows, boot = [], [], {}
    z = float(ndtri(0.975))
    ref_s, onebit_s, _ = RATIO_DEFS["rho_S"]
    cov_rows, edge_rows = [], []
    n_rep = int(est.get("n_replicates", 8))
    for case in estimator_cases(params):
        key, eps, snr, seed = case.key, case.eps, case.snr_db, case.seed
        if case.case_set == "edge":
            edge_rows += _edge_rows(params, case, merged_runs(inputs["shards"], key, kinds=EDGE_KINDS))
            continue
        runs = merged_runs(inputs["shards"], key, with_blocks=True)
        s, Fq, d = _estimator_design(params, eps, snr)
        ev = d["eval_idx"]
        var_inf = float(stationary_variance(eps, s))
        bounds, steady, dev = {}, {}, {}
        for F, kf, ks in ((Fq, "filter_1bit", "smoother_1bit"), (1.0 / se**2, "kalman_filter", "rts_smoother")):
            Jf, Js = bound_paths(F, eps, s, var_inf, d["horizon"])
            jf = float(rw_filtering_fixed_point(F, eps, s))
            js = jf + float(rw_smoothing_gain_fixed_point(F, eps, s))
            for kind, J, jss in ((kf, Jf, jf), (ks, Js, js)):
                bounds[kind], steady[kind] = float(np.mean(1.0 / J[ev])), 1.0 / jss
                dev[kind] = float(np.max(np.abs(jss / J[ev] - 1.0)))
        design_cols = dict(tau=d["tau"], window_start=d["start"], window_stop=d["stop"], horizon=d["horizon"],
                           stride=d["stride"], n_eval=len(ev), start_over_tau=d["start"] / d["tau"])
        for kind in ESTIMATOR_KINDS:
            v = runs[kind]
            m, half = float(v.mean()), z * float(v.std(ddof=1)) / math.sqrt(len(v))
            tails = run_tail_statistics(v, runs["block"])
            if len(v) >= 2 * n_rep:   # the normal interval's coverage on disjoint replicates (issue 37)
                exact = kind in ("kalman_filter", "rts_smoother")   # Kalman/RTS attain the finite-record BCRB
                cov = replicate_coverage(v, n_rep, reference=bounds[kind] if exact else None)
                cov_rows += [dict(alpha=1.0 - eps, snr_db=snr, kind=kind, case_set=case.case_set, replicate=r,
                                  reference_kind="exact (finite-record BCRB)" if exact else "other replicates",
                                  kurtosis=tails["kurtosis"], **{c: cov[c][r] for c in cov})
                             for r in range(n_rep)]
            mse_rows.append(dict(alpha=1.0 - eps, snr_db=snr, kind=kind, mse=m, mse_lo=m - half, mse_hi=m + half,
                                 bound=bounds[kind], bound_steady=steady[kind], mse_over_bound=m / bounds[kind],
                                 n_runs=len(v), steady_dev=dev[kind], **design_cols, case_set=case.case_set,
                                 **tails))
        bound = information_ratios(np.array([snr]), eps, se, params["snr_definition"])
        # the three ratios, and the Kalman filter over the RTS smoother: both attain their bound, so that ratio is
        # known exactly and checks the paired bootstrap band (adding the pair changes no other pair's numbers)
        pairs = [(ref, onebit) for ref, onebit, _ in RATIO_DEFS.values()] + [("kalman_filter", "rts_smoother")]
        intervals, reps = paired_ratio_intervals(runs, pairs, est["n_boot"], seed,  # one resampling per case,
                                                 replicates=True)                    # shared by the ratios
        for (qty, (ref, onebit, col)), (e, lo, hi) in zip(RATIO_DEFS.items(), intervals):
            rep = _replicate_ratios_db(runs[ref], runs[onebit], n_rep)
            ratio_rows.append(dict(alpha=1.0 - eps, snr_db=snr, quantity=qty, estimate_db=e, lo_db=lo, hi_db=hi,
                                   bound_db=float(bound[col][0]), n_runs=len(runs[ref]),
                                   steady_dev=max(dev[ref], dev[onebit]), **design_cols, case_set=case.case_set,
                                   se_boot_db=(hi - lo) / (2.0 * z), se_rep_db=float(np.std(rep, ddof=1) / math.sqrt(n_rep)),
                                   key=key, half_db=_half_ratios_db(runs[ref], runs[onebit]), rep_db=rep))
        e, lo, hi = intervals[-1]
        exact_db = 10.0 * math.log10(bounds["kalman_filter"] / bounds["rts_smoother"])
        se_b = (hi - lo) / (2.0 * z)
        cov_rows.append(dict(alpha=1.0 - eps, snr_db=snr, kind="ratio_db:kalman_filter/rts_smoother",
                             case_set=case.case_set, replicate=-1, reference_kind="exact (ratio of the finite-record BCRBs)",
                             kurtosis=float("nan"), n=float(len(runs["kalman_filter"])), mean=e, se=se_b,
                             reference=exact_db, reference_se=0.0, z=(e - exact_db) / se_b, covered=lo <= exact_db <= hi))
        # bootstrap replicates of the achievable rho_S for the crossing fit: bootstrap_ratio_db(runs[ref_s],
        # runs[onebit_s], n_boot, seed), the same numbers as the intervals' resampling (same seed), not redrawn
        boot[key] = reps[pairs.index((ref_s, onebit_s))]
    crossing = _crossing_rows(params, ratio_rows, boot)
    ratios = pd.DataFrame(ratio_rows).drop(columns=["key", "half_db", "rep_db"])
    coverage = pd.DataFrame(cov_rows, columns=COVERAGE_COLUMNS)
    coverage["covered"] = coverage["covered"].astype(bool)
    return {"table": pd.DataFrame(mse_rows), "ratios": ratios, "crossing": crossing, "coverage": coverage,
            "edge": pd.DataFrame(edge_rows, columns=EDGE_COLUMNS)}


COVERAGE_COLUMNS = ["alpha", "snr_db", "kind", "case_set", "replicate", "reference_kind", "kurtosis", "n", "mean", "se",
                    "reference", "reference_se", "z", "covered"]
EDGE_COLUMNS = ["alpha", "snr_db", "quantity", "estimate", "lo", "hi", "unit", "n_runs", "extra_taus", "tau"]


def _edge_rows(params, case, runs) -> list:
    """Rows of ``estimator_edge.csv`` for one edge case: each estimator's MSE on the standard record over
    its MSE on the long record (dB), and the bias of rho_S, rho_F, rho_SL (standard minus long record, dB),
    with paired percentile bootstrap intervals over runs (:func:`.estimators.paired_db_contrasts`)."""
    est = params["estimator"]
    _, _, d = _estimator_design(params, case.eps, case.snr_db)
    contrasts, names = [], []
    for kind in ESTIMATOR_KINDS:
        contrasts.append([(kind, f"{kind}_long", 1.0)])
        names.append(f"mse_edge_bias_db.{kind}")
    for qty, (ref, onebit, _) in RATIO_DEFS.items():
        contrasts.append([(ref, onebit, 1.0), (f"{ref}_long", f"{onebit}_long", -1.0)])
        names.append(f"edge_bias_db.{qty}")
    res = paired_db_contrasts(runs, contrasts, est["n_boot"], case.seed)
    n = len(runs[ESTIMATOR_KINDS[0]])
    return [dict(alpha=1.0 - case.eps, snr_db=case.snr_db, quantity=name, estimate=e, lo=lo, hi=hi, unit="dB",
                 n_runs=n, extra_taus=float(est["edge"]["extra_taus"]), tau=d["tau"])
            for name, (e, lo, hi) in zip(names, res)]


def run_estimator(params):
    """Shard and merge in one process (tests, notebooks): the same tables as the two pipeline steps.

    Runs :func:`estimator_shard_step` as the only shard into a temporary file, then
    :func:`estimator_step` on it.

    Parameters
    ----------
    params : dict
        The ``onebit`` configuration's ``estimator``, ``sigma_eta`` and ``snr_definition`` (as for
        :func:`estimator_step`).

    Returns
    -------
    dict
        What :func:`estimator_step` returns: ``{"table", "ratios", "crossing", "coverage", "edge": DataFrame}``.
    """
    import tempfile
    from pathlib import Path

    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "runs.npz"
        estimator_shard_step(dict(params, shard=0, n_shards=1), {}, {"runs": path})
        return estimator_step(params, {"shards": [path]}, {})


def alpha_scan_step(params, inputs, outputs):
    """Tables ``alpha_scan.csv`` and ``alpha_threshold.csv``: rho_S (49) and the break-even lag over alpha.

    ``alpha_scan.csv``: ``alpha, one_minus_alpha, snr_db, rho_s_db, rho_f_db, delta_break_even``
    on the configured grid. ``alpha_threshold.csv``: per SNR the largest ``1 - alpha`` with
    rho_S > 0 dB (bisection), and ``single_sign_change``: whether rho_S changes sign once along the
    grid (the bisection's premise).

    Parameters
    ----------
    params : dict
        The ``onebit`` configuration's ``alpha_scan`` (``one_minus_alpha``: the ``1 - alpha`` grid;
        ``snr_db``: the SNRs in dB), ``sigma_eta`` and ``snr_definition``.
    inputs : dict
        Only the step's code (no table is read).
    outputs : dict
        ``table`` and ``threshold``: ``results/onebit/alpha_scan.csv`` and ``alpha_threshold.csv``.

    Returns
    -------
    dict
        ``{"table": DataFrame, "threshold": DataFrame}``: the scan (one row per alpha and SNR; the
        break-even lag NaN where there is none) and, per SNR, ``snr_db, one_minus_alpha_max,
        alpha_min, single_sign_change``.
    """
    sc, se = params["alpha_scan"], params["sigma_eta"]
    snr = np.asarray(sc["snr_db"], dtype=float)
    rows = []
    for eps in sc["one_minus_alpha"]:
        res = information_ratios(snr, eps, se, params["snr_definition"])
        Fq = res["efq"] / se**2
        lag = rw_break_even_lag(Fq, np.full_like(Fq, 1.0 / se**2), eps, res["sigma_z2"]).astype(float)
        rows.append(pd.DataFrame(dict(alpha=1.0 - eps, one_minus_alpha=eps, snr_db=snr, rho_s_db=res["rho_s_db"],
                                      rho_f_db=res["rho_f_db"], delta_break_even=np.where(lag < 0, np.nan, lag))))
    scan = pd.concat(rows, ignore_index=True)
    thr = []
    for x in snr:
        col = scan[scan["snr_db"] == x].sort_values("one_minus_alpha")["rho_s_db"].to_numpy() > 0
        eps_max = rho_s_threshold_eps(float(x), se, definition=params["snr_definition"])
        thr.append(dict(snr_db=x, one_minus_alpha_max=eps_max, alpha_min=1.0 - eps_max,
                        single_sign_change=bool(np.count_nonzero(np.diff(col.astype(int))) <= 1)))
    return {"table": scan, "threshold": pd.DataFrame(thr)}


def vector_check_step(params, inputs, outputs):
    """Table ``vector_check.csv``: the general recursions on a 2-D non-symmetric model vs Kalman/RTS.

    The general recursions (7), (14), (16), (17)-(19), corrected and as printed, against the inverse
    Kalman/RTS covariances of the same linear-Gaussian model (:func:`.model.vector_check`; errata
    E1-E3).

    Parameters
    ----------
    params : dict
        The ``onebit`` configuration's ``vector_check``: ``A, Q, C, R, P0`` (nested lists) and
        ``horizon`` (number of steps).
    inputs : dict
        Only the step's code (no table is read).
    outputs : dict
        ``table``: ``results/onebit/vector_check.csv``.

    Returns
    -------
    dict
        ``{"table": DataFrame}``: columns ``quantity, form, max_rel_err`` (largest relative
        Frobenius error of the inverse BIM over all steps).
    """
    res = vector_check(params["vector_check"])
    frame = pd.DataFrame([dict(quantity=q, form=f, max_rel_err=v) for (q, f), v in res.items()])
    return {"table": frame}

