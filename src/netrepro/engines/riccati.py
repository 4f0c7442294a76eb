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
]


@dataclass(frozen=True)
class Sensor:
    """One sensor: output matrix ``C`` (m x n) and noise covariance ``R`` (m x m)."""

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
    """Split a stacked ``(C, R)`` with block-diagonal ``R`` into one sensor per output row."""
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

    ``P`` has shape ``(N, n, n)``; ``received`` is a bool array ``(N,)``.
    """
    C, R = sensor.C, sensor.R
    PCt = P @ C.T  # (N, n, m)
    S = C @ PCt + R  # (N, m, m)
    with np.errstate(invalid="ignore", over="ignore"):
        gain_term = PCt @ np.linalg.solve(S, np.swapaxes(PCt, 1, 2))
    post = P - gain_term
    post = 0.5 * (post + np.swapaxes(post, 1, 2))
    return np.where(received[:, None, None], post, P)


def covariance_paths(P0, A, Q, sensors, arrivals: np.ndarray, keep: str = "all") -> np.ndarray:
    """Prediction-error covariances along many loss sequences at once (eq. (4) / (14)).

    Parameters
    ----------
    P0 : array (n, n) or scalar
        Initial covariance, common to all paths.
    A, Q : arrays (n, n)
    sensors : list of :class:`Sensor`
    arrivals : bool array ``(N, T)`` (one sensor) or ``(N, T, n_sensors)``
    keep : ``"all"`` returns ``P_0..P_T`` with shape ``(N, T+1, n, n)``;
        ``"last"`` returns ``P_T`` with shape ``(N, n, n)``.

    Notes
    -----
    The scalar case (n = 1, scalar sensors) runs on flat arrays and returns
    shapes ``(N, T+1)`` / ``(N,)``. Paths that diverge become ``inf``.
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

    if _is_scalar_problem(A, sensors):
        return _scalar_paths(float(np.asarray(P0, dtype=float).reshape(-1)[0]), float(A[0, 0]), float(Q[0, 0]),
                             [float(s.R[0, 0]) / float(s.C[0, 0]) ** 2 for s in sensors], arrivals, keep)

    P = np.broadcast_to(np.atleast_2d(np.asarray(P0, dtype=float)), (N, n, n)).copy()
    out = np.empty((N, T + 1, n, n)) if keep == "all" else None
    if out is not None:
        out[:, 0] = P
    with np.errstate(over="ignore", invalid="ignore"):
        for k in range(T):
            for j, sensor in enumerate(sensors):
                P = measurement_update(P, sensor, arrivals[:, k, j])
            P = A @ P @ A.T + Q
            P[~np.isfinite(P).all(axis=(1, 2))] = np.inf
            if out is not None:
                out[:, k + 1] = P
    return out if keep == "all" else P


def _scalar_paths(p0, a, q, r_eff, arrivals, keep):
    """Flat-array fast path of :func:`covariance_paths` for scalar state and sensors.

    A scalar sensor y = c x + v with variance r is equivalent to c = 1 and
    variance r / c^2; the update p -> p r / (p + r) is written as
    r / (1 + r / p) so that p = inf maps to r instead of NaN.
    """
    N, T, m = arrivals.shape
    p = np.full(N, p0)
    out = np.empty((N, T + 1)) if keep == "all" else None
    if out is not None:
        out[:, 0] = p
    a2 = a * a
    with np.errstate(over="ignore", divide="ignore", invalid="ignore"):
        for k in range(T):
            for j in range(m):
                post = r_eff[j] / (1.0 + r_eff[j] / p)
                p = np.where(arrivals[:, k, j], post, p)
            p = a2 * p + q
            if out is not None:
                out[:, k + 1] = p
    return out if keep == "all" else p


def expected_riccati_map(X, A, Q, sensors, probs) -> np.ndarray:
    """Expected one-step Riccati map over independent i.i.d. sensor losses.

    .. math::

        g(X) = \\sum_S \\pi_S \\, [A (X - X C_S^T (C_S X C_S^T + R_S)^{-1} C_S X) A^T] + Q

    over all arrival patterns S. For one sensor this is Sinopoli's modified
    algebraic Riccati map g_lambda(X); for two scalar sensors it is the
    corrected eq. (15) of the `intermittent` report (Liu & Goldsmith).
    ``X`` may be batched with shape ``(B, n, n)``.
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
    """``X_0, g(X_0), g(g(X_0)), ...`` (n_steps + 1 matrices): the upper-bound sequence."""
    X = np.atleast_2d(np.asarray(X0, dtype=float))
    seq = [X]
    with np.errstate(over="ignore", invalid="ignore"):
        for _ in range(n_steps):
            X = expected_riccati_map(X, A, Q, sensors, probs)
            seq.append(X)
    return np.stack(seq)
