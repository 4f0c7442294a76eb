"""Pipeline steps of `intermittent`: read inputs, call the model and the engines, return tables.

Tables
------
``results/intermittent/exact_mean.csv``: ``lam, k, mean_exact``.
``results/intermittent/monte_carlo.csv``: ``lam, k, cond_mean, cond_lo, cond_hi, plain_mean, plain_lo,
plain_hi, plain_max, n_paths``.
``results/intermittent/scalar_bounds.csv``: ``lam, k, s, r, report_estimate, mean, mean_lo, mean_hi,
mean_method`` plus ``lam_label, report_estimate_printed, plain_mean, plain_lo, plain_hi``.
``results/intermittent/two_sensor_region.csv``: ``lambda1, lambda2c_lower, lambda2c_upper`` plus
``bracket_lower, n_solves, status_at_threshold, certified_radius, statuses_seen``.
``results/intermittent/two_sensor_simulation.csv``: ``lambda1, lambda2, side, k, mean, mean_lo, mean_hi,
predicted_growth``.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from ...engines.channels import iid_arrivals
from ...engines.montecarlo import load_sums, merge_block_sums, run_blocks, run_monte_carlo, save_sums, shard_blocks
from ...engines.riccati import Sensor, covariance_paths
from ...errors import InputError
from ...io import read_table
from .estimators import conditional_mean_paths
from .model import (critical_probability, exact_mean_enumeration, lower_bound_sequence, report_estimate_sequence,
                    upper_bound_sequence)
from .two_sensor import two_sensor_lower_bound, two_sensor_upper_bound

__all__ = [
    "exact_mean_step",
    "monte_carlo_shard_step",
    "monte_carlo_merge_step",
    "scalar_bounds_step",
    "two_sensor_region_shard_step",
    "two_sensor_region_merge_step",
    "two_sensor_simulation_step",
]


def _lambdas(cfg):
    """(lambda, label) for each configured offset from lambda_c."""
    lam_c = critical_probability(cfg["a"])
    return [(lam_c + off, f"lambda_c{off:+g}") for off in cfg["lambda_offsets"]]


def exact_mean_step(params, inputs, outputs):
    """Step: exact E(p_k), k <= exact_horizon, for each lambda."""
    frames = []
    for lam, _ in _lambdas(params):
        means = exact_mean_enumeration(params["Ep0"], params["a"], params["R1"], params["R2"], lam,
                                       params["exact_horizon"])
        frames.append(pd.DataFrame({"lam": lam, "k": np.arange(len(means)), "mean_exact": means}))
    return {"table": pd.concat(frames, ignore_index=True)}


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
    """Step: block sums of one Monte Carlo shard (both lambdas); merged by :func:`monte_carlo_merge_step`."""
    blocks = shard_blocks(params["n_paths"], params["block_size"], params["n_shards"], params["shard"])
    named = {}
    for i, (lam, _) in enumerate(_lambdas(params)):
        named[f"lam{i}"] = run_blocks(_scalar_simulator(params, lam), params["n_paths"], params["block_size"],
                                      params["seed"] + i, blocks=blocks)
    save_sums(outputs["sums"], named)
    return {"provenance": {"blocks": [int(b) for b in blocks]}}


def monte_carlo_merge_step(params, inputs, outputs):
    """Step: merge the shards (in block order, so any shard count gives identical results) into the
    plain and conditional Monte Carlo estimates of E(p_k) with 95% bands."""
    shards = [load_sums(path) for path in inputs["shards"]]
    frames = []
    for i, (lam, _) in enumerate(_lambdas(params)):
        mc = merge_block_sums(shard[f"lam{i}"] for shard in shards)
        cm, clo, chi = mc.ci("cond")
        pm, plo, phi = mc.ci("plain")
        frames.append(pd.DataFrame({
            "lam": lam, "k": np.arange(params["horizon"] + 1), "cond_mean": cm, "cond_lo": clo, "cond_hi": chi,
            "plain_mean": pm, "plain_lo": plo, "plain_hi": phi, "plain_max": mc.maximum("plain"), "n_paths": mc.n,
        }))
    return {"table": pd.concat(frames, ignore_index=True)}


def scalar_bounds_step(params, inputs, outputs):
    """Step: the Figs 1-2 table (bounds, report estimate, true mean with its method)."""
    exact = read_table(inputs["exact"])
    mc = read_table(inputs["mc"])
    a, R1, R2, p0, T = params["a"], params["R1"], params["R2"], params["Ep0"], params["horizon"]
    frames = []
    for lam, label in _lambdas(params):
        s = lower_bound_sequence(p0, a, R1, lam, T)
        r = upper_bound_sequence(p0, a, R1, R2, lam, T)
        est = report_estimate_sequence(p0, s, r, a, R1, R2, lam)
        est_printed = report_estimate_sequence(p0, s, r, a, R1, R2, lam, printed=True)
        ex = exact[np.isclose(exact["lam"], lam)].set_index("k")["mean_exact"]
        m = mc[np.isclose(mc["lam"], lam)].set_index("k")
        k = np.arange(T + 1)
        use_exact = np.isin(k, ex.index)
        mean = np.where(use_exact, ex.reindex(k).to_numpy(), m["cond_mean"].reindex(k).to_numpy())
        lo = np.where(use_exact, mean, m["cond_lo"].reindex(k).to_numpy())
        hi = np.where(use_exact, mean, m["cond_hi"].reindex(k).to_numpy())
        frames.append(pd.DataFrame({
            "lam": lam, "k": k, "s": s, "r": r, "report_estimate": est, "mean": mean, "mean_lo": lo, "mean_hi": hi,
            "mean_method": np.where(use_exact, "exact enumeration", "conditional Monte Carlo"),
            "lam_label": label, "report_estimate_printed": est_printed,
            "plain_mean": m["plain_mean"].reindex(k).to_numpy(), "plain_lo": m["plain_lo"].reindex(k).to_numpy(),
            "plain_hi": m["plain_hi"].reindex(k).to_numpy(),
        }))
    return {"table": pd.concat(frames, ignore_index=True)}


def two_sensor_region_shard_step(params, inputs, outputs):
    """Step: lower bound (closed form) and LMI upper bound (bisection) on one shard of the lambda1 grid."""
    # every n-th grid point, so that shards near and far from lambda1 = 0 get balanced work
    grid = np.linspace(0.0, 1.0, params["lambda1_grid"])[params["shard"]::params["n_shards"]]
    upper = pd.DataFrame(two_sensor_upper_bound(grid, params["a"], params["bisection_tol"]))
    upper.insert(1, "lambda2c_lower", two_sensor_lower_bound(grid, params["a"]))
    return {"table": upper, "provenance": {"lmi_solves": int(upper["n_solves"].sum())}}


def two_sensor_region_merge_step(params, inputs, outputs):
    """Step: the Figs 4-5 table, concatenating the lambda1 shards."""
    table = pd.concat([read_table(p) for p in inputs["shards"]], ignore_index=True).sort_values("lambda1",
                                                                                                  kind="stable")
    expected = np.linspace(0.0, 1.0, params["lambda1_grid"])
    if len(table) != len(expected) or not np.allclose(table["lambda1"].to_numpy(), expected, rtol=0, atol=1e-12):
        raise InputError(f"the {len(inputs['shards'])} lambda1 shards do not cover the grid of {len(expected)} points "
                         "exactly once; rebuild the shards (snakemake --forcerun intermittent_two_sensor_region_shard)")
    return {"table": table.reset_index(drop=True), "provenance": {"total_lmi_solves": int(table["n_solves"].sum())}}


def two_sensor_simulation_step(params, inputs, outputs):
    """Step: E(p_k) with the two-sensor recursion (14) on both sides of the boundary at lambda1 = check_lambda1."""
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
        mean, lo, hi = mc.ci("cond")
        frames.append(pd.DataFrame({
            "lambda1": lam1, "lambda2": lam2, "side": side, "k": np.arange(T + 1), "mean": mean, "mean_lo": lo,
            "mean_hi": hi, "predicted_growth": (1 - lam1) * (1 - lam2) * a * a,
        }))
    return {"table": pd.concat(frames, ignore_index=True)}
