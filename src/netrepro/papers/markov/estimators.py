"""Monte Carlo estimators of ``E||P_k||`` over the Gilbert-Elliott channel (eq. 3): the plain
sample mean and the conditional (Rao-Blackwellised) estimators that integrate the trailing loss
run exactly.
"""

from __future__ import annotations

import numpy as np

from ...engines.channels import gilbert_elliott_arrivals
from ...engines.riccati import Sensor, covariance_paths
from ...errors import InputError
from .model import riccati_g, riccati_h, sym_norm

__all__ = ["covariance_paths_ge", "plain_mc", "rb_mean_norm", "rb_mean_trace", "rb_trace_grid", "gilbert_elliott_arrivals"]


def covariance_paths_ge(system, Sigma0, arrivals) -> np.ndarray:
    """``P_1..P_{T+1}`` along each path, shape ``(N, T+1, n, n)``: ``P_{k+1} = g(P_k)`` if ``gamma_k = 1``
    else ``h(P_k)`` (eqs. 4-5), batched over paths: the shared engine's recursion with one sensor (C, R).

    Parameters
    ----------
    system : LinearSystem
        The system (eqs. 1-2).
    Sigma0 : array_like
        ``P_1``.
    arrivals : bool array ``(N, T)``
        ``gamma_1..gamma_T`` per path.

    Returns
    -------
    ndarray ``(N, T+1, n, n)``
    """
    return covariance_paths(Sigma0, system.A, system.Q, [Sensor(system.C, system.R)], arrivals, keep="all")


def plain_mc(system, Sigma0, p, q, n_paths, horizon, rng):
    """Plain sample mean of ``||P_k||`` over ``n_paths`` Gilbert-Elliott paths (``gamma_1 = 1``).

    Parameters
    ----------
    system : LinearSystem
        The system (eqs. 1-2).
    Sigma0 : array_like
        ``P_1``.
    p, q : float
        Failure and recovery rates.
    n_paths, horizon : int
        Number of paths and of steps.
    rng : numpy.random.Generator
        Random source.

    Returns
    -------
    (norms, arrivals)
        ``norms`` of shape ``(N, horizon + 1)`` (``k = 1..horizon+1``), ``arrivals`` ``(N, horizon)``.
    """
    arrivals = gilbert_elliott_arrivals(rng, n_paths, horizon, p, q, initial=1)
    P = covariance_paths_ge(system, Sigma0, arrivals)
    return sym_norm(P), arrivals


def _trailing_run_weights(p, q, k):
    """Weights of ``h^{k-1-i}(P_{i+1})``, ``i = 1..k-1``, in :func:`rb_mean_norm`: the probability of the
    trailing loss run after the last reception ``i`` (``p (1-q)^{k-2-i}``), 1 for ``i = k-1``."""
    i = np.arange(1, k)
    return np.where(i < k - 1, p * (1.0 - q) ** np.maximum(k - 2 - i, 0), 1.0)


def rb_mean_norm(system, Sigma0, p, q, arrivals, P=None, which="norm", kernel="compiled"):
    r"""Conditional (Rao-Blackwellised) estimator of ``E||P_k||`` integrating the trailing loss run.

    With ``l = max{i <= k-1 : gamma_i = 1}`` the last reception before ``k``,
    ``P_k = h^{k-1-l}(P_{l+1})`` (eq. 4) and, by the Markov property (eq. 3),
    ``P(l = i | gamma_1..gamma_i, gamma_i = 1) = p (1-q)^{k-2-i}`` for ``i < k-1`` (1 for ``i = k-1``). So

    .. math:: E\|P_k\| = \sum_{i=1}^{k-1} E\big[1\{\gamma_i = 1\}\, w_{k,i}\, \|h^{k-1-i}(P_{i+1})\|\big]

    and the per-path sum is an unbiased estimator whose loss-run tail (the growth
    ``|lambda_A|^{2j} (1-q)^j``) is computed exactly instead of sampled. ``gamma_1 = 1`` is required.

    Parameters
    ----------
    system : LinearSystem
        The system (eqs. 1-2).
    Sigma0 : array_like
        ``P_1``, ``(n, n)``.
    p : float
        Failure rate ``P(gamma_{k+1}=0 | gamma_k=1)``.
    q : float
        Recovery rate ``P(gamma_{k+1}=1 | gamma_k=0)``.
    arrivals : ndarray of bool, shape (N, T)
        ``gamma_1..gamma_T`` per path, with ``arrivals[:, 0]`` all True.
    P : ndarray, shape (N, T+1, n, n), optional
        Covariances ``P_1..P_{T+1}`` along the same paths; computed from ``arrivals`` if omitted.
    which : {"norm", "trace"}
        The functional of ``P_k``.
    kernel : {"compiled", "numpy"}
        ``"compiled"`` (n = 2, 3): :func:`.kernels.rb_norm_kernel`, the same arithmetic path by path
        (equal to the numpy form bit for bit where numpy's small products use FMAs, as OpenBLAS's do);
        ``"numpy"``: the batched numpy reference below (also used for other n).

    Returns
    -------
    ndarray ``(N, T+1)``
        Per-path estimator values for ``k = 1..T+1`` (average over axis 0); column 0 is ``||P_1||``.

    Raises
    ------
    InputError
        If some path has ``gamma_1 = 0``.
    """
    arrivals = np.asarray(arrivals, dtype=bool)
    if not arrivals[:, 0].all():
        raise InputError("rb_mean_norm needs gamma_1 = 1 on every path")
    A, Q = system.A, system.Q
    if P is None:
        P = covariance_paths_ge(system, Sigma0, arrivals)
    N, T = arrivals.shape
    if kernel == "compiled" and A.shape[0] in (2, 3):
        from .kernels import rb_norm_kernel  # numba: imported by the steps that run the estimator

        W = np.zeros((T + 1, T))
        for kk in range(2, T + 2):
            W[kk - 1, :kk - 1] = _trailing_run_weights(p, q, kk)
        out = np.empty((N, T + 1))
        with np.errstate(over="ignore", invalid="ignore"):
            rb_norm_kernel(np.ascontiguousarray(P, dtype=float), np.ascontiguousarray(arrivals),
                           np.ascontiguousarray(A, dtype=float), np.ascontiguousarray(Q, dtype=float), W,
                           which != "norm", out)
        return out
    normf = sym_norm if which == "norm" else (lambda M: np.trace(M, axis1=-2, axis2=-1))
    out = np.empty((N, T + 1))
    out[:, 0] = normf(P[:, 0])
    # H[:, i] = h^{k-1-i}(P_{i+1}) for the current k, for i = 1..k-1 (0-based column i-1)
    H = np.empty((N, 0) + A.shape)
    for k in range(2, T + 2):
        with np.errstate(over="ignore", invalid="ignore"):
            H = riccati_h(H, A, Q) if H.shape[1] else H
            H = np.concatenate([H, P[:, k - 1][:, None]], axis=1)  # P_k = h^0(P_k), i = k-1
        w = _trailing_run_weights(p, q, k)
        g = arrivals[:, :k - 1]  # gamma_1..gamma_{k-1}
        with np.errstate(over="ignore", invalid="ignore"):
            vals = normf(H)
            out[:, k - 1] = np.sum(np.where(g, w * vals, 0.0), axis=1)
    return out


def rb_mean_trace(system, Sigma0, p, q, arrivals, n_batches: int, z: float):
    """Conditional estimator of ``E tr P_k`` for long horizons, with batch means.

    Same decomposition as :func:`rb_mean_norm`, but for the trace, which is *linear* in the
    covariance at the last reception: ``tr h^j(P) = <W_j, P> + c_j`` with ``W_j = (A^j)' A^j`` and
    ``c_j = tr sum_{t<j} A^t Q (A^t)'`` (eq. 4). So only the batch means of
    ``1{gamma_i = 1} P_{i+1}`` are needed and the cost is ``O(N T)`` instead of ``O(N T^2)``.

    Parameters
    ----------
    system : LinearSystem
        The system (eqs. 1-2).
    Sigma0 : array_like
        ``P_1``.
    p, q : float
        Failure and recovery rates.
    arrivals : bool array ``(N, T)``
        With ``arrivals[:, 0]`` all True.
    n_batches : int
        Number of batches of the confidence interval.
    z : float
        Normal quantile of the interval (``config.yaml``: ``markov.estimator.interval_z``; 1.96: 95%).

    Returns
    -------
    (mean, low, high): arrays of length ``T + 1`` (``k = 1..T+1``), batch-means interval ``mean +- z s / sqrt(B)``.
    """
    arrivals = np.asarray(arrivals, dtype=bool)
    if not arrivals[:, 0].all():
        raise InputError("rb_mean_trace needs gamma_1 = 1 on every path")
    A, Q = system.A, system.Q
    N, T = arrivals.shape
    P = covariance_paths_ge(system, Sigma0, arrivals)  # (N, T+1, n, n)
    batches = np.array_split(np.arange(N), n_batches)
    g = arrivals.astype(float)  # gamma_1..gamma_T
    S = np.stack([np.einsum("ni,nixy->ixy", g[b], P[b, 1:]) / len(b) for b in batches])  # (B, T, n, n)
    f = np.stack([g[b].mean(axis=0) for b in batches])  # (B, T)
    W, c = [np.eye(A.shape[0])], [0.0]
    Aj, Qsum = np.eye(A.shape[0]), np.zeros_like(A)
    for _ in range(1, T + 1):
        Qsum = A @ Qsum @ A.T + Q
        Aj = A @ Aj
        W.append(Aj.T @ Aj)
        c.append(float(np.trace(Qsum)))
    W, c = np.array(W), np.array(c)
    with np.errstate(over="ignore", invalid="ignore"):
        inner = np.einsum("bixy,jxy->bij", S, W)  # <W_j, S_b[i]>
        vals = np.empty((len(batches), T + 1))
        vals[:, 0] = np.trace(np.asarray(Sigma0, float))
        for k in range(2, T + 2):
            i = np.arange(1, k)  # last reception time (1-based) -> column i-1
            j = k - 1 - i
            w = np.where(i < k - 1, p * (1.0 - q) ** np.maximum(k - 2 - i, 0), 1.0)
            vals[:, k - 1] = np.sum(w * (inner[:, i - 1, j] + c[j] * f[:, i - 1]), axis=1)
    mean = vals.mean(axis=0)
    half = z * vals.std(axis=0, ddof=1) / np.sqrt(len(batches))
    return mean, mean - half, mean + half


def _riccati_step(P, received, A, C, Q, R):
    """One step of eqs. (4)-(5) for a batch of paths: ``g(P)`` (eq. 5) where ``received``, else ``h(P)``
    (eq. 4), each map evaluated only on its own paths (every batched product and solve acts on one
    matrix at a time, so this equals ``np.where(received, g(P), h(P))`` bit for bit at half the work).
    Two states and one output: the compiled :func:`.kernels.riccati_step_2x1`, the same numbers."""
    if P.shape[1:] == (2, 2) and np.shape(C) == (1, 2) and np.shape(R) == (1, 1):
        from .kernels import riccati_step_2x1  # numba: imported by the steps that run the estimator

        return riccati_step_2x1(P, received, A, C, Q, R)
    out = np.empty_like(P)
    out[received] = riccati_g(P[received], A, C, Q, R)
    lost = ~received
    out[lost] = riccati_h(P[lost], A, Q)
    return out


def rb_trace_grid(system, Sigma0, ps, qs, n_paths: int, horizon: int, rng, n_batches: int, z: float):
    """:func:`rb_mean_trace` for many ``(p, q)`` points at once (all paths of all points in one batch).

    Memory is ``O(points x paths)``: the batch sums of ``1{gamma_i = 1} P_{i+1}`` are accumulated
    during the time loop, the covariances themselves are not stored.

    Parameters
    ----------
    system : LinearSystem
        The system (eqs. 1-2).
    Sigma0 : array_like
        ``P_1``.
    ps, qs : array_like
        The points.
    n_paths, horizon : int
        Paths per point and number of steps.
    rng : numpy.random.Generator
        Random source.
    n_batches : int
        Number of batches of the confidence interval.
    z : float
        Normal quantile of the interval (``markov.estimator.interval_z``; 1.96: 95%).

    Returns
    -------
    (mean, half): arrays ``(n_points, horizon + 1)``, the estimate of ``E tr P_k`` and the
    batch-means half-width ``z s / sqrt(B)``.
    """
    ps, qs = np.atleast_1d(np.asarray(ps, float)), np.atleast_1d(np.asarray(qs, float))
    npts, B, T = len(ps), n_batches, horizon
    per = -(-n_paths // B)  # paths per batch
    A, C, Q, R = system.A, system.C, system.Q, system.R
    n = A.shape[0]
    arr = np.concatenate([gilbert_elliott_arrivals(rng, B * per, T, p, q, initial=1) for p, q in zip(ps, qs)])
    starts = np.arange(0, npts * B * per, per)  # contiguous (point, batch) groups
    P = np.broadcast_to(np.asarray(Sigma0, float), (len(arr), n, n)).copy()
    S = np.empty((npts * B, T, n, n))
    with np.errstate(over="ignore", invalid="ignore"):
        for k in range(T):
            P = _riccati_step(P, arr[:, k], A, C, Q, R)
            S[:, k] = np.add.reduceat(np.where(arr[:, k, None, None], P, 0.0), starts, axis=0) / per
    f = np.add.reduceat(arr.astype(float), starts, axis=0) / per  # (npts*B, T)
    W, c = [np.eye(n)], [0.0]
    Aj, Qsum = np.eye(n), np.zeros_like(A)
    for _ in range(T):
        Qsum = A @ Qsum @ A.T + Q
        Aj = A @ Aj
        W.append(Aj.T @ Aj)
        c.append(float(np.trace(Qsum)))
    W, c = np.array(W), np.array(c)
    vals = np.empty((npts * B, T + 1))
    vals[:, 0] = np.trace(np.asarray(Sigma0, float))
    pr = np.repeat(ps, B)[:, None]
    qr = np.repeat(qs, B)[:, None]
    with np.errstate(over="ignore", invalid="ignore"):
        inner = np.einsum("bixy,jxy->bij", S, W)
        for k in range(2, T + 2):
            i = np.arange(1, k)
            j = k - 1 - i
            w = np.where(i < k - 1, pr * (1.0 - qr) ** np.maximum(k - 2 - i, 0), 1.0)
            vals[:, k - 1] = np.sum(w * (inner[:, i - 1, j] + c[j] * f[:, i - 1]), axis=1)
    vals = vals.reshape(npts, B, T + 1)
    mean = vals.mean(axis=1)
    half = z * vals.std(axis=1, ddof=1) / np.sqrt(B)
    return mean, half


