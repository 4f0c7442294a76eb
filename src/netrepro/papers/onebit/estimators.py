"""Estimators beyond the paper: simulation of the model, the grid (point-mass) 1-bit filter and
smoother, and the unquantized Kalman filter / RTS smoother, all vectorised over runs.

The model is the random walk (21) observed through (20) (unquantized) or (28) (1-bit).
"""

from __future__ import annotations

import math

import numpy as np
from scipy import sparse
from scipy.special import ndtr

from ...errors import InputError
from .model import stationary_variance

__all__ = [
    "downward_roots",
    "simulate_block",
    "grid_filter_smoother",
    "kalman_rts",
    "state_grid",
    "transition_matrix",
    "grid_smoother_at",
    "window_mse",
    "paired_ratio_interval",
    "paired_ratio_intervals",
    "db_zero_crossing",
    "bootstrap_ratio_db",
    "downward_root",
    "local_crossing_fit",
    "run_tail_statistics",
    "pooled_se_ratio",
    "paired_db_contrasts",
    "replicate_coverage",
    "binomial_coverage",
]


def simulate_block(rng, n_runs: int, horizon: int, eps: float, sigma_z2: float, sigma_eta: float):
    """Stationary random-walk paths (21), unquantized (20) and 1-bit (28) measurements.

    ``theta_0 ~ N(0, sigma_theta_inf^2)`` (stationary start). Returns
    ``theta`` (n, horizon+1), ``y`` and ``r`` (n, horizon) for k = 1..horizon.

    Parameters
    ----------
    rng : numpy.random.Generator
        Random source.
    n_runs, horizon : int
        Runs and steps K.
    eps : float
        ``1 - alpha`` of the random walk (21).
    sigma_z2 : float
        Transition noise variance.
    sigma_eta : float
        Measurement noise standard deviation.

    Returns
    -------
    theta : ndarray (n_runs, horizon+1)
        States, k = 0..K.
    y, r : ndarray (n_runs, horizon)
        Unquantized measurements (20) and their signs (28), k = 1..K, from one noise draw.
    """
    alpha = 1.0 - eps
    sd_inf = math.sqrt(float(stationary_variance(eps, sigma_z2)))
    th = np.empty((horizon + 1, n_runs))           # step-major: each step updates one contiguous row
    th[0] = sd_inf * rng.standard_normal(n_runs)
    zT = np.ascontiguousarray((math.sqrt(sigma_z2) * rng.standard_normal((n_runs, horizon))).T)
    for k in range(horizon):
        np.add(alpha * th[k], zT[k], out=th[k + 1])
    theta = np.ascontiguousarray(th.T)
    y = theta[:, 1:] + sigma_eta * rng.standard_normal((n_runs, horizon))
    return theta, y, np.where(y >= 0, 1.0, -1.0)


def grid_filter_smoother(r, eps: float, sigma_z2: float, sigma_eta: float, grid_half_width: float = 6.0,
                         points_per_sigma_z: float = 1.5, quantized: bool = True):
    r"""Conditional means :math:`E[\theta_k|r_{1:k}]` and :math:`E[\theta_k|r_{1:K}]` on a grid, vectorised over runs.

    The point-mass approximation of the exact Bayesian recursions
    (Chapman-Kolmogorov + Bayes, forward; backward messages
    :math:`\beta_{k-1} = \sum p(\theta_k|\theta_{k-1}) p(r_k|\theta_k)\beta_k`),
    with :math:`p(r|\theta) = \Phi(r\theta/\sigma_\eta)`. The grid spans
    ``grid_half_width`` stationary standard deviations with spacing
    ``sigma_z / points_per_sigma_z``, so the discretised Gaussian transition
    keeps its first two moments to ~exp(-2 pi^2 points^2) (Poisson summation).

    Parameters
    ----------
    r : ndarray (n_runs, K)
        1-bit measurements (+-1) at k = 1..K, or, with ``quantized=False``,
        unquantized measurements (20) (Gaussian likelihood; the grid then
        reproduces the Kalman filter / RTS smoother, which tests the grid).
    eps : float
        ``1 - alpha``.
    sigma_z2 : float
        Transition noise variance.
    sigma_eta : float
        Measurement noise standard deviation.
    grid_half_width, points_per_sigma_z : float
        Grid, see :func:`state_grid`.
    quantized : bool
        1-bit (28) or Gaussian (20) likelihood.

    Returns
    -------
    filt, smooth : ndarray (n_runs, K+1)
        Estimates for k = 0..K (k = 0: prior mean, smoothed).

    Notes
    -----
    :func:`grid_smoother_at` at every step with the dense transition (small problems, tests).
    """
    K = np.asarray(r).shape[1]
    return grid_smoother_at(r, eps, sigma_z2, sigma_eta, np.arange(K + 1), grid_half_width, points_per_sigma_z,
                            band_sigmas=None, quantized=quantized)


def kalman_rts(y, eps, sigma_z2, sigma_eta):
    """Scalar Kalman filter and RTS smoother means (unquantized reference), compiled loops over runs and steps.

    Parameters
    ----------
    y : ndarray (n_runs, K)
        Unquantized measurements (20).
    eps : float
        ``1 - alpha`` of the random walk (21).
    sigma_z2 : float
        Transition noise variance.
    sigma_eta : float
        Measurement noise standard deviation.

    Returns
    -------
    mf, ms : ndarray (n_runs, K+1)
        Filtered and smoothed means, k = 0..K, started from the stationary prior.
    """
    from .kernels import kalman_rts_recursions  # numba: imported by the steps that run the filter

    alpha = 1.0 - eps
    y = np.ascontiguousarray(y, dtype=float)
    n, K = y.shape
    mf, ms = np.empty((n, K + 1)), np.empty((n, K + 1))
    kalman_rts_recursions(y, alpha, alpha**2, float(stationary_variance(eps, sigma_z2)), sigma_z2, sigma_eta**2,
                          mf, ms, np.empty((5, K + 1)))
    return mf, ms


def _kalman_rts_numpy(y, eps, sigma_z2, sigma_eta):
    """:func:`kalman_rts` as a numpy loop over steps (the reference of the compiled recursions)."""
    alpha = 1.0 - eps
    n, K = y.shape
    P = float(stationary_variance(eps, sigma_z2))
    m = np.zeros(n)
    yT = np.ascontiguousarray(np.asarray(y).T)     # step-major: each step works on contiguous rows
    mf, Pf, mp, Pp = np.zeros((K + 1, n)), np.zeros(K + 1), np.zeros((K + 1, n)), np.zeros(K + 1)
    Pf[0] = P
    for k in range(1, K + 1):
        mpk, Ppk = alpha * m, alpha**2 * P + sigma_z2
        G = Ppk / (Ppk + sigma_eta**2)
        m, P = mpk + G * (yT[k - 1] - mpk), (1 - G) * Ppk
        mp[k], Pp[k], mf[k], Pf[k] = mpk, Ppk, m, P
    ms = mf.copy()
    for k in range(K - 1, -1, -1):
        C = Pf[k] * alpha / Pp[k + 1]
        ms[k] = mf[k] + C * (ms[k + 1] - mp[k + 1])
    return np.ascontiguousarray(mf.T), np.ascontiguousarray(ms.T)


# ============================================================================ banded grid smoother (issue 17)
def state_grid(eps: float, sigma_z2: float, grid_half_width: float = 6.0, points_per_sigma_z: float = 1.0):
    r"""The uniform grid of the point-mass filter: ``grid_half_width`` stationary standard deviations (33).

    Parameters
    ----------
    eps : float
        ``1 - alpha``.
    sigma_z2 : float
        Transition noise variance of (21).
    grid_half_width : float
        Half width in units of :math:`\sigma_{\theta,\infty}`.
    points_per_sigma_z : float
        Grid points per :math:`\sigma_z` (the spacing is ``sigma_z / points_per_sigma_z``).

    Returns
    -------
    ndarray
        Symmetric grid ``x`` with an odd number of points, ``x[n//2] = 0``.
    """
    sd_inf = math.sqrt(float(stationary_variance(eps, sigma_z2)))
    sz = math.sqrt(sigma_z2)
    n_half = int(math.ceil(grid_half_width * sd_inf / (sz / points_per_sigma_z)))
    return np.linspace(-grid_half_width * sd_inf, grid_half_width * sd_inf, 2 * n_half + 1)


def transition_matrix(x, alpha: float, sigma_z: float, band_sigmas: float | None = None):
    r"""Row-normalised transition of (21) on the grid: :math:`T_{ji} \propto \exp(-(x_i - \alpha x_j)^2 / 2\sigma_z^2)`.

    Row ``j`` is :math:`p(\theta_k = x_i | \theta_{k-1} = x_j)`. With ``band_sigmas`` only the entries
    with :math:`|x_i - \alpha x_j| \le` ``band_sigmas`` :math:`\sigma_z` are kept (a band of about
    ``2 band_sigmas points_per_sigma_z + 1`` entries per row) and the matrix is sparse (CSR); the
    dropped Gaussian mass is below ``exp(-band_sigmas^2 / 2)`` per row before renormalisation.

    Parameters
    ----------
    x : ndarray (n,)
        Uniform grid.
    alpha : float
        Transition coefficient of (21).
    sigma_z : float
        Transition noise standard deviation.
    band_sigmas : float, optional
        Band half width in units of ``sigma_z``; ``None`` gives the dense matrix.

    Returns
    -------
    ndarray (n, n) or scipy.sparse.csr_matrix
        The transition, rows summing to one.

    Raises
    ------
    InputError
        If the grid is not uniform or ``band_sigmas`` is not positive.
    """
    x = np.asarray(x, dtype=float)
    if band_sigmas is None:
        T = np.exp(-0.5 * ((x[None, :] - alpha * x[:, None]) / sigma_z) ** 2)
        return T / T.sum(axis=1, keepdims=True)
    if band_sigmas <= 0:
        raise InputError(f"band_sigmas must be positive, got {band_sigmas}")
    h = x[1] - x[0]
    if not np.allclose(np.diff(x), h, rtol=1e-9, atol=0):
        raise InputError("transition_matrix: the grid x must be uniform")
    n = len(x)
    m = int(math.ceil(band_sigmas * sigma_z / h)) + 1
    centre = np.rint((alpha * x - x[0]) / h).astype(np.int64)
    rows = np.repeat(np.arange(n), 2 * m + 1)
    cols = (centre[:, None] + np.arange(-m, m + 1)[None, :]).ravel()
    d = (x[np.clip(cols, 0, n - 1)] - alpha * x[rows]) / sigma_z
    keep = (cols >= 0) & (cols < n) & (np.abs(d) <= band_sigmas)
    rows, cols, d = rows[keep], cols[keep], d[keep]
    vals = np.exp(-0.5 * d * d)
    vals /= np.bincount(rows, weights=vals, minlength=n)[rows]
    return sparse.csr_matrix((vals, (rows, cols)), shape=(n, n))


def grid_smoother_at(r, eps: float, sigma_z2: float, sigma_eta: float, eval_idx, grid_half_width: float = 6.0,
                     points_per_sigma_z: float = 1.0, band_sigmas: float | None = 8.0, quantized: bool = True):
    r"""Grid filter and smoother means at selected steps only (memory ``len(eval_idx) x grid x runs``).

    The same point-mass recursions as :func:`grid_filter_smoother` (forward: Chapman-Kolmogorov
    with the transition (21) and Bayes with :math:`p(r|\theta) = \Phi(r\theta/\sigma_\eta)`, (28);
    backward: :math:`\beta_{k-1} = T(p(r_k|\cdot)\beta_k)`), started from the stationary prior
    :math:`N(0, \sigma^2_{\theta,\infty})`, with the banded transition of
    :func:`transition_matrix` (or the dense one, ``band_sigmas=None``). Arrays are laid out
    grid-major ``(n_grid, n_runs)`` so that each step is one sparse-times-dense product.

    Parameters
    ----------
    r : ndarray (n_runs, K)
        1-bit measurements (+-1) at k = 1..K, or unquantized ones (20) with ``quantized=False``.
    eps : float
        ``1 - alpha``.
    sigma_z2 : float
        Transition noise variance.
    sigma_eta : float
        Measurement noise standard deviation.
    eval_idx : array_like of int
        Steps ``k`` in ``0..K`` at which the estimates are returned (sorted, unique).
    grid_half_width, points_per_sigma_z : float
        Grid, see :func:`state_grid`.
    band_sigmas : float or None
        Band of the transition, see :func:`transition_matrix`.
    quantized : bool
        1-bit (28) or Gaussian (20) likelihood.

    Returns
    -------
    filt, smooth : ndarray (n_runs, len(eval_idx))
        :math:`E[\theta_k | r_{1:k}]` and :math:`E[\theta_k | r_{1:K}]` at ``eval_idx``.

    Raises
    ------
    InputError
        If ``eval_idx`` is not sorted, unique and within ``0..K``.
    """
    r = np.asarray(r, dtype=float)
    n, K = r.shape
    ev = np.asarray(eval_idx, dtype=np.int64)
    if ev.ndim != 1 or len(ev) == 0 or np.any(np.diff(ev) <= 0) or ev[0] < 0 or ev[-1] > K:
        raise InputError(f"eval_idx must be sorted, unique and within 0..{K}")
    if quantized and band_sigmas is not None:
        return _grid_smoother_banded_1bit(r, eps, sigma_z2, sigma_eta, ev, grid_half_width, points_per_sigma_z,
                                          band_sigmas)
    return _grid_smoother_at_numpy(r, eps, sigma_z2, sigma_eta, ev, grid_half_width, points_per_sigma_z,
                                   band_sigmas, quantized)


def _grid_model(eps, sigma_z2, sigma_eta, grid_half_width, points_per_sigma_z, band_sigmas):
    """Grid, transition (21), likelihood of r = +1 (28) and normalised stationary prior of the grid recursions."""
    x = state_grid(eps, sigma_z2, grid_half_width, points_per_sigma_z)
    T = transition_matrix(x, 1.0 - eps, math.sqrt(sigma_z2), band_sigmas)
    sd_inf = math.sqrt(float(stationary_variance(eps, sigma_z2)))
    prior = np.exp(-0.5 * (x / sd_inf) ** 2)
    prior /= prior.sum()
    return x, T, ndtr(x / sigma_eta), prior


def _grid_smoother_banded_1bit(r, eps, sigma_z2, sigma_eta, ev, grid_half_width, points_per_sigma_z, band_sigmas):
    """:func:`grid_smoother_at` for 1-bit data and a banded transition: the recursions in one compiled kernel.

    Same operations in the same order as :func:`_grid_smoother_at_numpy` (bit-identical); the kernel
    returns the filtered masses and backward messages at the evaluation steps, the means are formed here.
    """
    from .kernels import band_forward_backward  # numba: imported by the steps that run the smoother

    n, K = r.shape
    x, T, lik_pos, prior = _grid_model(eps, sigma_z2, sigma_eta, grid_half_width, points_per_sigma_z, band_sigmas)
    TT = T.T.tocsr()
    slot = np.full(K + 1, -1, dtype=np.int64)
    slot[ev] = np.arange(len(ev))
    stored = np.empty((len(ev), len(x), n))
    betas = np.empty((len(ev), len(x), n))
    band_forward_backward(TT.indptr, TT.indices, TT.data, T.indptr, T.indices, T.data, lik_pos, 1.0 - lik_pos,
                          r.T > 0, prior, slot, int(ev[0]), stored, betas)
    filt = np.empty((n, len(ev)))
    smooth = np.empty((n, len(ev)))
    for i, k in enumerate(ev):
        filt[:, i] = x @ stored[i]
        if k == K:
            smooth[:, i] = filt[:, i]
        else:
            g = stored[i] * betas[i]
            smooth[:, i] = (x @ g) / g.sum(axis=0)
    return filt, smooth


def _grid_smoother_at_numpy(r, eps, sigma_z2, sigma_eta, ev, grid_half_width, points_per_sigma_z, band_sigmas,
                            quantized):
    """:func:`grid_smoother_at` in numpy/scipy (the reference; dense or unquantized cases)."""
    n, K = r.shape
    x, T, lik_pos, prior = _grid_model(eps, sigma_z2, sigma_eta, grid_half_width, points_per_sigma_z, band_sigmas)
    TT = T.T.tocsr() if sparse.issparse(T) else np.ascontiguousarray(T.T)
    lik_pos = lik_pos[:, None]
    rT = np.ascontiguousarray(r.T)

    def likelihood(k):  # p(r_{k+1} | x), (n_grid, n_runs)
        if quantized:
            return np.where(rT[k] > 0, lik_pos, 1.0 - lik_pos)
        return np.exp(-0.5 * ((rT[k][None, :] - x[:, None]) / sigma_eta) ** 2)

    post = np.repeat(prior[:, None], n, axis=1)
    slot = {int(k): i for i, k in enumerate(ev)}
    stored = np.empty((len(ev), len(x), n))
    filt = np.empty((n, len(ev)))
    if 0 in slot:
        stored[0] = post
        filt[:, 0] = x @ post
    for k in range(K):
        p = (TT @ post) * likelihood(k)
        post = p / p.sum(axis=0)
        if k + 1 in slot:
            i = slot[k + 1]
            stored[i] = post
            filt[:, i] = x @ post
    smooth = np.empty((n, len(ev)))
    beta = np.ones((len(x), n))
    if K in slot:
        smooth[:, slot[K]] = filt[:, slot[K]]
    for k in range(K, int(ev[0]), -1):
        beta = T @ (beta * likelihood(k - 1))
        beta /= beta.sum(axis=0)
        if k - 1 in slot:
            i = slot[k - 1]
            g = stored[i] * beta
            smooth[:, i] = (x @ g) / g.sum(axis=0)
    return filt, smooth


def window_mse(estimates, theta):
    r"""Per-run mean squared error over the evaluation steps.

    Parameters
    ----------
    estimates, theta : ndarray (n_runs, E)
        Estimates and true states at the same ``E`` evaluation steps.

    Returns
    -------
    ndarray (n_runs,)
        :math:`E^{-1}\sum_e (\hat\theta_e - \theta_e)^2` per run.
    """
    return np.mean((np.asarray(estimates) - np.asarray(theta)) ** 2, axis=1)


def paired_ratio_interval(num, den, n_boot: int, seed: int, level: float = 0.95):
    r"""Ratio of mean MSEs in dB with a paired percentile bootstrap interval.

    The estimate is :math:`10\log_{10}(\bar a / \bar b)` for per-run values ``a = num``, ``b = den``
    from the *same* runs (same states and noise). Each bootstrap replicate resamples runs with
    replacement and uses the same run indices for ``a`` and ``b``, so the interval reflects the
    variance of the paired difference, not of each mean alone.

    Parameters
    ----------
    num, den : ndarray (n_runs,)
        Per-run values of the numerator and denominator estimators (paired by run).
    n_boot : int
        Bootstrap replicates.
    seed : int
        Seed of the resampling generator.
    level : float
        Coverage of the percentile interval.

    Returns
    -------
    tuple of float
        ``(estimate_db, lo_db, hi_db)``.

    Raises
    ------
    InputError
        If ``num`` and ``den`` differ in length or are empty.
    """
    a, b = np.asarray(num, dtype=float), np.asarray(den, dtype=float)
    if a.shape != b.shape or a.ndim != 1 or len(a) == 0:
        raise InputError(f"num and den must be 1-D of the same length, got {a.shape} and {b.shape}")
    n = len(a)
    rng = np.random.default_rng(seed)
    idx = rng.integers(0, n, size=(n_boot, n))
    # one plain gather, not _bootstrap_means: this single-pair form is the independent computation
    # that paired_ratio_intervals (blocked gathers, shared resampling) is tested against
    ratio = a[idx].mean(axis=1) / b[idx].mean(axis=1)
    q = 100.0 * (1.0 - level) / 2.0
    lo, hi = np.percentile(10.0 * np.log10(ratio), [q, 100.0 - q])
    return float(10.0 * np.log10(a.mean() / b.mean())), float(lo), float(hi)


def _bootstrap_means(arrs, idx, block: int = 64):
    """``{k: a[idx].mean(axis=1)}`` computed by blocks of replicates (rows of ``idx``).

    Each block's gathered values stay in cache; the row means are the same numbers as those of
    one big gather (each row is reduced on its own).
    """
    boot = {k: np.empty(len(idx)) for k in arrs}
    for r0 in range(0, len(idx), block):
        rows = idx[r0:r0 + block]
        for k, a in arrs.items():
            boot[k][r0:r0 + len(rows)] = a[rows].mean(axis=1)
    return boot


def paired_ratio_intervals(values, pairs, n_boot: int, seed: int, level: float = 0.95, replicates: bool = False):
    r""":func:`paired_ratio_interval` for several ``(num, den)`` pairs of the same runs and seed, resampled once.

    Every pair gets exactly what ``paired_ratio_interval(values[num], values[den], n_boot, seed, level)``
    returns (the same resampled run indices, the same bootstrap means); the indices and each
    estimator's bootstrap means are computed once instead of once per pair.

    Parameters
    ----------
    values : dict of ndarray (n_runs,)
        Per-run values of each estimator (paired by run).
    pairs : sequence of tuple of str
        ``(num, den)`` keys of ``values``.
    n_boot : int
        Bootstrap replicates.
    seed : int
        Seed of the resampling generator.
    level : float
        Coverage of the percentile interval.
    replicates : bool
        Also return each pair's bootstrap replicates in dB, ``10 log10(mean a* / mean b*)``: the same
        numbers as ``bootstrap_ratio_db(values[num], values[den], n_boot, seed)`` (the same generator and
        seed draw the same run indices, whatever the chunking: bounded 32-bit integers are drawn one by
        one; each replicate's means are reduced row by row).

    Returns
    -------
    list of tuple of float
        ``(estimate_db, lo_db, hi_db)`` per pair.
    list of ndarray (n_boot,)
        With ``replicates``: the replicates in dB, per pair.

    Raises
    ------
    InputError
        If the values differ in length or are empty.
    """
    arrs = {k: np.asarray(values[k], dtype=float) for pair in pairs for k in pair}
    shapes = {a.shape for a in arrs.values()}
    if len(shapes) != 1 or next(iter(shapes)) == (0,) or len(next(iter(shapes))) != 1:
        raise InputError(f"values must be 1-D of the same length, got {sorted(shapes)}")
    n = len(next(iter(arrs.values())))
    rng = np.random.default_rng(seed)
    idx = rng.integers(0, n, size=(n_boot, n))
    boot = _bootstrap_means(arrs, idx)
    q = 100.0 * (1.0 - level) / 2.0
    out, reps = [], []
    for num, den in pairs:
        a, b = arrs[num], arrs[den]
        rep = 10.0 * np.log10(boot[num] / boot[den])
        lo, hi = np.percentile(rep, [q, 100.0 - q])
        out.append((float(10.0 * np.log10(a.mean() / b.mean())), float(lo), float(hi)))
        reps.append(rep)
    return (out, reps) if replicates else out


def db_zero_crossing(x, y) -> float:
    r"""First downward crossing of 0 by ``y(x)``, linearly interpolated between grid points.

    Parameters
    ----------
    x : array_like
        Increasing abscissae (SNR in dB).
    y : array_like
        Values (dB) at ``x``.

    Returns
    -------
    float
        The ``x`` at which ``y`` first goes from > 0 to <= 0; NaN if it does not on the grid.
    """
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    for i in range(len(x) - 1):
        if y[i] > 0 >= y[i + 1]:
            return float(x[i] + (x[i + 1] - x[i]) * y[i] / (y[i] - y[i + 1]))
    return float("nan")


def bootstrap_ratio_db(num, den, n_boot: int, seed: int, chunk: int = 250):
    r"""Paired bootstrap replicates of :math:`10\log_{10}(\bar a / \bar b)` over runs.

    Each replicate resamples the runs with replacement and uses the same run indices for ``a = num``
    and ``b = den`` (as :func:`paired_ratio_interval`). The indices are drawn ``chunk`` replicates
    at a time (bounded memory for many runs); the stream is fixed by ``seed`` and ``chunk``.

    Parameters
    ----------
    num, den : ndarray (n_runs,)
        Per-run values, paired by run.
    n_boot : int
        Replicates.
    seed : int
        Seed of the resampling generator.
    chunk : int
        Replicates per draw of indices.

    Returns
    -------
    ndarray (n_boot,)
        The replicates in dB.

    Raises
    ------
    InputError
        If ``num`` and ``den`` differ in length or are empty.
    """
    a, b = np.asarray(num, dtype=float), np.asarray(den, dtype=float)
    if a.shape != b.shape or a.ndim != 1 or len(a) == 0:
        raise InputError(f"num and den must be 1-D of the same length, got {a.shape} and {b.shape}")
    n = len(a)
    rng = np.random.default_rng(seed)
    out = np.empty(n_boot)
    for r0 in range(0, n_boot, chunk):
        idx = rng.integers(0, n, size=(min(chunk, n_boot - r0), n))
        out[r0:r0 + len(idx)] = 10.0 * np.log10(a[idx].mean(axis=1) / b[idx].mean(axis=1))
    return out


def downward_root(coefs, lo: float, hi: float) -> float:
    """The smallest root in ``[lo, hi]`` of the polynomial ``coefs`` (highest power first) where it decreases.

    Parameters
    ----------
    coefs : array_like
        Polynomial coefficients, highest power first (as :func:`numpy.polyfit`).
    lo, hi : float
        The window.

    Returns
    -------
    float
        The root, NaN if the polynomial does not cross 0 downwards inside the window.
    """
    p = np.poly1d(np.asarray(coefs, dtype=float))
    dp = p.deriv()
    roots = [float(r.real) for r in np.atleast_1d(p.roots) if abs(r.imag) <= 1e-12 * max(1.0, abs(r.real))]
    ok = sorted(r for r in roots if lo <= r <= hi and dp(r) < 0)
    return ok[0] if ok else float("nan")


def downward_roots(coefs, lo: float, hi: float) -> np.ndarray:
    """:func:`downward_root` of each row of ``coefs``, the same numbers, the polynomials' roots in one batch.

    For a row without leading or trailing zero coefficients (all finite) the roots are the eigenvalues of
    its companion matrix, as :func:`numpy.roots` computes them (``eigvals`` of a stack runs the same LAPACK
    routine matrix by matrix); the derivative is evaluated by Horner's rule as :func:`numpy.polyval` does.
    Other rows go through :func:`downward_root` itself.

    Parameters
    ----------
    coefs : array_like (n, d + 1)
        Polynomial coefficients per row, highest power first.
    lo, hi : float
        The window.

    Returns
    -------
    ndarray (n,)
        Per row the smallest root in ``[lo, hi]`` where the polynomial decreases, NaN if none.
    """
    c = np.atleast_2d(np.asarray(coefs, dtype=float))
    n, d = c.shape[0], c.shape[1] - 1
    out = np.full(n, np.nan)
    plain = np.all(np.isfinite(c), -1) & (c[:, 0] != 0) & (c[:, -1] != 0) if d >= 1 else np.zeros(n, dtype=bool)
    for i in np.nonzero(~plain)[0]:
        out[i] = downward_root(c[i], lo, hi)
    rows = np.nonzero(plain)[0]
    if len(rows) == 0:
        return out
    cp = c[rows]
    A = np.zeros((len(rows), d, d))
    if d > 1:
        A[:, np.arange(1, d), np.arange(d - 1)] = 1.0
    A[:, 0, :] = -cp[:, 1:] / cp[:, :1]
    roots = np.linalg.eigvals(A)                           # (m, d)
    re, im = roots.real, roots.imag
    real = np.abs(im) <= 1e-12 * np.maximum(1.0, np.abs(re))
    dcoef = cp[:, :-1] * np.arange(d, 0, -1)               # numpy.polyder
    y = np.zeros_like(re)
    for j in range(d):                                     # numpy.polyval: y = y * x + p_j
        y = y * re + dcoef[:, j:j + 1]
    ok = real & (lo <= re) & (re <= hi) & (y < 0)
    best = np.where(ok, re, np.inf).min(-1)
    out[rows] = np.where(np.isfinite(best), best, np.nan)
    return out


def local_crossing_fit(x, y, y_boot, degree: int = 2, level: float = 0.95) -> dict:
    r"""Where a curve known at a few points crosses 0 downwards: a local polynomial fit with a bootstrap interval.

    The points ``(x_i, y_i)`` (e.g. the achievable :math:`\rho_S` in dB at SNRs around its
    crossing) are fitted by least squares with a polynomial of degree ``degree``; the crossing is
    its downward root inside ``[min x, max x]`` (:func:`downward_root`). The interval refits every
    bootstrap replicate (row of ``y_boot``: the curve recomputed from runs resampled independently
    at each point) and takes percentiles of the replicate roots. Replicates whose fit has no root
    in the window are counted in ``fail_frac``; they are placed beyond the window on the side
    their fit lies on (all above 0: right end; all below: left end), so the percentiles (order statistics) stay
    those of all replicates.

    Parameters
    ----------
    x : array_like (m,)
        Abscissae, ``m > degree``.
    y : array_like (m,)
        Values at ``x``.
    y_boot : array_like (n_boot, m)
        Bootstrap replicates of ``y``.
    degree : int
        Degree of the local fit.
    level : float
        Coverage of the percentile interval.

    Returns
    -------
    dict
        ``estimate, lo, hi`` (float), ``fail_frac`` (float), ``residual_rms`` (float, of the fit
        to ``y``), ``coefs`` (ndarray).

    Raises
    ------
    InputError
        If there are not more points than the degree, or shapes disagree.
    """
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    yb = np.atleast_2d(np.asarray(y_boot, dtype=float))
    if x.ndim != 1 or x.shape != y.shape or len(x) <= degree or yb.shape[1] != len(x):
        raise InputError(f"need m > degree points with y_boot of shape (n_boot, m); got x {x.shape}, y {y.shape}, "
                         f"y_boot {yb.shape}, degree {degree}")
    lo_x, hi_x = float(x.min()), float(x.max())
    coefs = np.polyfit(x, y, degree)
    est = downward_root(coefs, lo_x, hi_x)
    cb = np.polyfit(x, yb.T, degree).T          # (n_boot, degree + 1)
    roots = downward_roots(cb, lo_x, hi_x)
    fail = np.isnan(roots)
    if fail.any():
        above = np.array([np.polyval(c, hi_x) > 0 for c in cb[fail]])
        roots[fail] = np.where(above, np.inf, -np.inf)
    q = 100.0 * (1.0 - level) / 2.0
    lo, hi = np.percentile(roots, [q, 100.0 - q], method="inverted_cdf")   # order statistics: no inf - inf
    return dict(estimate=float(est), lo=float(lo), hi=float(hi), fail_frac=float(fail.mean()),
                residual_rms=float(np.sqrt(np.mean((np.polyval(coefs, x) - y) ** 2))), coefs=coefs)


def run_tail_statistics(values, blocks) -> dict:
    r"""How heavy-tailed the per-run values are, and whether their normal standard error holds.

    ``kurtosis`` is Pearson's :math:`m_4/m_2^2` (3 for a normal law); ``max_over_mean`` the largest
    run over the mean. The standard error of the mean, :math:`s/\sqrt n`, is checked against
    independent seed replicates: the runs of each seed block (its own generator) form one
    replicate, and the batch-means standard error :math:`\mathrm{sd}(\bar v_b)/\sqrt B` over the
    ``B`` equal-size blocks is divided by :math:`s/\sqrt n` (``se_ratio``, about 1 when the normal
    error is right; its own relative sampling error is about :math:`1/\sqrt{2(B-1)}`).

    Parameters
    ----------
    values : ndarray (n,)
        Per-run values.
    blocks : ndarray (n,) of int
        Seed block of each run.

    Returns
    -------
    dict
        ``kurtosis, max_over_mean, se_ratio`` (float) and ``n_blocks`` (int, the full-size blocks used).
    """
    v = np.asarray(values, dtype=float)
    b = np.asarray(blocks)
    d = v - v.mean()
    m2 = float(np.mean(d * d))
    kurt = float(np.mean(d**4) / m2**2) if m2 > 0 else float("nan")
    ids, counts = np.unique(b, return_counts=True)
    full = ids[counts == counts.max()]
    means = np.array([v[b == i].mean() for i in full])
    se_normal = float(v.std(ddof=1)) / math.sqrt(len(v))
    nb = len(full)
    m_block = int(counts.max())
    # batch means over full blocks: sd of a block mean / sqrt(m_block) is the per-run sd they imply
    se_batch = float(means.std(ddof=1)) * math.sqrt(m_block) / math.sqrt(len(v)) if nb > 1 else float("nan")
    return dict(kurtosis=kurt, max_over_mean=float(v.max() / v.mean()),
                se_ratio=se_batch / se_normal if se_normal > 0 else float("nan"), n_blocks=nb)


def pooled_se_ratio(se_ratio, n_blocks) -> tuple:
    r"""Pool the replicate/normal standard-error ratios of independent cases, with a 95 % chi-square band.

    Case :math:`c` has ratio :math:`r_c` from :math:`B_c` seed blocks (:func:`run_tail_statistics`).
    Under normal block means with the variance the normal standard error assumes,
    :math:`(B_c - 1) r_c^2 \sim \chi^2_{B_c-1}`, so over independent cases
    :math:`\sum_c (B_c-1) r_c^2 \sim \chi^2_{\nu}`, :math:`\nu = \sum_c (B_c-1)`. The pooled ratio is
    :math:`\sqrt{\sum_c (B_c-1) r_c^2/\nu}` and its band :math:`\sqrt{\chi^2_{\nu; 0.025, 0.975}/\nu}`.

    Parameters
    ----------
    se_ratio : array_like
        Per-case ratios :math:`r_c`.
    n_blocks : array_like of int
        Per-case block counts :math:`B_c` (at least 2).

    Returns
    -------
    tuple
        ``(pooled, dof, band_lo, band_hi)``.

    Raises
    ------
    InputError
        If the inputs differ in length, are empty, or a case has fewer than two blocks.
    """
    from scipy import stats

    r, b = np.asarray(se_ratio, dtype=float), np.asarray(n_blocks, dtype=float)
    if r.shape != b.shape or r.ndim != 1 or len(r) == 0 or (b < 2).any():
        raise InputError(f"se_ratio and n_blocks must be 1-D of one length with n_blocks >= 2; got {r.shape}, {b.shape}")
    dof = float((b - 1).sum())
    band = np.sqrt(stats.chi2.ppf([0.025, 0.975], dof) / dof)
    return math.sqrt(float(((r**2) * (b - 1)).sum()) / dof), int(dof), float(band[0]), float(band[1])


def paired_db_contrasts(values, contrasts, n_boot: int, seed: int, level: float = 0.95):
    r"""Contrasts of log ratios of mean per-run values, with one paired percentile bootstrap over runs.

    Contrast :math:`c` is :math:`\sum_t w_t\, 10\log_{10}(\bar a_t/\bar b_t)` over its terms
    ``(a_t, b_t, w_t)``: e.g. ``[("kf_short", "sm_short", 1), ("kf_long", "sm_long", -1)]`` is the
    bias of rho_S on short records against long ones of the same runs. Every replicate resamples the
    runs with replacement and uses the same run indices for every array (the arrays are paired by
    run), as :func:`paired_ratio_intervals` does (same generator, same draw of indices).

    Parameters
    ----------
    values : dict of ndarray (n_runs,)
        Per-run values, paired by run.
    contrasts : sequence of sequence of tuple
        Per contrast its terms ``(num, den, weight)`` (keys of ``values``, float).
    n_boot : int
        Bootstrap replicates.
    seed : int
        Seed of the resampling generator.
    level : float
        Coverage of the percentile interval.

    Returns
    -------
    list of tuple of float
        ``(estimate, lo, hi)`` per contrast, in dB.

    Raises
    ------
    InputError
        If the arrays differ in length or are empty.
    """
    keys = sorted({k for c in contrasts for a, b, _ in c for k in (a, b)})
    arrs = {k: np.asarray(values[k], dtype=float) for k in keys}
    shapes = {a.shape for a in arrs.values()}
    if len(shapes) != 1 or next(iter(shapes)) == (0,) or len(next(iter(shapes))) != 1:
        raise InputError(f"values must be 1-D of the same length, got {sorted(shapes)}")
    n = len(arrs[keys[0]])
    rng = np.random.default_rng(seed)
    idx = rng.integers(0, n, size=(n_boot, n))
    boot = _bootstrap_means(arrs, idx)
    q = 100.0 * (1.0 - level) / 2.0
    out = []
    for c in contrasts:
        est = sum(w * 10.0 * math.log10(arrs[a].mean() / arrs[b].mean()) for a, b, w in c)
        rep = sum(w * 10.0 * np.log10(boot[a] / boot[b]) for a, b, w in c)
        lo, hi = np.percentile(rep, [q, 100.0 - q])
        out.append((float(est), float(lo), float(hi)))
    return out


def replicate_coverage(values, n_replicates: int, reference=None, level: float = 0.95) -> dict:
    r"""Coverage of the normal interval of a mean, tested on disjoint replicates of the runs.

    The runs (independent, in block order) are cut into ``n_replicates`` contiguous disjoint
    replicates. Replicate :math:`r` has mean :math:`\bar v_r` and normal standard error
    :math:`s_r/\sqrt{n_r}`. Its reference is ``reference`` (an exact value, standard error 0) or,
    without one, the mean of the other replicates' runs with its own normal standard error
    (independent of replicate :math:`r`: disjoint runs). The replicate's interval covers when
    :math:`|z_r| \le z_{(1+\text{level})/2}`, :math:`z_r = (\bar v_r - \text{ref}_r)/\sqrt{se_r^2 + se_{\text{ref}}^2}`;
    with correct standard errors and a normal mean, :math:`z_r \sim N(0, 1)` and the coverage is
    ``level``. Heavy tails show as under-coverage: most replicates miss the rare large runs, so
    their mean and their :math:`s_r` are both too small.

    Parameters
    ----------
    values : ndarray (n,)
        Per-run values.
    n_replicates : int
        Number of disjoint replicates (at least 2, at most n/2).
    reference : float, optional
        The exact mean, if known.
    level : float
        Nominal coverage of the normal interval.

    Returns
    -------
    dict of ndarray (n_replicates,)
        ``n, mean, se, reference, reference_se, z`` (float) and ``covered`` (bool).

    Raises
    ------
    InputError
        If there are fewer than two replicates or fewer than two runs per replicate.
    """
    from scipy.special import ndtri

    v = np.asarray(values, dtype=float)
    R = int(n_replicates)
    if R < 2 or v.ndim != 1 or len(v) < 2 * R:
        raise InputError(f"need at least 2 replicates of at least 2 runs; got {R} replicates of {v.shape} runs")
    parts = np.array_split(v, R)
    n = np.array([len(p) for p in parts], dtype=float)
    sums = np.array([p.sum() for p in parts])
    sq = np.array([np.sum((p - p.mean()) ** 2) for p in parts])
    mean = sums / n
    se = np.sqrt(sq / (n - 1.0) / n)
    if reference is not None:
        ref = np.full(R, float(reference))
        ref_se = np.zeros(R)
    else:
        others = [np.concatenate(parts[:r] + parts[r + 1:]) for r in range(R)]
        ref = np.array([o.mean() for o in others])
        ref_se = np.array([o.std(ddof=1) / math.sqrt(len(o)) for o in others])
    z = (mean - ref) / np.sqrt(se**2 + ref_se**2)
    return dict(n=n, mean=mean, se=se, reference=ref, reference_se=ref_se, z=z,
                covered=np.abs(z) <= float(ndtri(0.5 + level / 2.0)))


def binomial_coverage(covered: int, total: int, nominal: float = 0.95, level: float = 0.95) -> dict:
    r"""Observed coverage of ``total`` intervals against their nominal level: Clopper-Pearson interval and test.

    ``covered`` of ``total`` independent intervals hold their reference; under correct intervals
    the count is :math:`\mathrm{Bin}(\text{total}, \text{nominal})`. The one-sided p-value of
    under-coverage is :math:`P(X \le \text{covered})`; the Clopper-Pearson interval of the coverage
    at ``level`` comes from the beta quantiles.

    Parameters
    ----------
    covered, total : int
        Intervals that cover, and all intervals (``0 <= covered <= total``, ``total >= 1``).
    nominal : float
        The intervals' nominal coverage.
    level : float
        Level of the Clopper-Pearson interval.

    Returns
    -------
    dict
        ``fraction, lo, hi, p_under`` (float).

    Raises
    ------
    InputError
        If the counts are inconsistent.
    """
    from scipy import stats

    k, n = int(covered), int(total)
    if n < 1 or not 0 <= k <= n:
        raise InputError(f"need 0 <= covered <= total, total >= 1; got {k} of {n}")
    a = (1.0 - level) / 2.0
    lo = float(stats.beta.ppf(a, k, n - k + 1)) if k > 0 else 0.0
    hi = float(stats.beta.ppf(1.0 - a, k + 1, n - k)) if k < n else 1.0
    return dict(fraction=k / n, lo=lo, hi=hi, p_under=float(stats.binom.cdf(k, n, nominal)))
