"""Batched Riccati recursions for Kalman filtering with packet losses.

The prediction-error covariance of the Kalman filter with intermittent
observations (Sinopoli et al. 2004, eq. (4) of the `intermittent` report) is

.. math::

    P_{k+1} = A P_k A^T + Q - \\gamma_k A P_k C^T (C P_k C^T + R)^{-1} C P_k A^T .

With several sensors whose noises are independent (block-diagonal R) and whose
packets are lost independently, the measurement update is applied sensor by
sensor for the sensors whose packet arrived; this equals the joint update with
the stacked received rows (Liu & Goldsmith 2004, eq. (14) of the report).

Everything here is batched over sample paths: ``P`` has shape ``(N, n, n)``
(or ``(N,)`` on the scalar fast path) and the loop runs over time only.
Diverging paths are kept as ``inf`` (never NaN).

Three implementations of :func:`covariance_paths`, which agree to rounding: the compiled
kernels of :mod:`netrepro.engines.kernels` (default for n <= 3; one fused loop per step,
vectorised across paths), the batched numpy kernels below (``kernel="numpy"``; a fixed handful
of array calls per step), and the dense ``(N, n, n)`` form (any n; the reference form).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .channels import arrival_patterns

__all__ = [
    "Sensor",
    "as_sensors",
    "measurement_update",
    "covariance_paths",
    "expected_riccati_map",
    "iterate_expected_riccati",
    "packed_flops_per_step",
]


@dataclass(frozen=True)
class Sensor:
    """One sensor: output matrix ``C`` (m x n) and noise covariance ``R`` (m x m).

    Parameters
    ----------
    C : array_like, shape ``(m, n)``
        Output matrix (a vector is one row).
    R : array_like, shape ``(m, m)``
        Measurement noise covariance.

    Raises
    ------
    ValueError
        If ``R`` does not match the rows of ``C``.
    """

    C: np.ndarray
    R: np.ndarray

    def __post_init__(self):
        C = np.atleast_2d(np.asarray(self.C, dtype=float))
        R = np.atleast_2d(np.asarray(self.R, dtype=float))
        if R.shape != (C.shape[0], C.shape[0]):
            raise ValueError(f"sensor R must be {C.shape[0]}x{C.shape[0]} to match C {C.shape}, got {R.shape}")
        object.__setattr__(self, "C", C)
        object.__setattr__(self, "R", R)


def as_sensors(C, R) -> list[Sensor]:
    """Split a stacked ``(C, R)`` with diagonal ``R`` into one sensor per output row.

    Parameters
    ----------
    C : array_like, shape ``(m, n)``
        Stacked output matrix.
    R : array_like, shape ``(m, m)``
        Diagonal noise covariance (independent sensor noises).

    Returns
    -------
    list of Sensor
        One scalar sensor per row of ``C``.

    Raises
    ------
    ValueError
        If ``R`` has an off-diagonal entry.
    """
    C = np.atleast_2d(np.asarray(C, dtype=float))
    R = np.atleast_2d(np.asarray(R, dtype=float))
    off = R - np.diag(np.diag(R))
    if np.any(off != 0):
        raise ValueError("as_sensors needs a diagonal R (independent sensor noises); build Sensor objects for blocks")
    return [Sensor(C[i : i + 1], R[i : i + 1, i : i + 1]) for i in range(C.shape[0])]


def _is_scalar_problem(A, sensors):
    return A.shape == (1, 1) and all(s.C.shape == (1, 1) for s in sensors)


def measurement_update(P: np.ndarray, sensor: Sensor, received: np.ndarray) -> np.ndarray:
    """Posterior covariance after one sensor's packet, batched: ``P - g P C^T (C P C^T + R)^{-1} C P``.

    Parameters
    ----------
    P : ndarray, shape ``(N, n, n)``
        Prior covariances.
    sensor : Sensor
        The sensor whose packet is (or is not) received.
    received : ndarray of bool, shape ``(N,)``
        ``g``: whether each path received the packet.

    Returns
    -------
    ndarray, shape ``(N, n, n)``
        Posterior covariances (symmetrised; the prior where nothing arrived).
    """
    C, R = sensor.C, sensor.R
    PCt = P @ C.T  # (N, n, m)
    S = C @ PCt + R  # (N, m, m)
    with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
        if C.shape[0] == 1:  # scalar innovation: a division, no LAPACK call per path
            gain_term = PCt @ (np.swapaxes(PCt, 1, 2) / S)
        else:
            gain_term = PCt @ np.linalg.solve(S, np.swapaxes(PCt, 1, 2))
    post = P - gain_term
    post = 0.5 * (post + np.swapaxes(post, 1, 2))
    return np.where(received[:, None, None], post, P)


def covariance_paths(P0, A, Q, sensors, arrivals: np.ndarray, keep: str = "all", kernel: str = "compiled") -> np.ndarray:
    """Prediction-error covariances along many loss sequences at once (eq. (4) / (14)).

    Parameters
    ----------
    P0 : array (n, n) or scalar
        Initial covariance, common to all paths.
    A, Q : arrays (n, n)
        State matrix and process noise covariance.
    sensors : list of :class:`Sensor`
        The sensors, one arrival channel each.
    arrivals : bool array ``(N, T)`` (one sensor) or ``(N, T, n_sensors)``
        Which packets arrived, per path and step.
    keep : {"all", "last"}
        ``"all"`` returns ``P_0..P_T`` with shape ``(N, T+1, n, n)``;
        ``"last"`` returns ``P_T`` with shape ``(N, n, n)``.
    kernel : {"compiled", "numpy", "dense"}
        ``"compiled"`` (default) runs n <= 3 on the fused numba kernels of
        :mod:`netrepro.engines.kernels`; ``"numpy"`` on the batched numpy kernels (the
        reference form the benchmark and tests compare with); ``"dense"`` on the plain
        ``(N, n, n)`` batches with one LAPACK-style update per sensor. All three agree to
        rounding; n > 3 (or a sensor noise that is not positive definite) always runs dense.

    Returns
    -------
    ndarray
        The covariances, shaped as ``keep`` says (scalar problems: see Notes).

    Raises
    ------
    ValueError
        If ``arrivals`` does not match ``sensors``, or ``keep`` / ``kernel`` is unknown.

    Notes
    -----
    The scalar case (n = 1, scalar sensors) runs on flat arrays and returns
    shapes ``(N, T+1)`` / ``(N,)``. Paths that diverge become ``inf``.

    Numerical range: the covariance-form update ``P - P c^T c P / (c P c^T + r)`` leaves a
    posterior variance of about ``r`` along ``c`` as the difference of two numbers of size
    ``c P c^T``; once ``c P c^T / r`` nears 1/eps (~1e15; e.g. an unobserved unstable mode after
    a long loss run) no digit of it survives, the computed ``P`` stops being a covariance and its
    later values are rounding noise, different for each implementation. Every kernel checks,
    after each update, the posterior ``c P c^T`` against its exact value, ``r - r^2 / (s0 + r)``
    after a reception (a form free of cancellation; ``s0 = c P c^T`` before the update) and ``s0``
    after a loss, and marks a path that misses it by more than ``r / 2`` as ``inf`` from then on,
    as if it had overflowed: its covariance has left what float64 can follow in this form. Below
    that range the check never fires.
    """
    A = np.atleast_2d(np.asarray(A, dtype=float))
    Q = np.atleast_2d(np.asarray(Q, dtype=float))
    n = A.shape[0]
    arrivals = np.asarray(arrivals, dtype=bool)
    if arrivals.ndim == 2:
        arrivals = arrivals[:, :, None]
    if arrivals.shape[2] != len(sensors):
        raise ValueError(f"arrivals has {arrivals.shape[2]} sensor channels but {len(sensors)} sensors were given")
    N, T = arrivals.shape[:2]
    if keep not in ("all", "last"):
        raise ValueError(f"keep must be 'all' or 'last', got {keep!r}")
    if kernel not in KERNELS:
        raise ValueError(f"kernel must be one of {KERNELS}, got {kernel!r}")

    if kernel != "dense" and _is_scalar_problem(A, sensors):
        scalar = _compiled_scalar_paths if kernel == "compiled" else _scalar_paths
        return scalar(float(np.asarray(P0, dtype=float).reshape(-1)[0]), float(A[0, 0]), float(Q[0, 0]),
                      [float(s.R[0, 0]) / float(s.C[0, 0]) ** 2 for s in sensors], arrivals, keep)
    if kernel != "dense" and n <= PACKED_MAX_STATES:
        rows = _whitened_rows(sensors)
        if rows is not None:
            small = _compiled_small_paths if kernel == "compiled" else _small_paths
            return small(np.atleast_2d(np.asarray(P0, dtype=float)), A, Q, rows, arrivals, keep)
    return _dense_paths(P0, A, Q, sensors, arrivals, keep)


KERNELS = ("compiled", "numpy", "dense")
# A path is lost when its posterior variance along a measured row misses the exact value by more
# than this fraction of the row's noise variance (covariance_paths, "Numerical range").
LOST_TOLERANCE = 0.5


def _compiled_scalar_paths(p0, a, q, r_eff, arrivals, keep):
    """:func:`_scalar_paths` on the fused compiled kernel (one division per update; equal to rounding)."""
    from . import kernels  # numba: imported by the steps that run a recursion, not at workflow start-up

    N, T, _ = arrivals.shape
    hist = np.empty((N, T + 1)) if keep == "all" else np.empty((N, 0))
    last = np.empty(N)
    kernels.scalar_kernel()(p0, a * a, q, np.asarray(r_eff, dtype=float), kernels.arrival_words(arrivals), T,
                            hist, last)
    return hist if keep == "all" else last


def _compiled_small_paths(P0, A, Q, rows, arrivals, keep):
    """:func:`_small_paths` on the fused compiled kernel (packed symmetric state, FMAs)."""
    from . import kernels

    n = A.shape[0]
    N, T, _ = arrivals.shape
    P0_given = np.broadcast_to(P0, (n, n))
    a_idx, b_idx = np.triu_indices(n)
    p0 = 0.5 * (P0_given[a_idx, b_idx] + P0_given[b_idx, a_idx])
    M, q = kernels.packed_prediction(A, Q)
    rows_c = np.array([c for _, c, _ in rows], dtype=float).reshape(len(rows), n)
    rows_r = np.array([r for _, _, r in rows], dtype=float)
    rows_channel = np.array([j for j, _, _ in rows], dtype=np.int64)
    c = len(p0)
    hist = np.empty((N, T + 1, c)) if keep == "all" else np.empty((N, 0, c))
    last = np.empty((N, c))
    kernels.small_state_kernel(n)(p0, M, q, rows_c, rows_r, rows_channel, kernels.arrival_words(arrivals),
                                  arrivals.shape[2], T, LOST_TOLERANCE, hist, last)
    full = kernels.packed_index(n).ravel()
    if keep == "last":
        return last[:, full].reshape(N, n, n)
    out = hist[:, :, full].reshape(N, T + 1, n, n)
    out[:, 0] = P0_given
    return out


def _lost_precision(prior, post, sensor, received):
    """Paths whose update lost the measured directions to rounding (see :func:`covariance_paths`).

    In exact arithmetic ``C P+ C^T = S0 - S0 S^{-1} S0 = R - R S^{-1} R`` (``S0 = C P C^T``,
    ``S = S0 + R``) after a reception, the second form free of cancellation, and ``S0`` after a
    loss; a path is lost when the stored posterior misses that by more than
    ``LOST_TOLERANCE`` times the smallest noise variance, or when ``S0`` has a negative diagonal
    entry (impossible for a covariance).
    """
    C, R = sensor.C, sensor.R
    S0 = C @ prior @ C.T
    with np.errstate(invalid="ignore", over="ignore"):
        updated = R - R @ np.linalg.solve(S0 + R, np.broadcast_to(R, S0.shape))
        want = np.where(received[:, None, None], updated, S0)
        err = np.abs(C @ post @ C.T - want).max(axis=(1, 2))
    return (np.diagonal(S0, axis1=1, axis2=2) < 0).any(axis=1) | (err > LOST_TOLERANCE * np.diag(R).min())


def _dense_paths(P0, A, Q, sensors, arrivals, keep):
    """Reference form of :func:`covariance_paths`: ``(N, n, n)`` batches, one sensor update at a time."""
    n = A.shape[0]
    N, T = arrivals.shape[:2]
    P = np.broadcast_to(np.atleast_2d(np.asarray(P0, dtype=float)), (N, n, n)).copy()
    out = np.empty((N, T + 1, n, n)) if keep == "all" else None
    if out is not None:
        out[:, 0] = P
    with np.errstate(over="ignore", invalid="ignore"):
        for k in range(T):
            for j, sensor in enumerate(sensors):
                prior = P
                P = measurement_update(P, sensor, arrivals[:, k, j])
                P[_lost_precision(prior, P, sensor, arrivals[:, k, j])] = np.nan  # inf below
            P = A @ P @ A.T + Q
            P[~np.isfinite(P).all(axis=(1, 2))] = np.inf
            if out is not None:
                out[:, k + 1] = P
    return out if keep == "all" else P


PACKED_MAX_STATES = 3  # state dimensions that run on the small-state kernel
CHUNK_PATHS = 2048  # paths per cache-resident chunk of the small-state kernel (small GEMMs stay single-threaded)
SCALAR_CHUNK_PATHS = 8192  # paths per chunk of the scalar kernel


def _chunks(N, size=None):
    size = size or CHUNK_PATHS
    return [(lo, min(lo + size, N)) for lo in range(0, N, size)]


def _scalar_paths(p0, a, q, r_eff, arrivals, keep):
    """Flat-array fast path of :func:`covariance_paths` for scalar state and sensors.

    A scalar sensor y = c x + v with variance r is equivalent to c = 1 and
    variance r / c^2; the update p -> p r / (p + r) is written as
    r / (1 + r / p) so that p = inf maps to r instead of NaN.

    Paths run in cache-sized chunks with preallocated buffers and in-place
    ufuncs; the arithmetic (and so every bit of the result) is that of the
    plain expression ``a^2 where(gamma, r / (1 + r / p), p) + q``.
    """
    N, T, m = arrivals.shape
    out = np.empty((N, T + 1)) if keep == "all" else None
    last = np.empty(N)
    a2 = a * a
    with np.errstate(over="ignore", divide="ignore", invalid="ignore"):
        for lo, hi in _chunks(N, SCALAR_CHUNK_PATHS):
            B = hi - lo
            gam = np.ascontiguousarray(arrivals[lo:hi].transpose(1, 2, 0))  # (T, m, B)
            p = np.full(B, p0)
            post = np.empty(B)
            if out is not None:
                out[lo:hi, 0] = p
            for k in range(T):
                for j in range(m):
                    np.divide(r_eff[j], p, out=post)
                    post += 1.0
                    np.divide(r_eff[j], post, out=post)
                    np.putmask(p, gam[k, j], post)
                np.multiply(a2, p, out=p)
                p += q
                if out is not None:
                    out[lo:hi, k + 1] = p
            last[lo:hi] = p
    return out if keep == "all" else last


def _whitened_rows(sensors):
    """Each sensor as scalar rows ``(sensor index, c, r = 1)`` with whitened noise, or None.

    With ``R = L L^T`` (Cholesky), ``y' = L^{-1} y`` has rows ``L^{-1} C`` and unit
    independent noises, so the joint update of a sensor equals the sequential
    scalar updates of its whitened rows (all gated by that sensor's arrival).
    Returns None when some ``R`` is not positive definite (the dense path then runs).
    """
    rows = []
    for j, s in enumerate(sensors):
        if s.C.shape[0] == 1:
            if not s.R[0, 0] > 0:
                return None
            rows.append((j, s.C[0], float(s.R[0, 0])))
            continue
        try:
            L = np.linalg.cholesky(s.R)
        except np.linalg.LinAlgError:
            return None
        W = np.linalg.solve(L, s.C)
        rows.extend((j, W[i], 1.0) for i in range(W.shape[0]))
    return rows


def packed_flops_per_step(n: int, n_rows: int) -> int:
    """Floating-point operations one path-step needs (symmetric storage, dense coefficients).

    Per scalar row ``c``: ``u = P c^T`` (``n^2`` multiply-adds), ``s = c u + r`` (``n``
    multiply-adds), ``w = gamma / s`` (1), ``t = w u`` (n), ``P -= t u^T`` on the
    ``m = n (n + 1) / 2`` distinct entries (``m`` multiply-adds); the prediction
    ``A P A^T + Q`` as a map on the distinct entries (``m^2`` multiply-adds). A multiply-add
    counts as two flops. This is the count of the compiled kernel
    (:func:`netrepro.engines.kernels.small_state_kernel`) and the one the benchmark's
    "fraction of peak" uses; the numpy kernel works on all ``n^2`` entries (more flops).

    Parameters
    ----------
    n : int
        State dimension.
    n_rows : int
        Scalar measurement rows per step.

    Returns
    -------
    int
        Flops per path and step.
    """
    m = n * (n + 1) // 2
    return n_rows * (2 * n * n + 2 * n + 1 + n + 2 * m) + 2 * m * m


def _small_operators(A, Q, rows):
    """Linear maps of the small-state kernel on ``vec(P)`` (row-major, length n^2).

    Returns ``(Maug, Ss, full)``. ``Maug`` (``n(n+1)/2`` rows) maps ``[vec(P); 1]`` to the
    upper triangle of ``A P A^T + Q``, with the symmetrised coefficients
    ``(A_ak A_bl + A_al A_bk) / 2`` so that the result is exactly symmetric;
    ``full`` gathers the upper triangle back into ``vec``. Per scalar row ``c``,
    ``S`` (``(n + 1, n^2)``) gives ``S vec(P) = [P c^T; c P c^T]``.
    """
    n = A.shape[0]
    n2 = n * n
    I, J = np.triu_indices(n)
    idx = np.empty((n, n), dtype=np.intp)
    idx[I, J] = np.arange(len(I))
    idx[J, I] = np.arange(len(I))
    Qf = np.broadcast_to(np.atleast_2d(np.asarray(Q, dtype=float)), (n, n))
    Maug = np.zeros((len(I), n2 + 1))
    for row, (a, b) in enumerate(zip(I, J)):
        Maug[row, :n2] = 0.5 * (np.outer(A[a], A[b]) + np.outer(A[b], A[a])).ravel()
        Maug[row, n2] = 0.5 * (Qf[a, b] + Qf[b, a])
    Ss = []
    for _, c, _ in rows:
        S = np.zeros((n + 1, n2))
        S[:n] = np.kron(np.eye(n), c[None, :])
        S[n] = np.kron(c[None, :], c[None, :])
        Ss.append(S)
    return Maug, Ss, idx.ravel()


def _small_paths(P0, A, Q, rows, arrivals, keep):
    """Kernel of :func:`covariance_paths` for n <= 3: ``vec(P)`` of every path as a column of ``(n^2 + 1, paths)``.

    Each scalar row ``c`` (noise ``r``) that arrived updates
    ``P <- P - (P c^T)(c P) / (c P c^T + r)``. One small matrix product gives
    ``u = P c^T`` and ``s = c P c^T + r`` together; with ``v = u sqrt(gamma / s)``
    (zero when the packet was lost) the update is the rank-one ``P -= v v^T``,
    one broadcast multiply and one subtraction, exactly symmetric. The prediction
    ``A P A^T + Q`` is one product on ``[vec(P); 1]`` giving the upper triangle
    (symmetrised coefficients) and one gather. Keeping ``P`` exactly symmetric
    matters: with an unstable ``A`` the rounding asymmetry of the plain textbook
    loop grows (to ~1e-4 relative over 200 steps in the benchmark's 3-state system).
    Arrays are float64, C-contiguous, preallocated per cache-sized chunk of paths and
    updated in place, so a step costs a fixed handful of numpy calls whatever the
    number of paths. A path with any non-finite entry is set to ``inf`` and stays
    ``inf``, as in the dense form (checked with one sum per step; the exact per-path
    test runs only when that sum is not finite).
    """
    n = A.shape[0]
    n2 = n * n
    N, T, _ = arrivals.shape
    Maug, Ss, full = _small_operators(A, Q, rows)
    rs = [r for _, _, r in rows]
    chan = [j for j, _, _ in rows]
    P0_given = np.broadcast_to(P0, (n, n))
    P0 = 0.5 * (P0_given + P0_given.T)  # covariances are symmetric; the kernel keeps them exactly so
    out = np.empty((N, T + 1, n, n)) if keep == "all" else None
    last = np.empty((N, n, n))
    with np.errstate(over="ignore", divide="ignore", invalid="ignore"):
        for lo, hi in _chunks(N):
            B = hi - lo
            gam = np.ascontiguousarray(arrivals[lo:hi].transpose(1, 2, 0), dtype=float)  # (T, m, B)
            pa = np.empty((n2 + 1, B))
            pa[:n2] = P0.reshape(n2, 1)
            pa[n2] = 1.0
            p = pa[:n2]
            upper = np.empty((Maug.shape[0], B))
            us, w, check = np.empty((n + 1, B)), np.empty(B), np.empty((n + 1, B))
            v, outer = np.empty((n, B)), np.empty((n, n, B))
            outer_flat = outer.reshape(n2, B)
            dead = None
            if out is not None:
                out[lo:hi, 0] = P0_given
            for k in range(T):
                for S, r, j in zip(Ss, rs, chan):
                    np.matmul(S, p, out=us)
                    s = us[n]
                    s0 = s.copy()
                    s += r
                    np.divide(gam[k, j], s, out=w)
                    np.sqrt(w, out=w)
                    np.multiply(us[:n], w, out=v)
                    np.multiply(v[:, None, :], v[None, :, :], out=outer)
                    p -= outer_flat
                    np.matmul(S, p, out=check)  # accuracy check, see covariance_paths
                    exact = np.where(gam[k, j] > 0, r - r * (r / s), s0)
                    lost = (s0 < 0) | (np.abs(check[n] - exact) > LOST_TOLERANCE * r)
                    if lost.any():
                        p[:, lost] = np.nan
                np.matmul(Maug, pa, out=upper)
                np.take(upper, full, axis=0, out=p)
                if not np.isfinite(p.sum()):
                    bad = ~np.isfinite(p).all(axis=0)
                    dead = bad if dead is None else (dead | bad)
                if dead is not None:
                    p[:, dead] = np.inf
                if out is not None:
                    out[lo:hi, k + 1] = p.T.reshape(B, n, n)
            last[lo:hi] = p.T.reshape(B, n, n)
    return out if keep == "all" else last


def expected_riccati_map(X, A, Q, sensors, probs) -> np.ndarray:
    """Expected one-step Riccati map over independent i.i.d. sensor losses.

    .. math::

        g(X) = \\sum_S \\pi_S \\, [A (X - X C_S^T (C_S X C_S^T + R_S)^{-1} C_S X) A^T] + Q

    over all arrival patterns S. For one sensor this is Sinopoli's modified
    algebraic Riccati map g_lambda(X); for two scalar sensors it is the
    corrected eq. (15) of the `intermittent` report (Liu & Goldsmith).

    Parameters
    ----------
    X : array_like, shape ``(n, n)`` or ``(B, n, n)``
        Covariance(s) to map.
    A, Q : array_like, shape ``(n, n)``
        State matrix and process noise covariance.
    sensors : list of Sensor
        The sensors.
    probs : sequence of float
        Independent arrival probability of each sensor.

    Returns
    -------
    ndarray
        ``g(X)``, shaped like ``X``.
    """
    A = np.atleast_2d(np.asarray(A, dtype=float))
    Q = np.atleast_2d(np.asarray(Q, dtype=float))
    X = np.asarray(X, dtype=float)
    squeeze = X.ndim < 3
    Xb = np.atleast_2d(X)[None] if squeeze else X
    patterns, weights = arrival_patterns(probs)
    total = np.zeros_like(Xb)
    for pattern, weight in zip(patterns, weights):
        post = Xb
        for j, received in enumerate(pattern):
            if received:
                post = measurement_update(post, sensors[j], np.ones(len(post), dtype=bool))
        total = total + weight * (A @ post @ A.T)
    result = total + Q
    return result[0] if squeeze else result


def iterate_expected_riccati(X0, A, Q, sensors, probs, n_steps: int) -> np.ndarray:
    """``X_0, g(X_0), g(g(X_0)), ...`` (n_steps + 1 matrices): the upper-bound sequence.

    Parameters
    ----------
    X0 : array_like, shape ``(n, n)``
        Starting covariance.
    A, Q : array_like, shape ``(n, n)``
        State matrix and process noise covariance.
    sensors : list of Sensor
        The sensors.
    probs : sequence of float
        Arrival probabilities (:func:`expected_riccati_map`).
    n_steps : int
        Number of applications of ``g``.

    Returns
    -------
    ndarray, shape ``(n_steps + 1, n, n)``
        The sequence (overflow gives ``inf``, silently).
    """
    X = np.atleast_2d(np.asarray(X0, dtype=float))
    seq = [X]
    with np.errstate(over="ignore", invalid="ignore"):
        for _ in range(n_steps):
            X = expected_riccati_map(X, A, Q, sensors, probs)
            seq.append(X)
    return np.stack(seq)
