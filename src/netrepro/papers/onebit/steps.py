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
    ``one_minus_alpha, sigma_z2, j_f_inf, j_f_q, j_s_inf, j_s_q`` -- steady-state
    fixed points; ``alpha = 1.0`` rows are the alpha -> 1 limit
    (``one_minus_alpha = 0``, BIM columns empty).
``lag.csv``
    ``alpha, snr_db, delta_needed`` then ``delta_q, delta_inf, delta_q_iterated,
    delta_inf_iterated, tol_db, delta_scaled`` -- smallest smoothing lag at which
    both the 1-bit and the unquantized smoothing BIM are within ``tol_db`` of
    their Delta -> infinity values (closed form of the Moebius iteration,
    checked by iterating (27)/(37)-(38)); ``delta_scaled = delta_q *
    sqrt(E[F_q] sigma_z^2)`` tends to a constant as alpha -> 1.
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
    Monte Carlo block sums of shard ``i`` (merged in block order).
``estimator_mse.csv``
    ``alpha, snr_db, kind, mse, mse_lo, mse_hi, bound`` then ``bound_steady,
    mse_over_bound, n_runs`` -- ``kind`` in ``filter_1bit, smoother_1bit,
    kalman_filter, rts_smoother``; grid filter/smoother on 1-bit data and
    Kalman/RTS on unquantized data, 95 % confidence intervals over runs,
    ``bound`` = BCRB averaged over the evaluation window.
``vector_check.csv``
    ``quantity, form, max_rel_err`` -- general vector recursions on a 2-D
    non-symmetric model against the Kalman filter / RTS smoother.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from .estimators import grid_filter_smoother, kalman_rts, simulate_block
from .fisher import expected_fisher_1bit, expected_fisher_1bit_quad
from .model import sigma_z2_from_snr, snr_grid, stationary_variance, vector_check
from .randomwalk import (
    information_ratios,
    information_ratios_limit,
    iterate_transient,
    rw_filtering_fixed_point,
    rw_lag_iterated,
    rw_lag_needed,
    rw_smoothing_gain_fixed_point,
    rw_smoothing_gain_step,
    window_bounds,
)

__all__ = [
    "efq_step",
    "ratios_step",
    "lag_step",
    "convergence_step",
    "estimator_shard_step",
    "estimator_step",
    "run_estimator",
    "vector_check_step",
]


def _db(x):
    return 10.0 * np.log10(x)


def efq_step(params, inputs, outputs):
    """Table ``efq.csv``: (29) on a fine SNR grid by the trapezoid form and by adaptive quadrature."""
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
    """Table ``ratios.csv``: steady-state (47)-(49) for each alpha and the alpha -> 1 limit."""
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
            j_s_inf=np.nan, j_s_q=np.nan)))
    return {"table": pd.concat(frames, ignore_index=True)}


def lag_step(params, inputs, outputs):
    """Table ``lag.csv``: the smoothing lag Delta each SNR needs (closed form, checked by iteration)."""
    snr_db = snr_grid(**params["snr_grid_db"])
    tol = params["lag_tol_db"]
    se = params["sigma_eta"]
    frames = []
    for eps in params["one_minus_alpha"]:
        s = sigma_z2_from_snr(snr_db, eps, se, params["snr_definition"])
        Fq = expected_fisher_1bit(stationary_variance(eps, s) / se**2) / se**2
        Fi = np.full_like(s, 1.0 / se**2)
        dq, di = rw_lag_needed(Fq, eps, s, tol), rw_lag_needed(Fi, eps, s, tol)
        if max(dq.max(), di.max()) <= params["lag_iterate_max"]:
            dq_it, di_it = rw_lag_iterated(Fq, eps, s, tol), rw_lag_iterated(Fi, eps, s, tol)
        else:
            dq_it = di_it = np.full(len(s), -1)
        frames.append(pd.DataFrame(dict(alpha=1.0 - eps, snr_db=snr_db, delta_needed=np.maximum(dq, di),
                                        delta_q=dq, delta_inf=di, delta_q_iterated=dq_it, delta_inf_iterated=di_it,
                                        tol_db=tol, delta_scaled=dq * np.sqrt(Fq * s))))
    return {"table": pd.concat(frames, ignore_index=True)}


def convergence_step(params, inputs, outputs):
    """Tables ``convergence.csv`` and ``transient.csv``: fixed points against long iterations."""
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
        kq, ki = np.zeros_like(s), np.zeros_like(s)
        last_q = np.zeros(len(s), dtype=np.int64)
        last_i = np.zeros(len(s), dtype=np.int64)
        kq_star = rw_smoothing_gain_fixed_point(Fq, eps, s)
        ki_star = rw_smoothing_gain_fixed_point(Fi, eps, s)
        for d in range(1, c["n_lag_steps"][params["one_minus_alpha"].index(eps)] + 1):
            kq = rw_smoothing_gain_step(kq, Fq, eps, s)
            ki = rw_smoothing_gain_step(ki, Fi, eps, s)
            last_q[np.abs(kq / kq_star - 1) > c["rtol"]] = d
            last_i[np.abs(ki / ki_star - 1) > c["rtol"]] = d
        n_lag = c["n_lag_steps"][params["one_minus_alpha"].index(eps)]
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


def _estimator_simulator(params, j):
    """``fn(rng, n)`` for the Monte Carlo engine: per-run window-mean squared errors of the four estimators."""
    est = params["estimator"]
    eps, se = est["one_minus_alpha"], params["sigma_eta"]
    K, (w0, w1) = est["horizon"], est["window"]
    s = float(sigma_z2_from_snr(est["snr_db"][j], eps, se, params["snr_definition"]))

    def fn(rng, n):
        theta, y, r = simulate_block(rng, n, K, eps, s, se)
        filt, smooth = grid_filter_smoother(r, eps, s, se, est["grid_half_width"], est["points_per_sigma_z"])
        kf, rts = kalman_rts(y, eps, s, se)
        w = slice(w0, w1)

        def mse(x):
            return np.mean((x[:, w] - theta[:, w]) ** 2, axis=1)

        return {"filter_1bit": mse(filt), "smoother_1bit": mse(smooth), "kalman_filter": mse(kf),
                "rts_smoother": mse(rts)}

    return fn


def estimator_shard_step(params, inputs, outputs):
    """Step: Monte Carlo block sums of one shard (all SNRs; SNR ``j`` uses root seed ``seed + j``)."""
    from ...engines.montecarlo import run_blocks, save_sums, shard_blocks

    est = params["estimator"]
    blocks = shard_blocks(est["n_runs"], est["block_size"], params["n_shards"], params["shard"])
    named = {f"snr{j}": run_blocks(_estimator_simulator(params, j), est["n_runs"], est["block_size"],
                                   est["seed"] + j, blocks=blocks) for j in range(len(est["snr_db"]))}
    save_sums(outputs["sums"], named)
    return {"provenance": {"blocks": [int(b) for b in blocks], "seed": est["seed"]}}


def estimator_step(params, inputs, outputs):
    """Step: table ``estimator_mse.csv`` -- merged shards (block order) next to the bounds.

    ``bound`` is the BCRB (34)/(36) (1-bit) or (24)/(26) (unquantized) for the
    simulated horizon, started from the stationary prior, averaged over the
    evaluation window; ``bound_steady`` is the steady-state fixed point.
    """
    from ...engines.montecarlo import load_sums, merge_block_sums

    est = params["estimator"]
    eps, se = est["one_minus_alpha"], params["sigma_eta"]
    K, (w0, w1) = est["horizon"], est["window"]
    shards = [load_sums(path) for path in inputs["shards"]]
    rows = []
    for j, snr in enumerate(est["snr_db"]):
        mc = merge_block_sums(shard[f"snr{j}"] for shard in shards)
        s = float(sigma_z2_from_snr(snr, eps, se, params["snr_definition"]))
        var_inf = float(stationary_variance(eps, s))
        Fq = float(expected_fisher_1bit(var_inf / se**2)) / se**2
        bounds, steady = {}, {}
        for label, F in (("1bit", Fq), ("unq", 1.0 / se**2)):
            bf, bs = window_bounds(F, eps, s, var_inf, K, (w0, w1))
            jf = float(rw_filtering_fixed_point(F, eps, s))
            kap = float(rw_smoothing_gain_fixed_point(F, eps, s))
            kf, ks = ("filter_1bit", "smoother_1bit") if label == "1bit" else ("kalman_filter", "rts_smoother")
            bounds[kf], bounds[ks] = bf, bs
            steady[kf], steady[ks] = 1.0 / jf, 1.0 / (jf + kap)
        for kind in ("filter_1bit", "smoother_1bit", "kalman_filter", "rts_smoother"):
            m, lo, hi = mc.ci(kind)
            rows.append(dict(alpha=1.0 - eps, snr_db=float(snr), kind=kind, mse=float(m), mse_lo=float(lo),
                             mse_hi=float(hi), bound=bounds[kind], bound_steady=steady[kind],
                             mse_over_bound=float(m) / bounds[kind], n_runs=mc.n))
    return {"table": pd.DataFrame(rows)}


def run_estimator(params):
    """Shard and merge in one process (tests, notebooks): the same table as the two pipeline steps."""
    import tempfile
    from pathlib import Path

    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "sums.npz"
        estimator_shard_step(dict(params, shard=0, n_shards=1), {}, {"sums": path})
        return estimator_step(params, {"shards": [path]}, {})["table"]


def vector_check_step(params, inputs, outputs):
    """Table ``vector_check.csv``: the general recursions on a 2-D non-symmetric model vs Kalman/RTS."""
    res = vector_check(params["vector_check"])
    frame = pd.DataFrame([dict(quantity=q, form=f, max_rel_err=v) for (q, f), v in res.items()])
    return {"table": frame}

