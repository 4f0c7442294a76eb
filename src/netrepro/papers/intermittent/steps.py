"""Pipeline steps of `intermittent`: read inputs, call the model and the engines, return tables.

Tables
------
``results/intermittent/exact_mean.csv``: ``lam, k, mean_exact, rel_error_bound, mean_enumeration,
enumeration_rel_diff`` (exact at every k; enumeration for k <= exact_horizon as a validation).
``results/intermittent/stationary_mean.csv``: ``lam, lam_label, loss_growth, stationary_mean, stationary_lo,
stationary_hi, bracket_rel_width, method, s_limit, r_limit, report_estimate_limit, n_iter``.
``results/intermittent/monte_carlo.csv``: ``lam, k, cond_mean, cond_lo, cond_hi, plain_mean, plain_lo,
plain_hi, plain_max, n_paths, exact_mean, cond_se, cond_z, plain_se, plain_z``.
``results/intermittent/scalar_bounds.csv``: ``lam, k, s, r, report_estimate, mean, mean_lo, mean_hi,
mean_method`` (mean exact at every k, lo = hi = mean) plus ``mean_rel_error_bound, lam_label,
report_estimate_printed, plain_mean, plain_lo, plain_hi, cond_mean, cond_z``.
``results/intermittent/two_sensor_region.csv``: ``lambda1, lambda2c_lower, lambda2c_upper`` plus
``bracket_lower, certified, upper_certified_by, lower_certified_by, upper_slack, n_solves, n_undecided,
status_at_threshold, statuses_seen`` (both bracket ends certified: see two_sensor.two_sensor_upper_bound).
``results/intermittent/stationary_curve.csv``: ``lam, stationary_mean, stationary_lo, stationary_hi, s_limit,
r_limit, tail_index, variance_finite, report_setting`` (lambda in (lambda_c, 1], with 1 - 1/a^4 and the report's
stable lambdas as grid points).
``results/intermittent/heavy_tail.csv``: ``lam, lam_label, tail_index, mean_finite, variance_finite, k, mean,
mean_exact, std``, per level ``q`` the two ends ``q<q>_lo, q<q>_hi`` of the quantile interval, ``flat_levels``,
``p_above_mean, p_above_mean_err, p_max, stationary_mean`` (law of p_k by enumeration). Quantile convention
(tails.quantile_interval): ``q<q>_lo = min{v : P(p_k <= v) >= q}``, ``q<q>_hi = inf{v : P(p_k <= v) > q}``; every
value in between is a q-quantile, and the two differ where the distribution function is flat at q (``flat_levels``
lists those levels: at lambda = 0.9, P(p_k <= v) = 0.9 on a whole stretch). ``p_above_mean`` = P(p_k > E p_k),
summed over the 2^k arrival sequences, with its rounding bound ``p_above_mean_err``.
``results/intermittent/region_closed_form.csv``: ``lambda1, lambda2c_lower`` on a dense grid with the kink.
``results/intermittent/two_sensor_simulation.csv``: ``lambda1, lambda2, side, k, mean, mean_lo, mean_hi,
predicted_growth`` (mean exact) plus ``mean_method, mean_rel_error_bound, stationary_mean, mc_mean, mc_lo, mc_hi,
mc_z``.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from ...engines.channels import iid_arrivals
from ...engines.montecarlo import load_sums, merge_block_sums, run_blocks, run_monte_carlo, save_sums, shard_blocks
from ...engines.riccati import Sensor, covariance_paths
from ...errors import InputError
from ...pipeline.io import read_table
from .estimators import conditional_mean_paths
from .exact import exact_mean, stationary_mean
from .model import (critical_probability, exact_mean_enumeration, lower_bound_limit, lower_bound_sequence,
                    mare_fixed_point, report_estimate_sequence, upper_bound_sequence)
from .tails import exceedance_probability, moment_finite_threshold, quantile_interval, tail_index
from .two_sensor import two_sensor_lower_bound, two_sensor_upper_bound

__all__ = [
    "exact_mean_step",
    "stationary_mean_step",
    "monte_carlo_shard_step",
    "monte_carlo_merge_step",
    "scalar_bounds_step",
    "two_sensor_region_shard_step",
    "two_sensor_region_merge_step",
    "two_sensor_simulation_step",
    "stationary_curve_step",
    "heavy_tail_step",
    "region_closed_form_step",
]


def _lambdas(cfg):
    """(lambda, label) for each configured offset from lambda_c."""
    lam_c = critical_probability(cfg["a"])
    return [(lam_c + off, f"lambda_c{off:+g}") for off in cfg["lambda_offsets"]]


def exact_mean_step(params, inputs, outputs):
    """Step: exact E(p_k) at every k <= horizon (exact.exact_mean), validated against enumeration for k <= exact_horizon.

    E(p_k) of the scalar recursion (6) at each configured lambda; the enumeration of all 2^k
    arrival sequences (model.exact_mean_enumeration) is an independent check.

    Parameters
    ----------
    params : dict
        The scalar system's ``a``, ``R1``, ``R2``, ``Ep0`` (E p_0) and ``lambda_offsets`` (lambda = lambda_c + offset),
        ``horizon`` and ``exact_horizon`` (last k of the enumeration).
    inputs : dict
        Only the step's code (no table is read).
    outputs : dict
        ``table`` (``results/intermittent/exact_mean.csv``).

    Returns
    -------
    dict
        ``{"table": DataFrame, "provenance": {"max_rel_diff_vs_enumeration": float}}``: per lambda
        and k, ``mean_exact``, its rigorous ``rel_error_bound``, ``mean_enumeration`` (NaN beyond
        ``exact_horizon``) and their relative difference.
    """
    frames = []
    worst = 0.0
    for lam, _ in _lambdas(params):
        a, R1, R2, p0 = params["a"], params["R1"], params["R2"], params["Ep0"]
        res = exact_mean(p0, a, R1, [R2], [lam], params["horizon"])
        enum = exact_mean_enumeration(p0, a, R1, R2, lam, params["exact_horizon"])
        k = np.arange(params["horizon"] + 1)
        enumerated = np.full(len(k), np.nan)
        enumerated[:len(enum)] = enum
        rel = np.abs(res.mean / enumerated - 1.0)
        worst = max(worst, float(np.nanmax(rel)))
        frames.append(pd.DataFrame({"lam": lam, "k": k, "mean_exact": res.mean,
                                    "rel_error_bound": res.rel_error_bound, "mean_enumeration": enumerated,
                                    "enumeration_rel_diff": rel}))
    return {"table": pd.concat(frames, ignore_index=True),
            "provenance": {"max_rel_diff_vs_enumeration": worst}}


def stationary_mean_step(params, inputs, outputs):
    """Step: lim E(p_k) for each lambda (exact bracket where (1 - lambda) a^2 < 1), next to the limits of s_k, r_k and
    the report's estimate.

    Where (1 - lambda) a^2 >= 1 the lower bound (10) diverges, so E(p_k) does too: the row holds
    ``inf``. The report's estimate is taken at k = 2000.

    Parameters
    ----------
    params : dict
        The scalar system's ``a``, ``R1``, ``R2``, ``Ep0`` (E p_0) and ``lambda_offsets`` (lambda = lambda_c + offset).
    inputs : dict
        Only the step's code (no table is read).
    outputs : dict
        ``table`` (``results/intermittent/stationary_mean.csv``).

    Returns
    -------
    dict
        ``{"table": DataFrame}``, one row per lambda: ``loss_growth`` (1 - lambda) a^2, the stationary
        mean with its bracket, the limits of (10) and (9), the report estimate's limit and the
        number of backward iterations.
    """
    a, R1, R2, p0 = params["a"], params["R1"], params["R2"], params["Ep0"]
    rows = []
    for lam, label in _lambdas(params):
        growth = (1.0 - lam) * a * a
        s = lower_bound_sequence(p0, a, R1, lam, 2000)
        r = upper_bound_sequence(p0, a, R1, R2, lam, 2000)
        est = report_estimate_sequence(p0, s, r, a, R1, R2, lam)
        row = {"lam": lam, "lam_label": label, "loss_growth": growth}
        if growth < 1.0:
            st = stationary_mean(a, R1, [R2], [lam], p0=p0)
            row.update({"stationary_mean": st["mean"], "stationary_lo": st["lo"], "stationary_hi": st["hi"],
                        "bracket_rel_width": (st["hi"] - st["lo"]) / st["mean"],
                        "method": "exact (Chebyshev backward recursion, rigorous bracket)",
                        "s_limit": lower_bound_limit(a, R1, lam), "r_limit": mare_fixed_point(a, R1, R2, lam),
                        "report_estimate_limit": est[-1], "n_iter": st["n_iter"]})
        else:
            row.update({"stationary_mean": np.inf, "stationary_lo": np.inf, "stationary_hi": np.inf,
                        "bracket_rel_width": np.nan,
                        "method": "unbounded: E(p_k) >= s_k and (1 - lambda) a^2 >= 1",
                        "s_limit": np.inf, "r_limit": np.inf, "report_estimate_limit": np.inf, "n_iter": 0})
        rows.append(row)
    return {"table": pd.DataFrame(rows)}


def _scalar_simulator(params, lam):
    a, R1, R2, p0, T = params["a"], params["R1"], params["R2"], params["Ep0"], params["horizon"]
    sensors = [Sensor([[1.0]], [[R2]])]

    def simulate(rng, n):
        arrivals = iid_arrivals(rng, n, T, lam)
        paths = covariance_paths(p0, [[a]], [[R1]], sensors, arrivals)
        cond = conditional_mean_paths(paths, p0, a, R1, [R2], [lam])
        return {"plain": paths, "cond": cond}

    return simulate


def monte_carlo_shard_step(params, inputs, outputs):
    """Step: block sums of one Monte Carlo shard (both lambdas); merged by :func:`monte_carlo_merge_step`.

    Parameters
    ----------
    params : dict
        The scalar system's ``a``, ``R1``, ``R2``, ``Ep0`` (E p_0) and ``lambda_offsets`` (lambda = lambda_c + offset),
        ``horizon``, ``n_paths``, ``block_size``, ``seed`` (lambda i uses ``seed + i``), and this
        shard's index ``shard`` of ``n_shards``.
    inputs : dict
        Only the step's code (no table is read).
    outputs : dict
        ``sums``: the ``.npz`` file of block sums, one entry ``lam<i>`` per lambda.

    Returns
    -------
    dict
        ``{"provenance": {"blocks": [...]}}``: the block indices of this shard (no table).
    """
    blocks = shard_blocks(params["n_paths"], params["block_size"], params["n_shards"], params["shard"])
    named = {}
    for i, (lam, _) in enumerate(_lambdas(params)):
        named[f"lam{i}"] = run_blocks(_scalar_simulator(params, lam), params["n_paths"], params["block_size"],
                                      params["seed"] + i, blocks=blocks)
    save_sums(outputs["sums"], named)
    return {"provenance": {"blocks": [int(b) for b in blocks]}}


def monte_carlo_merge_step(params, inputs, outputs):
    """Step: merge the shards into the plain and conditional Monte Carlo estimates of E(p_k), with z-scores.

    The shards are merged in block order, so any shard count gives identical results; the
    estimates get 95% bands, and their z-scores against the exact E(p_k) cross-check the estimators.

    Parameters
    ----------
    params : dict
        The scalar system's ``a``, ``R1``, ``R2``, ``Ep0`` (E p_0) and ``lambda_offsets`` (lambda = lambda_c + offset)
        and ``horizon`` (the other Monte Carlo keys are those of the shards).
    inputs : dict
        ``shards`` (the ``.npz`` block sums of :func:`monte_carlo_shard_step`) and ``exact``
        (``results/intermittent/exact_mean.csv``).
    outputs : dict
        ``table`` (``results/intermittent/monte_carlo.csv``).

    Returns
    -------
    dict
        ``{"table": DataFrame}``: per lambda and k the conditional and plain means with 95% bands,
        the largest plain sample, the number of paths, the exact mean, standard errors and z-scores
        (0 where the standard error is 0).
    """
    shards = [load_sums(path) for path in inputs["shards"]]
    exact = read_table(inputs["exact"])
    frames = []
    for i, (lam, _) in enumerate(_lambdas(params)):
        # a shard holds no block when there are more shards than blocks: merge_block_sums leaves it out
        mc = merge_block_sums(shard[f"lam{i}"] for shard in shards)
        cm, clo, chi = mc.ci("cond")
        pm, plo, phi = mc.ci("plain")
        k = np.arange(params["horizon"] + 1)
        ex = exact[np.isclose(exact["lam"], lam)].set_index("k")["mean_exact"].reindex(k).to_numpy()
        cse = mc.std("cond") / np.sqrt(mc.n)
        pse = mc.std("plain") / np.sqrt(mc.n)
        with np.errstate(divide="ignore", invalid="ignore"):
            cz = np.where(cse > 0, (cm - ex) / cse, 0.0)
            pz = np.where(pse > 0, (pm - ex) / pse, 0.0)
        frames.append(pd.DataFrame({
            "lam": lam, "k": k, "cond_mean": cm, "cond_lo": clo, "cond_hi": chi,
            "plain_mean": pm, "plain_lo": plo, "plain_hi": phi, "plain_max": mc.maximum("plain"), "n_paths": mc.n,
            "exact_mean": ex, "cond_se": cse, "cond_z": cz, "plain_se": pse, "plain_z": pz,
        }))
    return {"table": pd.concat(frames, ignore_index=True)}


def scalar_bounds_step(params, inputs, outputs):
    """Step: the Figs 1-2 table (bounds, report estimate, exact E(p_k) at every k, the Monte Carlo cross-check).

    Parameters
    ----------
    params : dict
        The scalar system's ``a``, ``R1``, ``R2``, ``Ep0`` (E p_0) and ``lambda_offsets`` (lambda = lambda_c + offset)
        and ``horizon``.
    inputs : dict
        ``exact`` (``results/intermittent/exact_mean.csv``) and ``mc`` (``results/intermittent/monte_carlo.csv``).
    outputs : dict
        ``table`` (``results/intermittent/scalar_bounds.csv``).

    Returns
    -------
    dict
        ``{"table": DataFrame}``: per lambda and k, the lower bound s_k (10), the upper bound r_k (9),
        the report's estimate (as corrected and as printed), the exact mean (``mean_lo = mean_hi =
        mean``) with its error bound, and the Monte Carlo columns.
    """
    exact = read_table(inputs["exact"])
    mc = read_table(inputs["mc"])
    a, R1, R2, p0, T = params["a"], params["R1"], params["R2"], params["Ep0"], params["horizon"]
    frames = []
    for lam, label in _lambdas(params):
        s = lower_bound_sequence(p0, a, R1, lam, T)
        r = upper_bound_sequence(p0, a, R1, R2, lam, T)
        est = report_estimate_sequence(p0, s, r, a, R1, R2, lam)
        est_printed = report_estimate_sequence(p0, s, r, a, R1, R2, lam, printed=True)
        ex = exact[np.isclose(exact["lam"], lam)].set_index("k")
        m = mc[np.isclose(mc["lam"], lam)].set_index("k")
        k = np.arange(T + 1)
        mean = ex["mean_exact"].reindex(k).to_numpy()
        frames.append(pd.DataFrame({
            "lam": lam, "k": k, "s": s, "r": r, "report_estimate": est, "mean": mean, "mean_lo": mean,
            "mean_hi": mean, "mean_method": "exact", "mean_rel_error_bound": ex["rel_error_bound"].reindex(k).to_numpy(),
            "lam_label": label, "report_estimate_printed": est_printed,
            "plain_mean": m["plain_mean"].reindex(k).to_numpy(), "plain_lo": m["plain_lo"].reindex(k).to_numpy(),
            "plain_hi": m["plain_hi"].reindex(k).to_numpy(),
            "cond_mean": m["cond_mean"].reindex(k).to_numpy(), "cond_z": m["cond_z"].reindex(k).to_numpy(),
        }))
    return {"table": pd.concat(frames, ignore_index=True)}


def two_sensor_region_shard_step(params, inputs, outputs):
    """Step: lower bound (closed form) and LMI upper bound (bisection) on one shard of the lambda1 grid.

    The shard takes every ``n_shards``-th point of the grid, starting at ``shard``, so that shards
    near and far from lambda1 = 0 get balanced work.

    Parameters
    ----------
    params : dict
        ``a``, ``lambda1_grid`` (number of points on [0, 1]), ``bisection_tol``, ``shard`` and ``n_shards``.
    inputs : dict
        Only the step's code (no table is read).
    outputs : dict
        ``table`` (``results/intermittent/shards/two_sensor_region_<shard>.csv``).

    Returns
    -------
    dict
        ``{"table": DataFrame, "provenance": {"lmi_solves": int}}``: the columns of
        :func:`two_sensor.two_sensor_upper_bound` with ``lambda2c_lower`` inserted second.
    """
    # every n-th grid point, so that shards near and far from lambda1 = 0 get balanced work
    grid = np.linspace(0.0, 1.0, params["lambda1_grid"])[params["shard"]::params["n_shards"]]
    upper = pd.DataFrame(two_sensor_upper_bound(grid, params["a"], params["bisection_tol"]))
    upper.insert(1, "lambda2c_lower", two_sensor_lower_bound(grid, params["a"]))
    return {"table": upper, "provenance": {"lmi_solves": int(upper["n_solves"].sum())}}


def two_sensor_region_merge_step(params, inputs, outputs):
    """Step: the Figs 4-5 table, concatenating the lambda1 shards.

    Parameters
    ----------
    params : dict
        ``lambda1_grid``: the number of grid points the shards must cover.
    inputs : dict
        ``shards``: the tables of :func:`two_sensor_region_shard_step`.
    outputs : dict
        ``table`` (``results/intermittent/two_sensor_region.csv``).

    Returns
    -------
    dict
        ``{"table": DataFrame, "provenance": {"total_lmi_solves": int}}``, rows sorted by lambda1.

    Raises
    ------
    InputError
        If the shards do not cover the grid exactly once.
    """
    table = pd.concat([read_table(p) for p in inputs["shards"]], ignore_index=True).sort_values("lambda1",
                                                                                                  kind="stable")
    expected = np.linspace(0.0, 1.0, params["lambda1_grid"])
    if len(table) != len(expected) or not np.allclose(table["lambda1"].to_numpy(), expected, rtol=0, atol=1e-12):
        raise InputError(f"the {len(inputs['shards'])} lambda1 shards do not cover the grid of {len(expected)} points "
                         "exactly once; rebuild the shards (snakemake --forcerun intermittent_two_sensor_region_shard)")
    return {"table": table.reset_index(drop=True), "provenance": {"total_lmi_solves": int(table["n_solves"].sum())}}


def two_sensor_simulation_step(params, inputs, outputs):
    """Step: E(p_k) of the two-sensor recursion (14) on both sides of the boundary at lambda1 = check_lambda1.

    Exact (exact.exact_mean) with the conditional Monte Carlo as a cross-check (z-scores), at
    lambda2 = lower boundary -/+ ``check_offset`` (clipped to [0, 1]), from p_0 = 1.

    Parameters
    ----------
    params : dict
        ``a``, ``R1``, ``sigma2`` (the two sensors' noise variances), ``check_lambda1``,
        ``check_offset``, ``check_horizon``, ``check_paths``, ``block_size`` and ``seed`` (side i uses ``seed + i``).
    inputs : dict
        Only the step's code (no table is read).
    outputs : dict
        ``table`` (``results/intermittent/two_sensor_simulation.csv``).

    Returns
    -------
    dict
        ``{"table": DataFrame}``: per side and k the exact mean and its error bound, the predicted
        growth (1 - lambda1)(1 - lambda2) a^2, the stationary mean (``inf`` where the growth is >= 1)
        and the Monte Carlo mean, band and z-score.
    """
    a, R1 = params["a"], params["R1"]
    var1, var2 = params["sigma2"]
    lam1 = params["check_lambda1"]
    boundary = float(two_sensor_lower_bound(lam1, a))
    sensors = [Sensor([[1.0]], [[var1]]), Sensor([[1.0]], [[var2]])]
    T = params["check_horizon"]
    frames = []
    for i, (side, lam2) in enumerate((("stable", boundary + params["check_offset"]),
                                      ("unstable", boundary - params["check_offset"]))):
        lam2 = float(np.clip(lam2, 0.0, 1.0))

        def simulate(rng, n, lam2=lam2):
            arrivals = iid_arrivals(rng, n, T, [lam1, lam2])
            paths = covariance_paths(1.0, [[a]], [[R1]], sensors, arrivals)
            return {"cond": conditional_mean_paths(paths, 1.0, a, R1, [var1, var2], [lam1, lam2])}

        mc = run_monte_carlo(simulate, params["check_paths"], params["block_size"], params["seed"] + i)
        mc_mean, mc_lo, mc_hi = mc.ci("cond")
        mc_se = mc.std("cond") / np.sqrt(mc.n)
        ex = exact_mean(1.0, a, R1, [var1, var2], [lam1, lam2], T)
        growth = (1 - lam1) * (1 - lam2) * a * a
        stationary = stationary_mean(a, R1, [var1, var2], [lam1, lam2], p0=1.0)["mean"] if growth < 1 else np.inf
        with np.errstate(divide="ignore", invalid="ignore"):
            z = np.where(mc_se > 0, (mc_mean - ex.mean) / mc_se, 0.0)
        frames.append(pd.DataFrame({
            "lambda1": lam1, "lambda2": lam2, "side": side, "k": np.arange(T + 1), "mean": ex.mean,
            "mean_lo": ex.mean, "mean_hi": ex.mean, "predicted_growth": growth, "mean_method": "exact",
            "mean_rel_error_bound": ex.rel_error_bound, "stationary_mean": stationary,
            "mc_mean": mc_mean, "mc_lo": mc_lo, "mc_hi": mc_hi, "mc_z": z,
        }))
    return {"table": pd.concat(frames, ignore_index=True)}


def stationary_curve_step(params, inputs, outputs):
    """Step: the exact E(p_inf)(lambda) next to s*(lambda) and r*(lambda) for lambda in (lambda_c, 1], with the
    tail index of p_inf and whether its variance is finite (tails.tail_index, tails.moment_finite_threshold).

    Parameters
    ----------
    params : dict
        The scalar system's ``a``, ``R1``, ``R2`` and ``lambda_offsets`` with the ``stationary_curve``
        section: ``n_lambda`` grid points, geometric from ``first_fraction`` of (1 - lambda_c) above
        lambda_c up to 1 (the variance threshold and the report's settings added).
    inputs : dict
        Only the step's code (no table is read).
    outputs : dict
        ``table`` (``results/intermittent/stationary_curve.csv``).

    Returns
    -------
    dict
        ``{"table": DataFrame}``, one row per lambda: the stationary mean and its bounds, s*, r*,
        the tail index, whether the variance is finite, and whether it is a report setting.

    Raises
    ------
    InputError
        If ``first_fraction`` is not in (0, 1).
    """
    a, R1, R2 = params["a"], params["R1"], params["R2"]
    lam_c = critical_probability(a)
    n, first = params["n_lambda"], params["first_fraction"]
    if not 0.0 < first < 1.0:
        raise InputError(f"stationary_curve.first_fraction = {first} must lie in (0, 1)")
    offsets = np.geomspace(first * (1.0 - lam_c), 1.0 - lam_c, n)
    lams = lam_c + offsets
    lams[-1] = 1.0
    var_from = moment_finite_threshold(2, a)
    report = [lam_c + off for off in params.get("lambda_offsets", []) if off > 0]
    # the variance threshold and the report's stable settings are grid points exactly
    lams = np.union1d(lams, [var_from, *report])
    rows = []
    for lam in lams:
        st = stationary_mean(a, R1, [R2], [lam], p0=R2)
        rows.append({"lam": lam, "stationary_mean": st["mean"], "stationary_lo": st["lo"], "stationary_hi": st["hi"],
                     "s_limit": lower_bound_limit(a, R1, lam), "r_limit": mare_fixed_point(a, R1, R2, lam),
                     "tail_index": tail_index(lam, a), "variance_finite": bool(lam > var_from),
                     "report_setting": bool(np.any(np.isclose(lam, report, rtol=0, atol=1e-15)))})
    return {"table": pd.DataFrame(rows)}


def heavy_tail_step(params, inputs, outputs):
    """Step: the law of p_k at k = horizon by enumeration of all 2^k arrival sequences (model.exact_mean_enumeration):
    the quantile intervals (tails.quantile_interval), P(p_k > E p_k) (tails.exceedance_probability), mean and
    standard deviation, beside the tail index of the stationary law; at the report's lambdas (lambda_c + the scalar
    offsets) and at the extra ``lambdas``.

    Each enumerated weight is a product of k rounded factors lambda or 1 - lambda (relative error gamma_{k+1},
    1 - lambda counted as one more rounding); E p_k is the exact mean of exact.exact_mean with its rigorous relative
    error bound.

    Parameters
    ----------
    params : dict
        The scalar system's ``a``, ``R1``, ``R2``, ``Ep0`` and ``lambda_offsets`` with the
        ``heavy_tail`` section (``horizon``, ``quantiles``, optional ``lambdas``).
    inputs : dict
        Only the step's code (no table is read).
    outputs : dict
        ``table`` (``results/intermittent/heavy_tail.csv``).

    Returns
    -------
    dict
        ``{"table": DataFrame}``, one row per lambda: tail index, whether the mean and the variance
        are finite, the mean (by enumeration and exact), the standard deviation, the quantile intervals
        ``q<prob>_lo, q<prob>_hi`` and the levels where they differ, P(p_k > E p_k) with its error bound,
        the largest p_k and the stationary mean.
    """
    a, R1, R2, p0, k = params["a"], params["R1"], params["R2"], params["Ep0"], params["horizon"]
    lam_c = critical_probability(a)
    probs = [float(q) for q in params["quantiles"]]
    u = np.finfo(float).eps / 2
    weight_rtol = (k + 1) * u / (1 - (k + 1) * u)
    rows = []
    cases = [(lam_c + off, f"lambda_c{off:+g}") for off in params["lambda_offsets"]]
    cases += [(float(x), f"lambda={x:g}") for x in params.get("lambdas", [])]
    for lam, label in cases:
        _, vals, w = exact_mean_enumeration(p0, a, R1, R2, lam, k, return_distribution=True)
        mean = float(w @ vals)
        exact = exact_mean(p0, a, R1, [R2], [lam], k)
        mean_exact = float(exact.mean[-1])
        row = {"lam": lam, "lam_label": label, "tail_index": tail_index(lam, a),
               "mean_finite": bool(lam > lam_c), "variance_finite": bool(lam > moment_finite_threshold(2, a)), "k": k,
               "mean": mean, "mean_exact": mean_exact, "std": float(np.sqrt(max(w @ (vals - mean) ** 2, 0.0)))}
        lo, hi = quantile_interval(vals, w, probs, weight_rtol)
        for q, x, y in zip(probs, lo, hi):
            row.update({f"q{q:g}_lo": x, f"q{q:g}_hi": y})
        row["flat_levels"] = "|".join(f"{q:g}" for q, x, y in zip(probs, lo, hi) if x < y)
        row["p_above_mean"], row["p_above_mean_err"] = exceedance_probability(
            vals, w, mean_exact, float(exact.rel_error_bound[-1]), weight_rtol)
        row["p_max"] = float(vals.max())
        row["stationary_mean"] = stationary_mean(a, R1, [R2], [lam], p0=p0)["mean"] if lam > lam_c else np.inf
        rows.append(row)
    return {"table": pd.DataFrame(rows)}


def region_closed_form_step(params, inputs, outputs):
    """Step: the closed-form lower bound of the two-sensor region (two_sensor.two_sensor_lower_bound) on a dense
    lambda_1 grid with its kink lambda_1 = 1 - 1/a^2 inserted exactly (Fig. 4).

    Parameters
    ----------
    params : dict
        The ``two_sensor`` section's ``a`` (the system's pole) and ``n_dense`` (grid points on [0, 1]).
    inputs : dict
        Only the step's code (no table is read).
    outputs : dict
        ``table`` (``results/intermittent/region_closed_form.csv``).

    Returns
    -------
    dict
        ``{"table": DataFrame}`` with columns ``lambda1`` and ``lambda2c_lower``.
    """
    a = params["a"]
    grid = np.union1d(np.linspace(0.0, 1.0, params["n_dense"]), [critical_probability(a)])
    return {"table": pd.DataFrame({"lambda1": grid, "lambda2c_lower": two_sensor_lower_bound(grid, a)})}
