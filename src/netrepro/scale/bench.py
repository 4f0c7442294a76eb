"""Benchmarks of the project's hot paths, each against a simple reference measured in the same run.

``python -m netrepro bench --out results/benchmarks.csv [--quick]`` (``make bench``) writes one
table with the columns ``benchmark, metric, ours, reference, ratio, unit`` and a sidecar
``<out>.meta.json`` (machine, BLAS kernels, load, sizes, repeats, notes). Times are medians
over repeats; because ours and the reference run in the same process, one after the other,
the *ratio* is comparable across machines and loads even where the absolute numbers are not.

``ratio`` is always "how many times better ours is" (so >= 1 is good):

* rates (path-steps/s, points/s, solves/s): ``ours / reference``;
* times and counts (s, solves): ``reference / ours``;
* ``fraction_of_peak``: ``ours / reference`` with ``reference`` the machine's measured peak
  (so here the ratio is the achieved fraction, at most 1);
* pipeline targets: ``reference`` is the target of issue 9 and ``ratio = target / measured``
  (>= 1 means the target is met);
* agreement rows (``max_rel_diff``): ``reference`` is the tolerance, ``ratio = tol / diff``.

Benchmarks
----------
``riccati_{iid,ge}_n{1,2,3}``
    :func:`netrepro.engines.riccati.covariance_paths` (batched over paths) against a per-path
    Python loop, for i.i.d. and Gilbert-Elliott arrivals and state dimension 1 to 3; plus the
    flop count per path-step and the achieved fraction of the single-core peak, measured by a
    large matrix product in a child process with ``OPENBLAS_CORETYPE``/``OPENBLAS_L2_SIZE``
    unset (the native kernel; see ``/work/.library/env/README.md``).
``channel_ge``
    :func:`netrepro.engines.channels.gilbert_elliott_arrivals` against a per-path loop.
``lmi_sweep``
    :class:`netrepro.engines.lmi.MareStabilizabilityLMI` compiled once and solved across a sweep
    against rebuilding the cvxpy problem for every point.
``lmi_bisection``
    LMI solves per stability curve (the two-sensor region of the ``intermittent`` paper) against
    plain bisections: warm-started from the neighbours (:func:`netrepro.engines.lmi.sweep_thresholds`),
    and bracketed from each point's closed-form lower bound (what the pipeline runs), with the
    fewest solves any bisection can do; all variants return the same lattice point.
``fisher_1bit``
    The expected 1-bit Fisher information (eq. (29)-(30) of the ``onebit`` paper) on a full SNR
    grid, vectorised against per-point adaptive quadrature, with their agreement.
``exact_mean``
    The exact E(p_k) of the ``intermittent`` paper (:func:`netrepro.papers.intermittent.exact.exact_mean`,
    every k of the horizon) against the conditional Monte Carlo estimator it replaces, at the
    pipeline's sample size; the ratio is the time ratio, with the estimator's largest relative 95%
    half-width (what the exact method removes) and the exact method's error bound.
``gainsched_moments``
    The exact error second moments of the ``gainsched`` filter (printed gains, linear f = F1 z;
    :func:`netrepro.papers.gainsched.moments.second_moments`) against the Monte Carlo mean of the
    pipeline's run count: time ratio, and the Monte Carlo's largest relative error over k.
``markov_exact``
    The exact E||P_k|| of the ``markov`` paper's Example II: the block-split path tree
    (:func:`netrepro.papers.markov.exact.exact_moments_split`, what the pipeline runs) against the
    full-matrix tree, at the same depth, with their agreement.
``onebit_grid_smoother``
    The ``onebit`` grid filter/smoother on 1-bit data (alpha = 1 - 1e-3, 0 dB): the banded sparse
    transition against the dense one (same estimates to rounding), and the compiled banded kernel the
    pipeline runs against its numpy/scipy form (same estimates bit for bit).
``job_exit``
    One job process as the rules start it: interpreter, the imports of an LMI or figure step
    (numpy, scipy, pandas, numba, cvxpy, matplotlib) and exit, ending through
    :func:`netrepro.pipeline.runner.exit_process` (no interpreter teardown, what the pipeline's command
    lines do) against the normal exit; the ratio is the time ratio per job.
``pipeline``
    Cold ``snakemake -j2 report`` in a scratch copy of the repository, a no-op rerun, one figure
    rebuilt after a parameter change, peak memory, and the three slowest jobs (job wall time
    against the step's own compute time from its provenance sidecar). Skipped by ``--quick``.
"""

from __future__ import annotations

import argparse
import base64
import json
import math
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import pandas as pd

from ..locations import checkout_file, checkout_root

__all__ = [
    "COLUMNS",
    "BenchRow",
    "median_time",
    "reference_covariance_loop",
    "reference_ge_loop",
    "bench_riccati",
    "bench_channels",
    "bench_lmi",
    "bench_fisher",
    "bench_exact_mean",
    "bench_job_exit",
    "bench_pipeline",
    "blas_peak",
    "run_all",
    "main",
]

COLUMNS = ["benchmark", "metric", "ours", "reference", "ratio", "unit"]
# the clone whose sources the pipeline benchmark copies and runs (benchmarks need a clone)
ROOT = checkout_root() or Path.cwd()


def BenchRow(benchmark, metric, ours, reference, ratio, unit) -> dict:  # noqa: N802 (a row constructor)
    """One row of the benchmark table.

    Parameters
    ----------
    benchmark : str
        What is benchmarked (``riccati_iid_n1``, ``pipeline``, ...).
    metric : str
        What is measured (``path_steps_per_s``, ``max_rel_diff``, ...).
    ours : float
        Our implementation's value.
    reference : float
        The reference's value (the loop, solver or budget compared against; NaN if none).
    ratio : float
        The improvement factor, oriented so that > 1 favours ours (reference/ours for times,
        ours/reference for rates); NaN where undefined.
    unit : str
        Unit of ``ours`` and ``reference``.

    Returns
    -------
    dict
        The row, keys ``benchmark, metric, ours, reference, ratio, unit`` (the numbers as float).
    """
    return dict(benchmark=benchmark, metric=metric, ours=float(ours), reference=float(reference),
                ratio=float(ratio), unit=unit)


def _div(a, b):
    return a / b if b not in (0, 0.0) and np.isfinite(b) else float("nan")


def median_time(fn, repeats: int = 5, min_time: float = 0.0) -> float:
    """Median wall time of ``fn()`` over ``repeats`` calls (one untimed warm-up call first).

    With ``min_time`` > 0 each timed sample loops ``fn`` until at least that long has passed
    and returns the time per call.

    Parameters
    ----------
    fn : callable
        Called with no arguments; its result is discarded.
    repeats : int, default 5
        Number of timed samples.
    min_time : float, default 0.0
        Minimum duration of one sample, in seconds.

    Returns
    -------
    float
        Median seconds per call.
    """
    fn()
    samples = []
    for _ in range(repeats):
        calls, start = 0, time.perf_counter()
        while True:
            fn()
            calls += 1
            elapsed = time.perf_counter() - start
            if elapsed >= min_time:
                break
        samples.append(elapsed / calls)
    return statistics.median(samples)


@contextmanager
def _single_thread_blas():
    """Limit BLAS to one thread (threadpoolctl if installed; else a no-op, reported in the sidecar)."""
    try:
        from threadpoolctl import threadpool_limits
    except ImportError:  # pragma: no cover - depends on the environment
        yield False
        return
    with threadpool_limits(1):
        yield True


def _blas_info() -> list[dict]:
    try:
        from threadpoolctl import threadpool_info
    except ImportError:  # pragma: no cover
        return []
    return [{k: i.get(k) for k in ("internal_api", "version", "architecture", "num_threads")}
            for i in threadpool_info()]


# ============================================================================ peak
_PEAK_SCRIPT = r"""
import json, time, sys
import numpy as np
size, repeats = int(sys.argv[1]), int(sys.argv[2])
out = {}
try:
    from threadpoolctl import threadpool_info, threadpool_limits
    out["blas"] = [{k: i.get(k) for k in ("internal_api", "version", "architecture", "num_threads")}
                   for i in threadpool_info()]
except ImportError:
    threadpool_limits = None
    out["blas"] = []
rng = np.random.default_rng(0)
a, b = rng.random((size, size)), rng.random((size, size))
c = np.empty((size, size))
def best(fn):
    fn()
    times = []
    for _ in range(repeats):
        t = time.perf_counter(); fn(); times.append(time.perf_counter() - t)
    return min(times)
flops = 2.0 * size ** 3
out["gflops_all_threads"] = flops / best(lambda: np.matmul(a, b, out=c)) / 1e9
if threadpool_limits is not None:
    with threadpool_limits(1):
        out["gflops_1_thread"] = flops / best(lambda: np.matmul(a, b, out=c)) / 1e9
print(json.dumps(out))
"""


def blas_peak(native: bool = True, size: int = 2048, repeats: int = 5) -> dict:
    """Double-precision GEMM rate of this machine, measured in a child process.

    ``native=True`` unsets ``OPENBLAS_CORETYPE`` and ``OPENBLAS_L2_SIZE`` (together, in the child
    only) so OpenBLAS picks its own kernel for this processor; ``native=False`` keeps the
    environment as it is (the kernel the pipeline's steps run with).

    Parameters
    ----------
    native : bool, default True
        Whether to unset the two OpenBLAS variables in the child.
    size : int, default 2048
        Order of the square matrices multiplied.
    repeats : int, default 5
        Timed products; the best is kept.

    Returns
    -------
    dict
        The best-of-repeats ``gflops_1_thread`` and ``gflops_all_threads``, the BLAS libraries
        with their kernels, and ``env``: the two variables as the child saw them.

    Raises
    ------
    RuntimeError
        If the child process fails (its stderr tail in the message).
    """
    env = dict(os.environ)
    if native:
        env.pop("OPENBLAS_CORETYPE", None)
        env.pop("OPENBLAS_L2_SIZE", None)
    proc = subprocess.run([sys.executable, "-c", _PEAK_SCRIPT, str(size), str(repeats)], env=env,
                          capture_output=True, text=True, timeout=600)
    if proc.returncode != 0:
        raise RuntimeError(f"peak measurement failed: {proc.stderr[-2000:]}")
    out = json.loads(proc.stdout.strip().splitlines()[-1])
    out["env"] = {k: env.get(k) for k in ("OPENBLAS_CORETYPE", "OPENBLAS_L2_SIZE")}
    return out


# ============================================================================ exact E(p_k) (intermittent)
def bench_exact_mean(n_paths: int, horizon: int, repeats: int) -> list[dict]:
    """Exact E(p_k), k <= horizon, against the conditional Monte Carlo estimator it replaces.

    The scalar system of the intermittent paper (a = 1.5, R1 = 0.1, R2 = 0.5, E p_0 = 10) at
    lambda = lambda_c + 0.1 and lambda_c - 0.1 (lambda_c = 1 - 1/a^2).

    Parameters
    ----------
    n_paths : int
        Monte Carlo paths per lambda (blocks of 20000, seed 7).
    horizon : int
        Last step k.
    repeats : int
        Timed samples of the exact computation (the estimator gets half as many, at least one).

    Returns
    -------
    list of dict
        Two :func:`BenchRow` rows: times, and the exact computation's relative error bound
        against the estimator's largest relative 95% half-width.
    """
    from ..engines.montecarlo import run_monte_carlo
    from ..papers.intermittent.exact import exact_mean
    from ..papers.intermittent.model import critical_probability
    from ..papers.intermittent.steps import _scalar_simulator

    a, R1, R2, p0 = 1.5, 0.1, 0.5, 10.0
    lams = [critical_probability(a) + off for off in (0.1, -0.1)]
    params = dict(a=a, R1=R1, R2=R2, Ep0=p0, horizon=horizon)
    results = {}

    def ours():
        results["exact"] = [exact_mean(p0, a, R1, [R2], [lam], horizon) for lam in lams]

    def estimator():
        results["mc"] = [run_monte_carlo(_scalar_simulator(params, lam), n_paths, 20000, 7).ci("cond") for lam in lams]

    t_ours = median_time(ours, repeats)
    t_ref = median_time(estimator, max(1, repeats // 2))
    half = max(float(np.max((hi - m) / m)) for m, _, hi in results["mc"])
    bound = max(float(r.rel_error_bound.max()) for r in results["exact"])
    return [
        BenchRow("exact_mean", f"time_s_{len(lams)}x{horizon + 1}_values", t_ours, t_ref, t_ref / t_ours, "s"),
        BenchRow("exact_mean", "max_rel_error", bound, half, half / bound, "1 (exact bound vs MC 95% half-width)"),
    ]


def _configured(slug: str) -> dict:
    """The paper's section of the full configuration (the benchmarks run the configured problem)."""
    import yaml

    return yaml.safe_load(checkout_file("config", "config.yaml").read_text())[slug]


def bench_gainsched_moments(n_runs: int, repeats: int) -> list[dict]:
    """Exact E||e(k)||^2 of the ``gainsched`` filter (printed gains, f = F1 z) against the Monte Carlo it replaces.

    The exact second-moment recursion (:func:`netrepro.papers.gainsched.moments.second_moments`)
    against ``n_runs`` simulated paths (:func:`netrepro.papers.gainsched.model.simulate`, the
    pipeline's run count) on the configured system, schedule and x(0); the second row is the
    Monte Carlo's largest relative error against the exact values over k (what the exact method
    removes: with the multiplicative noise the squared error is heavy-tailed).
    """
    from ..papers.gainsched.model import gains_from_dict, simulate, system_from_config
    from ..papers.gainsched.moments import error_mse, initial_moment, linear_gains, mode_matrices, second_moments
    from ..papers.gainsched.steps import p_sequence

    cfg = _configured("gainsched")
    sys_ = system_from_config(cfg["system"])
    gains = gains_from_dict(cfg["paper_gains"], sys_)
    p_seq = p_sequence(cfg, sys_)
    x0 = np.asarray(cfg["simulation"]["x0"], dtype=float)
    results = {}

    def ours():
        M1, M0, W = mode_matrices(sys_, gains, p_seq, linear_gains(sys_)["F1"])
        X = second_moments(M1, M0, W, p_seq, sys_.sigma2, initial_moment(x0, np.zeros((sys_.n, sys_.n)),
                                                                          np.zeros(sys_.n)))
        results["exact"] = error_mse(X)

    def estimator():
        e = simulate(sys_, gains, p_seq, np.tile(x0, (n_runs, 1)), np.random.default_rng(7), "lower")
        results["mc"] = np.mean(np.sum(e ** 2, axis=-1), axis=0)

    t_ours = median_time(ours, repeats)
    t_ref = median_time(estimator, max(1, repeats // 2))
    exact, mc = results["exact"], results["mc"]
    rel = float(np.max(np.abs(mc - exact) / exact))
    return [
        BenchRow("gainsched_moments", f"time_s_{exact.size}_steps", t_ours, t_ref, t_ref / t_ours,
                 f"s (exact recursion vs {n_runs} Monte Carlo runs)"),
        # the recursion is exact up to rounding: no ratio, the reference column is what Monte Carlo gets wrong
        BenchRow("gainsched_moments", "max_rel_error_mc", 0.0, rel, np.nan,
                 "1 (Monte Carlo mean's largest relative error over k against the exact recursion)"),
    ]


def bench_markov_exact(depth: int, repeats: int) -> list[dict]:
    """Exact E||P_k|| of ``markov`` Example II: the block-split tree against the full-matrix tree it replaces.

    Both enumerate every channel path to ``depth`` (exact, no sampling); the split one
    (:func:`netrepro.papers.markov.exact.exact_moments_split`) propagates each decoupled block by
    its own small Riccati map. Rows: the time ratio at the same depth, and the agreement of the
    two expectation polynomials on a (p, q) grid.
    """
    from ..papers.markov.exact import exact_moments, exact_moments_split, find_split
    from ..papers.markov.model import LinearSystem

    cfg = _configured("markov")
    ex = cfg["examples"]["II"]
    system, sigma0 = LinearSystem.from_config(ex), np.asarray(ex["Sigma0"], float)
    split = find_split(system, sigma0)
    if split is None:
        raise RuntimeError("markov Example II has no block split: the benchmark needs one")
    results = {}

    def ours():
        results["split"] = exact_moments_split(system, sigma0, depth, split)

    def reference():
        results["full"] = exact_moments(system, sigma0, depth)

    t_ours = median_time(ours, repeats)
    t_ref = median_time(reference, max(1, repeats // 2))
    p, q = np.meshgrid(np.linspace(0.05, 0.95, 7), np.linspace(0.05, 0.95, 7))
    a, b = results["split"].mean(p, q), results["full"].mean(p, q)
    diff = float(np.max(np.abs(a - b) / np.abs(b)))
    return [
        BenchRow("markov_exact", f"time_s_depth_{depth}", t_ours, t_ref, t_ref / t_ours,
                 "s (block-split tree vs full-matrix tree, Example II)"),
        BenchRow("markov_exact", "max_rel_diff", diff, 1e-10, _div(1e-10, diff) if diff > 0 else np.inf,
                 "1 (split vs full E||P_k|| on a 7x7 (p, q) grid; reference = tolerance)"),
    ]


# ============================================================================ (a) Riccati recursions
def reference_covariance_loop(P0, A, Q, c, r, arrivals, floats: bool = False) -> np.ndarray:
    """Per-path Python loop of the intermittent Riccati recursion with one scalar sensor (the reference).

    ``P_{k+1} = A (P_k - gamma_k P_k c^T c P_k / (c P_k c^T + r)) A^T + Q``, path by path and
    step by step with small numpy matrices (the textbook form, any n, the updated covariance
    symmetrised as the engine's dense form does); ``floats=True`` (n = 1 only) runs the same
    recursion on plain Python floats, the fastest per-path loop there is.

    Parameters
    ----------
    P0 : array_like
        Initial covariance, ``(n, n)`` or broadcastable to it (a scalar for n = 1).
    A, Q : array_like
        System and process-noise covariance matrices, ``(n, n)`` (scalars for n = 1).
    c : array_like
        Output row, ``n`` entries.
    r : float
        Measurement noise variance.
    arrivals : ndarray of bool, shape (N, T)
        ``gamma_k`` per path and step (True: the measurement arrives).
    floats : bool, default False
        Use the plain-float loop (requires n = 1).

    Returns
    -------
    ndarray, shape (N, n, n)
        ``P_T`` for every path.

    Raises
    ------
    ValueError
        If ``floats=True`` and n > 1.
    """
    A = np.atleast_2d(np.asarray(A, dtype=float))
    Q = np.atleast_2d(np.asarray(Q, dtype=float))
    n = A.shape[0]
    N, T = arrivals.shape
    out = np.empty((N, n, n))
    if floats:
        if n != 1:
            raise ValueError(f"floats=True needs a scalar system, got n = {n}")
        a2, q, cc = float(A[0, 0]) ** 2, float(Q[0, 0]), float(np.ravel(c)[0]) ** 2
        for i in range(N):
            p = float(np.asarray(P0, dtype=float).reshape(-1)[0])
            row = arrivals[i].tolist()
            for k in range(T):
                if row[k]:
                    p = p - p * cc * p / (cc * p + r)
                p = a2 * p + q
            out[i, 0, 0] = p
        return out
    c = np.asarray(c, dtype=float).reshape(1, n)
    for i in range(N):
        P = np.array(np.broadcast_to(P0, (n, n)), dtype=float)
        for k in range(T):
            if arrivals[i, k]:
                u = P @ c.T
                P = P - (u @ u.T) / ((c @ u).item() + r)
                P = 0.5 * (P + P.T)  # as the engine's dense form does; unsymmetrised, rounding grows
            P = A @ P @ A.T + Q
        out[i] = P
    return out


SCALAR_FLOPS_PER_STEP = 5  # p <- a^2 (r (p / (p + r))) + q: an add, a division, two multiplies, an add
RICCATI_RTOL = 1e-6  # agreement of two correct float64 implementations over 200 steps of an unstable system


def _system(n: int):
    """A fixed test system of dimension n: unstable (spectral radius 1.2), observable from c."""
    A = {1: [[1.2]], 2: [[1.1, 0.3], [-0.2, 0.95]], 3: [[1.1, 0.3, 0.0], [-0.2, 0.95, 0.1], [0.0, 0.2, 0.8]]}[n]
    A = np.array(A)
    c = np.ones(n) / np.sqrt(n)
    return A, 0.1 * np.eye(n), c, 0.5, np.eye(n)


def _arrivals(kind: str, rng, N: int, T: int):
    from ..engines.channels import gilbert_elliott_arrivals, iid_arrivals

    if kind == "iid":
        return iid_arrivals(rng, N, T, 0.7)
    return gilbert_elliott_arrivals(rng, N, T, p=0.2, q=0.6)


def bench_riccati(n_paths: int, horizon: int, ref_paths: int, repeats: int, peak_gflops: float,
                  dims=(1, 2, 3), kinds=("iid", "ge"), rows_out=None) -> list[dict]:
    """Batched covariance recursions against the per-path loop; flops and fraction of peak.

    For each arrival kind and state dimension: path-steps per second of
    :func:`netrepro.engines.riccati.covariance_paths` (single-threaded BLAS) against
    :func:`reference_covariance_loop`, against the engine's numpy kernel, the dense batched
    form (n > 1) and the float loop (n = 1); flops per path-step, the achieved fraction of
    ``peak_gflops``, and the largest relative difference of ``P_T`` on the reference paths.

    Parameters
    ----------
    n_paths : int
        Paths of the batched run.
    horizon : int
        Steps per path.
    ref_paths : int
        Paths of the per-path loops (the first ``ref_paths`` of the same arrivals).
    repeats : int
        Timed samples of ours (the references get half as many, at least one).
    peak_gflops : float
        Single-thread GEMM rate to compare with (from :func:`blas_peak`).
    dims : tuple of int, default (1, 2, 3)
        State dimensions.
    kinds : tuple of str, default ("iid", "ge")
        Arrival processes: i.i.d. Bernoulli or Gilbert-Elliott.
    rows_out : list, optional
        A list the rows are appended to (and returned); default a new list.

    Returns
    -------
    list of dict
        :func:`BenchRow` rows.
    """
    from ..engines.riccati import Sensor, covariance_paths, packed_flops_per_step

    rows = [] if rows_out is None else rows_out
    rng = np.random.default_rng(20261122)
    for kind in kinds:
        for n in dims:
            A, Q, c, r, P0 = _system(n)
            sensors = [Sensor(c[None, :], [[r]])]
            arr = _arrivals(kind, rng, n_paths, horizon)
            ref_arr = arr[:ref_paths]
            with _single_thread_blas():
                t_ours = median_time(lambda: covariance_paths(P0, A, Q, sensors, arr, keep="last"), repeats)
                ours_last = covariance_paths(P0, A, Q, sensors, ref_arr, keep="last")
            t_ref = median_time(lambda: reference_covariance_loop(P0, A, Q, c, r, ref_arr), max(1, repeats // 2))
            ref_last = reference_covariance_loop(P0, A, Q, c, r, ref_arr)
            ours_last = np.asarray(ours_last).reshape(ref_paths, n, n)
            scale = np.max(np.abs(ref_last), axis=(1, 2), keepdims=True)
            diff = float(np.max(np.abs(ours_last - ref_last) / scale))
            rate, ref_rate = n_paths * horizon / t_ours, ref_paths * horizon / t_ref
            flops = SCALAR_FLOPS_PER_STEP if n == 1 else packed_flops_per_step(n, 1)
            name = f"riccati_{kind}_n{n}"
            rows.append(BenchRow(name, "path_steps_per_s", rate, ref_rate, rate / ref_rate, "path-steps/s"))
            with _single_thread_blas():  # against the batched numpy kernel the compiled one replaced
                t_np = median_time(lambda: covariance_paths(P0, A, Q, sensors, arr, keep="last", kernel="numpy"),
                                   max(1, repeats // 2))
            rows.append(BenchRow(name, "path_steps_per_s_vs_numpy_batched", rate, n_paths * horizon / t_np,
                                 t_np / t_ours, "path-steps/s"))
            if n > 1:  # against the batched dense form (np.linalg.solve per update)
                from ..engines.riccati import _dense_paths

                sub = arr[: max(ref_paths, n_paths // 8)]
                with _single_thread_blas():
                    t_dense = median_time(lambda: _dense_paths(P0, A, Q, sensors, sub[:, :, None], "last"),
                                          max(1, repeats // 2))
                dense_rate = sub.size / t_dense
                rows.append(BenchRow(name, "path_steps_per_s_vs_dense_batched", rate, dense_rate, rate / dense_rate,
                                     "path-steps/s"))
            if n == 1:  # also against the fastest per-path loop: plain Python floats
                t_flt = median_time(lambda: reference_covariance_loop(P0, A, Q, c, r, ref_arr, floats=True),
                                    max(1, repeats // 2))
                flt_rate = ref_paths * horizon / t_flt
                rows.append(BenchRow(name, "path_steps_per_s_vs_float_loop", rate, flt_rate, rate / flt_rate,
                                     "path-steps/s"))
            rows.append(BenchRow(name, "flops_per_path_step", flops, np.nan, np.nan, "flop"))
            achieved = flops * rate / 1e9
            rows.append(BenchRow(name, "fraction_of_peak", achieved, peak_gflops, _div(achieved, peak_gflops),
                                 "Gflop/s (1 core)"))
            rows.append(BenchRow(name, "max_rel_diff", diff, RICCATI_RTOL, _div(RICCATI_RTOL, diff) if diff > 0 else np.inf,
                                 "1"))
    return rows


def reference_ge_loop(rng, n_paths: int, horizon: int, p: float, q: float) -> np.ndarray:
    """Gilbert-Elliott arrivals path by path, step by step (the reference sampler).

    The first state is drawn from the stationary law (arrival with probability ``q/(p+q)``).

    Parameters
    ----------
    rng : numpy.random.Generator
        Source of the uniform draws (``horizon`` per path).
    n_paths : int
        Number of paths.
    horizon : int
        Steps per path.
    p : float
        Probability of going from arrival (good) to loss (bad) in one step.
    q : float
        Probability of going from loss back to arrival in one step.

    Returns
    -------
    ndarray of bool, shape (n_paths, horizon)
        True where the packet arrives.
    """
    pi1 = q / (p + q)
    out = np.empty((n_paths, horizon), dtype=bool)
    for i in range(n_paths):
        u = rng.random(horizon).tolist()
        state = u[0] < pi1
        row = [state]
        for k in range(1, horizon):
            state = (u[k] >= p) if state else (u[k] < q)
            row.append(state)
        out[i] = row
    return out


def bench_channels(n_paths: int, horizon: int, ref_paths: int, repeats: int) -> list[dict]:
    """Vectorised Gilbert-Elliott sampling against a per-path loop (same law; different streams).

    Both sample with p = 0.2, q = 0.6.

    Parameters
    ----------
    n_paths : int
        Paths of the vectorised sampler.
    horizon : int
        Steps per path.
    ref_paths : int
        Paths of :func:`reference_ge_loop`.
    repeats : int
        Timed samples of ours (the reference gets half as many, at least one).

    Returns
    -------
    list of dict
        One :func:`BenchRow`: path-steps per second.
    """
    from ..engines.channels import gilbert_elliott_arrivals

    t_ours = median_time(lambda: gilbert_elliott_arrivals(np.random.default_rng(1), n_paths, horizon, 0.2, 0.6),
                         repeats)
    t_ref = median_time(lambda: reference_ge_loop(np.random.default_rng(1), ref_paths, horizon, 0.2, 0.6),
                        max(1, repeats // 2))
    rate, ref_rate = n_paths * horizon / t_ours, ref_paths * horizon / t_ref
    return [BenchRow("channel_ge", "path_steps_per_s", rate, ref_rate, rate / ref_rate, "path-steps/s")]


# ============================================================================ (b) LMI
def _two_sensor_modes():
    return [None, np.array([[1.0]]), np.array([[1.0]]), np.array([[1.0], [1.0]])]


def bench_lmi(n_sweep: int, grid_points: int, tol: float, repeats: int) -> list[dict]:
    """Parametrised LMI solved across a sweep vs rebuilt per point; solves per bisection curve.

    Sweeps: a two-sensor scalar system and a one-sensor n = 2 system, each over ``n_sweep``
    arrival weights. Curve: the two-sensor stability region (intermittent, Figs 4-5) by
    bisection on ``grid_points`` values of lambda_1, warm-started, plain, and bracketed from
    the closed-form lower bound (what the pipeline runs).

    Parameters
    ----------
    n_sweep : int
        Points of each sweep.
    grid_points : int
        Points of the bisection curve.
    tol : float
        Bisection tolerance on lambda_2.
    repeats : int
        Timed samples of the parametrised sweep (the rebuilt one gets half as many, at least one).

    Returns
    -------
    list of dict
        :func:`BenchRow` rows: solves per second, solves per curve (against the plain bisection
        and the fewest possible), curve times and the largest threshold gap.

    Raises
    ------
    AssertionError
        If the parametrised and rebuilt LMIs certify differently, or a bracketed bisection
        returns another threshold than the plain one.
    """
    from ..engines.channels import arrival_patterns
    from ..engines.lmi import MareStabilizabilityLMI, sweep_thresholds

    rows = []
    cases = {
        "lmi_sweep_two_sensor_n1": ([[1.5]], _two_sensor_modes(),
                                    [arrival_patterns([0.3, l2])[1] for l2 in np.linspace(0.05, 0.95, n_sweep)]),
        "lmi_sweep_one_sensor_n2": ([[1.1, 0.3], [-0.2, 0.95]], [None, np.array([[1.0, 0.5]])],
                                    [np.array([1 - lam, lam]) for lam in np.linspace(0.05, 0.95, n_sweep)]),
    }
    for name, (A, modes, weights) in cases.items():
        lmi = MareStabilizabilityLMI(A, modes)
        lmi.solve(weights[0])  # compile once (DPP); a sweep pays this once

        def sweep_ours(lmi=lmi, weights=weights):
            return [lmi.solve(w).certified for w in weights]

        def sweep_rebuild(A=A, modes=modes, weights=weights):
            return [MareStabilizabilityLMI(A, modes).solve(w).certified for w in weights]

        t_ours = median_time(sweep_ours, repeats)
        t_ref = median_time(sweep_rebuild, max(1, repeats // 2))
        if sweep_ours() != sweep_rebuild():
            raise AssertionError(f"{name}: parametrised and rebuilt LMIs disagree")
        rows.append(BenchRow(name, "solves_per_s", len(weights) / t_ours, len(weights) / t_ref, t_ref / t_ours,
                             "solves/s"))

    # solves per stability curve: the two-sensor region (intermittent, Figs 4-5)
    lmi = MareStabilizabilityLMI([[1.5]], _two_sensor_modes())

    def make(l1):
        def feasible(l2):
            return lmi.solve(arrival_patterns([l1, l2])[1]).certified
        return feasible

    lmi.solve(arrival_patterns([0.5, 0.5])[1])  # compile before timing either variant
    grid = np.linspace(0.0, 1.0, grid_points)
    timings = {}
    results = {}
    for label, warm in (("warm", True), ("plain", False)):
        start = time.perf_counter()
        results[label] = sweep_thresholds(make, grid, 0.0, 1.0, tol, warm_start=warm)
        timings[label] = time.perf_counter() - start
    # what the pipeline runs: each point bracketed from its own closed-form lower bound
    from ..engines.lmi import bisect_bracketed
    from ..papers.intermittent.two_sensor import two_sensor_lower_bound

    start = time.perf_counter()
    results["lower_bound"] = [bisect_bracketed(make(l1), 0.0, 1.0, g, 0.0, tol)
                              for l1, g in zip(grid, two_sensor_lower_bound(grid, 1.5))]
    timings["lower_bound"] = time.perf_counter() - start
    n_warm = sum(r.n_evals for r in results["warm"])
    n_plain = sum(r.n_evals for r in results["plain"])
    n_lower = sum(r.n_evals for r in results["lower_bound"])
    # fewest solves any bisection can do: two adjacent lattice points per bracketed answer, one otherwise
    n_min = sum(2 if r.bracketed else 1 for r in results["plain"])
    gap = max(abs(a.threshold - b.threshold) if np.isfinite(a.threshold) else 0.0
              for variant in ("warm", "lower_bound") for a, b in zip(results[variant], results["plain"]))
    if gap > 0:
        raise AssertionError(f"bracketed and plain bisections differ by {gap} (they must return the same point)")
    rows.append(BenchRow("lmi_bisection", f"solves_per_curve_{grid_points}pts", n_warm, n_plain, n_plain / n_warm,
                         "solves"))
    rows.append(BenchRow("lmi_bisection", f"solves_per_curve_{grid_points}pts_from_lower_bound", n_lower, n_plain,
                         n_plain / n_lower, "solves"))
    rows.append(BenchRow("lmi_bisection", f"solves_per_curve_{grid_points}pts_vs_fewest_possible", n_lower, n_min,
                         n_min / n_lower, "solves"))
    rows.append(BenchRow("lmi_bisection", "solves_per_grid_point", n_warm / grid_points, n_plain / grid_points,
                         n_plain / n_warm, "solves"))
    rows.append(BenchRow("lmi_bisection", "curve_time_s", timings["warm"], timings["plain"],
                         timings["plain"] / timings["warm"], "s"))
    rows.append(BenchRow("lmi_bisection", "curve_time_s_from_lower_bound", timings["lower_bound"], timings["plain"],
                         timings["plain"] / timings["lower_bound"], "s"))
    rows.append(BenchRow("lmi_bisection", "max_threshold_gap", gap, tol, _div(tol, gap) if gap > 0 else np.inf, "1"))
    return rows


# ============================================================================ (c) 1-bit Fisher information
_LOG_SQRT_2PI = 0.5 * math.log(2.0 * math.pi)


def _fisher_functions():
    """The onebit paper's vectorised and quadrature forms of eq. (29), or local equivalents.

    Returns ``(vectorised, quadrature, source)``. The local forms implement eqs. (29)-(30)
    of ``shared/papers/002`` the same way (product-Gaussian trapezoid; scipy ``quad``) and
    are used only when ``netrepro.papers.onebit`` does not provide them.
    """
    try:
        from ..papers.onebit.fisher import expected_fisher_1bit, expected_fisher_1bit_quad
        return expected_fisher_1bit, (lambda v: expected_fisher_1bit_quad(v)[0]), "netrepro.papers.onebit"
    except ImportError:  # pragma: no cover - only before the onebit paper exists
        pass
    from scipy import integrate
    from scipy.special import log_ndtr

    def log_h(x):
        return -0.5 * x * x - _LOG_SQRT_2PI - log_ndtr(x) - log_ndtr(-x)

    def fisher(theta):  # eq. (30), sigma_eta = 1
        x = np.asarray(theta, dtype=float)
        return np.exp(2.0 * (-0.5 * x * x - _LOG_SQRT_2PI) - log_ndtr(x) - log_ndtr(-x))

    def vectorised(v, half_width=12.0, step=0.1):  # eq. (29), theta ~ N(0, v)
        v = np.asarray(v, dtype=float)
        u = np.arange(-half_width, half_width + step / 2, step)
        w = np.exp(-0.5 * u * u - _LOG_SQRT_2PI) * step
        tau = np.sqrt(v / (1.0 + v))[..., None]
        return np.exp(log_h(tau * u)) @ w / np.sqrt(2.0 * np.pi * (1.0 + v))

    def quadrature(v):
        s = math.sqrt(v)
        lo, hi = max(-40.0 * s, -60.0), min(40.0 * s, 60.0)
        f = lambda t: float(fisher(t)) * math.exp(-0.5 * (t / s) ** 2) / (s * math.sqrt(2 * math.pi))  # noqa: E731
        return integrate.quad(f, lo, hi, points=[0.0], epsabs=0.0, epsrel=1e-13, limit=500)[0]

    return vectorised, quadrature, "netrepro.scale.bench (local eqs. (29)-(30))"


def bench_fisher(snr_start: float, snr_stop: float, snr_step: float, repeats: int) -> tuple[list[dict], str]:
    """Expected 1-bit Fisher information on an SNR grid: vectorised vs per-point adaptive quadrature.

    Parameters
    ----------
    snr_start, snr_stop, snr_step : float
        The SNR grid in dB, ``snr_stop`` included.
    repeats : int
        Timed samples of the vectorised form (at least 0.05 s each; quadrature gets half as many samples).

    Returns
    -------
    rows : list of dict
        :func:`BenchRow` rows: grid points per second and the largest relative difference.
    source : str
        Where the two implementations came from (the onebit package, or the local equivalents).
    """
    vectorised, quadrature, source = _fisher_functions()
    snr_db = np.arange(snr_start, snr_stop + snr_step / 2, snr_step)
    v = 10.0 ** (snr_db / 10.0)
    t_ours = median_time(lambda: vectorised(v), repeats, min_time=0.05)
    t_ref = median_time(lambda: [quadrature(float(x)) for x in v], max(1, repeats // 2))
    ours = np.asarray(vectorised(v))
    ref = np.array([quadrature(float(x)) for x in v])
    diff = float(np.max(np.abs(ours / ref - 1.0)))
    rows = [
        BenchRow("fisher_1bit", f"grid_points_per_s_{len(v)}pts", len(v) / t_ours, len(v) / t_ref, t_ref / t_ours,
                 "points/s"),
        BenchRow("fisher_1bit", "max_rel_diff", diff, 1e-10, _div(1e-10, diff) if diff > 0 else np.inf, "1"),
    ]
    return rows, source


# ============================================================================ job process exit
def _env_with_src(src: Path) -> dict:
    """This process's environment with ``src`` first on ``PYTHONPATH`` (its package is the one a child runs)."""
    return dict(os.environ, PYTHONPATH=os.pathsep.join(p for p in (str(src), os.environ.get("PYTHONPATH")) if p))


JOB_IMPORTS = "numpy, scipy.linalg, pandas, numba, cvxpy, matplotlib.pyplot"


def bench_job_exit(repeats: int) -> list[dict]:
    """Wall time of one job process ending through :func:`netrepro.pipeline.runner.exit_process` against a normal exit.

    Each process starts, imports what a step imports (``JOB_IMPORTS``) and exits; the normal
    exit's teardown frees every imported module: what each of a cold build's ~100 jobs paid before.

    Parameters
    ----------
    repeats : int
        Timed processes of each kind.

    Returns
    -------
    list of dict
        One :func:`BenchRow`: seconds per job.
    """
    env = _env_with_src(ROOT / "src")
    codes = {"ours": f"import {JOB_IMPORTS}\nfrom netrepro.pipeline.runner import exit_process\nexit_process(0)",
             "reference": f"import {JOB_IMPORTS}\nimport netrepro.pipeline.runner"}

    def job(which):
        return lambda: subprocess.run([sys.executable, "-c", codes[which]], env=env, check=True)

    t_ours = median_time(job("ours"), repeats)
    t_ref = median_time(job("reference"), repeats)
    return [BenchRow("job_exit", "time_s_per_job", t_ours, t_ref, _div(t_ref, t_ours),
                     f"s (start, import {JOB_IMPORTS}, exit)")]


def bench_grid_transition(n_runs: int, horizon: int, repeats: int) -> list[dict]:
    """The onebit grid filter/smoother (1-bit data, alpha = 1 - 1e-3, 0 dB): banded vs dense transition, and the
    compiled banded kernel (what the pipeline runs) against its numpy/scipy form (the tested reference)."""
    from ..papers.onebit.estimators import _grid_smoother_at_numpy, grid_smoother_at, simulate_block, state_grid
    from ..papers.onebit.model import sigma_z2_from_snr, stationary_variance

    eps = 1e-3
    s = float(sigma_z2_from_snr(0.0, eps))
    _, _, r = simulate_block(np.random.default_rng(1), n_runs, horizon, eps, s, 1.0)
    ev = np.arange(horizon // 2, horizon, 5)
    t_band = median_time(lambda: grid_smoother_at(r, eps, s, 1.0, ev), repeats)
    t_dense = median_time(lambda: grid_smoother_at(r, eps, s, 1.0, ev, band_sigmas=None), max(1, repeats // 2))
    fb, sb = grid_smoother_at(r, eps, s, 1.0, ev)
    fd, sd_ = grid_smoother_at(r, eps, s, 1.0, ev, band_sigmas=None)
    diff = float(max(np.abs(fb - fd).max(), np.abs(sb - sd_).max()) / math.sqrt(float(stationary_variance(eps, s))))
    def banded_numpy():
        return _grid_smoother_at_numpy(r, eps, s, 1.0, ev, 6.0, 1.0, 8.0, True)

    t_numpy = median_time(banded_numpy, max(1, repeats // 2))
    fn, sn = banded_numpy()
    kernel_diff = float(max(np.abs(fb - fn).max(), np.abs(sb - sn).max()))
    steps = n_runs * horizon
    n_grid = len(state_grid(eps, s))
    return [
        BenchRow("onebit_grid_smoother", f"run_steps_per_s_banded_vs_dense_{n_grid}pts", steps / t_band,
                 steps / t_dense, t_dense / t_band, "run-steps/s"),
        BenchRow("onebit_grid_smoother", "max_rel_diff", diff, 1e-10, _div(1e-10, diff) if diff > 0 else np.inf, "1"),
        BenchRow("onebit_grid_smoother", f"run_steps_per_s_kernel_vs_numpy_banded_{n_grid}pts", steps / t_band,
                 steps / t_numpy, t_numpy / t_band, "run-steps/s"),
        # the kernel repeats the numpy/scipy arithmetic in the same order: any difference is a defect
        BenchRow("onebit_grid_smoother", "kernel_max_abs_diff", kernel_diff, 0.0, np.inf if kernel_diff == 0 else 0.0,
                 "1"),
    ]


# ============================================================================ (d) pipeline
_IGNORE = shutil.ignore_patterns(".venv", ".git", "results", "logs", ".snakemake", "report", "figures", "__pycache__",
                                 "*.egg-info", ".pytest_cache", ".hypothesis", "tmp")


class _TreeMemory:
    """Samples the summed resident memory of a process tree (from /proc) in a thread."""

    def __init__(self, interval: float = 0.2):
        self.interval, self.peak_kb, self._stop, self.pid = interval, 0, threading.Event(), None

    def _tree_rss_kb(self):
        children, rss = {}, {}
        for entry in os.listdir("/proc"):
            if not entry.isdigit():
                continue
            try:
                with open(f"/proc/{entry}/stat") as fh:
                    fields = fh.read().rsplit(")", 1)[1].split()
                children.setdefault(int(fields[1]), []).append(int(entry))
                rss[int(entry)] = int(fields[21]) * os.sysconf("SC_PAGE_SIZE") // 1024
            except (OSError, IndexError, ValueError):
                continue
        total, stack = 0, [self.pid]
        while stack:
            pid = stack.pop()
            total += rss.get(pid, 0)
            stack.extend(children.get(pid, []))
        return total

    def _run(self):
        while not self._stop.is_set():
            self.peak_kb = max(self.peak_kb, self._tree_rss_kb())
            self._stop.wait(self.interval)

    def watch(self, pid):
        self.pid = pid
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def stop(self):
        self._stop.set()
        self._thread.join()


def _snakemake(work: Path, args, env, log: Path, memory: bool = False):
    """Run snakemake in ``work``; return (wall seconds, returncode, max child RSS kB, tree peak kB)."""
    cmd = [sys.executable, "-m", "snakemake", "--profile", "workflow/profiles/default", *args]
    sampler = _TreeMemory() if memory else None
    start = time.perf_counter()
    with open(log, "a") as fh:
        fh.write(f"\n$ {' '.join(cmd)}\n")
        fh.flush()
        proc = subprocess.Popen(cmd, cwd=work, env=env, stdout=fh, stderr=subprocess.STDOUT)
        if sampler:
            sampler.watch(proc.pid)
        _, status, usage = os.wait4(proc.pid, 0)
        proc.returncode = os.waitstatus_to_exitcode(status)
    wall = time.perf_counter() - start
    if sampler:
        sampler.stop()
    # ru_maxrss of a wait4 on snakemake: the largest resident set among it and its waited-for descendants
    return wall, proc.returncode, usage.ru_maxrss, sampler.peak_kb if sampler else 0


def _job_times(work: Path) -> pd.DataFrame:
    """Per-output job start/end times from ``.snakemake/metadata`` and step times from the sidecars."""
    records = []
    meta_dir = work / ".snakemake" / "metadata"
    for path in meta_dir.iterdir() if meta_dir.is_dir() else []:
        try:
            rec = json.loads(path.read_text())
            output = base64.b64decode(path.name.replace("@", "/")).decode()
        except (ValueError, UnicodeDecodeError):
            continue
        if rec.get("starttime") is None or rec.get("endtime") is None:
            continue
        step = np.nan
        sidecar = work / (output + ".meta.json")
        if sidecar.is_file():
            try:
                step = float(json.loads(sidecar.read_text()).get("wall_time_s", np.nan))
            except ValueError:
                pass
        records.append(dict(rule=rec.get("rule"), output=output, start=rec["starttime"], end=rec["endtime"],
                            step_s=step, job=json.dumps(rec.get("log") or [output])))
    if not records:
        return pd.DataFrame(columns=["rule", "output", "job_s", "step_s", "n_outputs", "start", "end"])
    df = pd.DataFrame(records)
    # one job = one rule run, identified by its log file(s); outputs without a log stand alone
    jobs = df.groupby(["rule", "job"]).agg(start=("start", "min"), end=("end", "max"), step_s=("step_s", "max"),
                                                 n_outputs=("output", "count"), output=("output", "min")).reset_index()
    jobs["job_s"] = jobs["end"] - jobs["start"]
    return jobs.sort_values("job_s", ascending=False)[["rule", "output", "job_s", "step_s", "n_outputs", "start", "end"]]


def _set_config_value(config_file: Path, dotted: str, factor: float) -> tuple[float, float]:
    """Multiply a numeric config value (``a.b.c``) by ``factor`` in place, keeping the file's other lines."""
    import yaml

    data = yaml.safe_load(config_file.read_text())
    node = data
    keys = dotted.split(".")
    for k in keys[:-1]:
        node = node[k]
    old = node[keys[-1]]
    new = type(old)(old * factor)
    node[keys[-1]] = new
    config_file.write_text(yaml.safe_dump(data, sort_keys=False))
    return old, new


def bench_pipeline(scratch: Path | None = None, config: str = "config/config.yaml", jobs: int = 2,
                   change_key: str = "intermittent.two_sensor.check_offset", change_factor: float = 0.5,
                   figure_target: str = "intermittent_fig5", keep: bool = False) -> tuple[list[dict], dict]:
    """Cold build, no-op rerun, one figure after a parameter change, memory, slowest jobs.

    Runs in a scratch copy of the repository (never in this checkout's own ``results/``), with
    ``PYTHONPATH`` pointing at the copy's ``src/`` so the copy's package is the one that runs.
    Stops after the cold build if it fails (its row NaN, the log tail in the information).

    Parameters
    ----------
    scratch : Path, optional
        Folder in which the scratch copy is made (default: the system's temporary folder).
    config : str, default "config/config.yaml"
        Configuration file of the build, relative to the copy.
    jobs : int, default 2
        Snakemake's ``-j``.
    change_key : str, default "intermittent.two_sensor.check_offset"
        Dotted configuration key multiplied by ``change_factor`` before the single-figure rerun.
    change_factor : float, default 0.5
        The factor.
    figure_target : str, default "intermittent_fig5"
        Snakemake target rebuilt after the change.
    keep : bool, default False
        Keep the scratch copy.

    Returns
    -------
    rows : list of dict
        :func:`BenchRow` rows (times against their budgets of 600 s, 5 s, 30 s; peak memory; the
        three slowest jobs against their steps' compute time).
    info : dict
        Scratch location, log, return codes, per-job times, the parameter change.
    """
    base = Path(tempfile.mkdtemp(prefix="netrepro-bench-", dir=scratch))
    work = base / "repo"
    shutil.copytree(ROOT, work, ignore=_IGNORE)
    for d in ("report", "figures"):
        (work / d).mkdir(exist_ok=True)
    log = base / "snakemake.log"
    env = _env_with_src(work / "src")
    common = [f"-j{jobs}", "--configfile", config]  # targets go first: --configfile takes several values
    info = {"scratch": str(work), "log": str(log), "config": config}
    rows = []
    cold, rc, maxrss_kb, tree_kb = _snakemake(work, ["report", *common], env, log, memory=True)
    info["cold_returncode"] = rc
    if rc != 0:
        info["error"] = f"cold build failed (exit {rc}); see {log}"
        tail = log.read_text()[-3000:]
        info["log_tail"] = tail
        rows.append(BenchRow("pipeline", "cold_report_s", np.nan, 600.0, np.nan, "s"))
        return rows, info
    rows.append(BenchRow("pipeline", "cold_report_s", cold, 600.0, 600.0 / cold, "s"))
    rows.append(BenchRow("pipeline", "peak_rss_largest_process_mb", maxrss_kb / 1024, np.nan, np.nan, "MB"))
    rows.append(BenchRow("pipeline", "peak_rss_process_tree_mb", tree_kb / 1024, 24 * 1024, _div(24 * 1024, tree_kb / 1024),
                         "MB"))
    jobs_df = _job_times(work)
    info["jobs"] = jobs_df.to_dict(orient="records")
    for rec in jobs_df.head(3).itertuples():
        rows.append(BenchRow(f"pipeline_rule:{rec.rule}", "job_s_vs_step_compute_s", rec.job_s, rec.step_s,
                             _div(rec.step_s, rec.job_s), "s"))
    noop, rc, _, _ = _snakemake(work, ["report", *common], env, log)
    rows.append(BenchRow("pipeline", "noop_rerun_s", noop if rc == 0 else np.nan, 5.0, _div(5.0, noop), "s"))
    old, new = _set_config_value(work / config, change_key, change_factor)
    info["parameter_change"] = {"key": change_key, "old": old, "new": new, "target": figure_target}
    dry = subprocess.run([sys.executable, "-m", "snakemake", "--profile", "workflow/profiles/default", figure_target,
                          "-n", *common], cwd=work, env=env, capture_output=True, text=True)
    info["parameter_change"]["dry_run_tail"] = dry.stdout[-1500:]
    single, rc, _, _ = _snakemake(work, [figure_target, *common], env, log)
    rows.append(BenchRow("pipeline", "single_figure_rerun_s", single if rc == 0 else np.nan, 30.0, _div(30.0, single),
                         "s"))
    if not keep:
        shutil.rmtree(base, ignore_errors=True)
        info["scratch"] = "(removed)"
    return rows, info


# ============================================================================ driver
SIZES = {
    "full": dict(riccati=(131072, 200, 40), channels=(131072, 200, 200), lmi=(20, 51, 1e-5), fisher=(-40.0, 40.0, 0.25),
                 repeats=5, peak_size=2048, exact_mean=(400000, 60), grid=(500, 400), gainsched=(4000,),
                 markov=(21,)),
    "quick": dict(riccati=(4096, 20, 4), channels=(4096, 20, 20), lmi=(3, 5, 1e-3), fisher=(-40.0, 40.0, 10.0),
                  repeats=2, peak_size=256, exact_mean=(20000, 60), grid=(20, 60), gainsched=(4000,),
                  markov=(10,)),
}


def _progress(msg):
    print(f"[bench {time.strftime('%H:%M:%S')}] {msg}", file=sys.stderr, flush=True)


def run_all(quick: bool = False, pipeline: bool = True, scratch: Path | None = None, keep_scratch: bool = False,
            only=None) -> tuple[pd.DataFrame, dict]:
    """Every benchmark in one run; returns the table and the sidecar information.

    Parameters
    ----------
    quick : bool, default False
        Small sizes (``SIZES["quick"]``) and no pipeline benchmark.
    pipeline : bool, default True
        Run :func:`bench_pipeline` (never with ``quick``).
    scratch : Path, optional
        Folder of the pipeline's scratch copy.
    keep_scratch : bool, default False
        Keep the pipeline's scratch copy.
    only : set of str, optional
        Benchmarks to run (riccati, channels, lmi, fisher, exact_mean, gainsched, markov, grid,
        job_exit, pipeline); default all. The BLAS peak is always measured.

    Returns
    -------
    table : pandas.DataFrame
        One row per measurement, columns ``COLUMNS``.
    info : dict
        Machine, versions, sizes, load averages, BLAS peaks and the benchmarks' extra information.
    """
    sizes = SIZES["quick" if quick else "full"]
    reps = sizes["repeats"]
    info = {"quick": quick, "python": sys.version.split()[0], "numpy": np.__version__,
            "machine": platform.platform(), "cpu_count": os.cpu_count(), "sizes": sizes,
            "loadavg_start": os.getloadavg(), "blas_in_process": _blas_info(),
            "env": {k: os.environ.get(k) for k in ("OPENBLAS_CORETYPE", "OPENBLAS_L2_SIZE", "OMP_NUM_THREADS")}}
    want = (lambda name: only is None or name in only)
    rows = []
    _progress(f"peak: large matrix products ({sizes['peak_size']}^2), native kernel and as configured")
    peak = blas_peak(native=True, size=sizes["peak_size"], repeats=reps)
    forced = blas_peak(native=False, size=sizes["peak_size"], repeats=reps)
    info["peak_native"], info["peak_as_configured"] = peak, forced
    peak1 = peak.get("gflops_1_thread", peak["gflops_all_threads"])
    rows.append(BenchRow("blas_peak", "gemm_1_thread", peak1, forced.get("gflops_1_thread", np.nan),
                         _div(peak1, forced.get("gflops_1_thread", np.nan)), "Gflop/s (native kernel vs as configured)"))
    rows.append(BenchRow("blas_peak", "gemm_all_threads", peak["gflops_all_threads"], forced["gflops_all_threads"],
                         _div(peak["gflops_all_threads"], forced["gflops_all_threads"]),
                         "Gflop/s (native kernel vs as configured)"))
    if want("riccati"):
        _progress("riccati: batched covariance recursions vs per-path loop")
        bench_riccati(*sizes["riccati"], reps, peak1, rows_out=rows)
    if want("channels"):
        _progress("channels: Gilbert-Elliott sampling")
        rows += bench_channels(*sizes["channels"], reps)
    if want("lmi"):
        _progress("lmi: parametrised sweep vs rebuild; solves per bisection curve")
        rows += bench_lmi(*sizes["lmi"], repeats=max(1, reps // 2 if not quick else 1))
    if want("fisher"):
        _progress("fisher: vectorised expected 1-bit Fisher information vs adaptive quadrature")
        fisher_rows, info["fisher_source"] = bench_fisher(*sizes["fisher"], reps)
        rows += fisher_rows
    if want("exact_mean"):
        _progress("exact_mean: exact E(p_k) vs the conditional Monte Carlo estimator")
        rows += bench_exact_mean(*sizes["exact_mean"], reps)
    if want("gainsched"):
        _progress("gainsched: exact second-moment recursion vs Monte Carlo")
        rows += bench_gainsched_moments(*sizes["gainsched"], reps)
    if want("markov"):
        _progress("markov: exact E||P_k|| by the block-split tree vs the full-matrix tree")
        rows += bench_markov_exact(*sizes["markov"], reps)
    if want("grid"):
        _progress("grid: onebit grid filter/smoother, banded vs dense transition, compiled vs numpy banded")
        rows += bench_grid_transition(*sizes["grid"], reps)
    if want("job_exit"):
        _progress("job_exit: one job process ending without the interpreter's teardown vs the normal exit")
        rows += bench_job_exit(reps)
    if pipeline and not quick and want("pipeline"):
        _progress("pipeline: cold snakemake -j2 report in a scratch copy, no-op rerun, one figure after a change")
        pipe_rows, info["pipeline"] = bench_pipeline(scratch=scratch, keep=keep_scratch)
        rows += pipe_rows
    info["loadavg_end"] = os.getloadavg()
    return pd.DataFrame(rows, columns=COLUMNS), info


def main(argv=None) -> int:
    """``python -m netrepro bench``: run the benchmarks and write the table and its ``.meta.json``.

    Parameters
    ----------
    argv : list of str, optional
        Command-line arguments (default ``sys.argv[1:]``).

    Returns
    -------
    int
        Exit status 0.
    """
    parser = argparse.ArgumentParser(prog="python -m netrepro bench", description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="results/benchmarks.csv", help="CSV to write (plus <out>.meta.json)")
    parser.add_argument("--quick", action="store_true", help="small sizes, no pipeline benchmark (seconds)")
    parser.add_argument("--no-pipeline", action="store_true", help="skip the whole-pipeline benchmark")
    parser.add_argument("--only", default=None,
                        help="comma-separated subset of riccati,channels,lmi,fisher,exact_mean,gainsched,markov,"
                             "grid,job_exit,pipeline")
    parser.add_argument("--scratch", default=None, help="folder for the pipeline's scratch copy (default: tmp)")
    parser.add_argument("--keep-scratch", action="store_true", help="keep the pipeline's scratch copy")
    args = parser.parse_args(argv)
    only = set(args.only.split(",")) if args.only else None
    table, info = run_all(quick=args.quick, pipeline=not args.no_pipeline,
                          scratch=Path(args.scratch) if args.scratch else None, keep_scratch=args.keep_scratch,
                          only=only)
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = out.with_name(out.name + ".tmp")
    table.to_csv(tmp, index=False, float_format="%.6g")
    tmp.replace(out)
    Path(str(out) + ".meta.json").write_text(json.dumps(info, indent=2, sort_keys=True, default=str))
    with pd.option_context("display.width", 200, "display.max_rows", 200):
        print(table.to_string(index=False))
    return 0


if __name__ == "__main__":
    sys.exit(main())
