"""Exact second moments of the estimation error when the nonlinearity is linear (issue 16, section 2).

With f(z) = F z for a fixed gain F inside the sector [F1, F2] of (3) (the edges F1, F2, or the
midpoint (F1 + F2)/2), plant (1), (6) and filter (8)-(9) are linear with a Bernoulli factor
xi(k) ~ B(p(k)) (7) and a scalar multiplicative noise w(k), E w^2 = sigma^2, independent of each
other and of the state. The augmented state z̄ = [x; x_f] of (10) then obeys

.. math::

    \\bar z(k+1) = M_{\\xi(k)}(k)\\,\\bar z(k) + w(k)\\,W \\bar z(k),\\quad
    M_\\xi = \\begin{bmatrix} A + BFZ & 0 \\\\ \\xi H(p) C & G(p) \\end{bmatrix},\\;
    W = \\begin{bmatrix} D & 0 \\\\ 0 & 0 \\end{bmatrix},

so its second moment X(k) = E z̄(k) z̄(k)^T follows the exact linear recursion

.. math::

    X(k+1) = p(k) M_1 X M_1^T + (1 - p(k)) M_0 X M_0^T + \\sigma^2 W X W^T,

and E||e(k)||^2 = tr(L X(k) L^T), L = [I, -I]. No sampling, no tail: the Monte Carlo mean of a
heavy-tailed ||e||^2 is replaced by its exact value.
"""

from __future__ import annotations

import numpy as np

from .model import Gains, GainschedError, System

__all__ = ["linear_gains", "mode_matrices", "second_moments", "error_mse", "initial_moment"]


def linear_gains(sys: System) -> dict:
    """The fixed linear gains F of f(z) = F z used for exact moments: the sector edges and the midpoint.

    Parameters
    ----------
    sys : System
        The plant; its sector bounds F1, F2 of (3) are used.

    Returns
    -------
    dict
        ``{"F1": F1, "F2": F2, "mid": (F1 + F2) / 2}`` (each nz x nz), all inside the sector (3).
    """
    return {"F1": sys.F1, "F2": sys.F2, "mid": 0.5 * (sys.F1 + sys.F2)}


def mode_matrices(sys: System, gains: Gains, p_seq, F):
    """Transition matrices of (10) with f = F z, per step, for xi = 1 and xi = 0, and the noise matrix.

    Parameters
    ----------
    sys : System
        The plant (1), (2), (6) and its sector (3).
    gains : Gains
        Filter (9); G(p(k)), H(p(k)) are evaluated at each p(k).
    p_seq : array_like (K,)
        p(0..K-1).
    F : ndarray (nz, nz)
        Linear gain of the nonlinearity.

    Returns
    -------
    tuple
        ``(M1, M0, W)``: M1, M0 of shape (K, 2n, 2n) (measurement received / lost) and W (2n, 2n).
    """
    p = np.asarray(p_seq, dtype=float)
    n = sys.n
    K = p.size
    AF = sys.A + sys.B @ F @ sys.Z
    G = gains.G0[None] + p[:, None, None] * gains.Gf[None]
    H = gains.H0[None] + p[:, None, None] * gains.Hf[None]
    M0 = np.zeros((K, 2 * n, 2 * n))
    M0[:, :n, :n] = AF
    M0[:, n:, n:] = G
    M1 = M0.copy()
    M1[:, n:, :n] = H @ sys.C
    W = np.zeros((2 * n, 2 * n))
    W[:n, :n] = sys.D
    return M1, M0, W


def initial_moment(x_mean, x_cov, xf0) -> np.ndarray:
    """E z̄(0) z̄(0)^T for x(0) with mean ``x_mean`` and covariance ``x_cov`` and a deterministic x_f(0).

    Parameters
    ----------
    x_mean : array_like (n,)
        Mean of x(0).
    x_cov : array_like (n, n)
        Covariance of x(0).
    xf0 : array_like (n,)
        The filter's initial state x_f(0).

    Returns
    -------
    ndarray (2n, 2n)
        ``[[cov + m m^T, m xf0^T], [xf0 m^T, xf0 xf0^T]]``.
    """
    m = np.asarray(x_mean, dtype=float)
    f = np.asarray(xf0, dtype=float)
    cov = np.asarray(x_cov, dtype=float)
    if cov.shape != (m.size, m.size) or f.shape != m.shape:
        raise GainschedError(f"initial moment: x_mean {m.shape}, x_cov {cov.shape}, xf0 {f.shape} do not agree")
    z = np.concatenate([m, f])
    X = np.outer(z, z)
    X[: m.size, : m.size] += cov
    return X


def second_moments(M1, M0, W, p_seq, sigma2: float, X0):
    """Exact X(k) = E z̄ z̄^T, k = 0..K, by the linear recursion of the module docstring, batched.

    Parameters
    ----------
    M1, M0 : ndarray (B, K, 2n, 2n) or (K, 2n, 2n)
        Transition matrices (:func:`mode_matrices`), stacked over a batch of B systems.
    W : ndarray (B, 2n, 2n) or (2n, 2n)
        Multiplicative-noise matrix.
    p_seq : array_like (K,)
        p(0..K-1): the arrival probabilities weighting M1 and M0.
    sigma2 : float
        E w^2.
    X0 : ndarray (B, 2n, 2n) or (2n, 2n)
        Initial second moments.

    Returns
    -------
    ndarray (B, K+1, 2n, 2n) (or (K+1, 2n, 2n) without batch)
        X(0..K).
    """
    single = np.ndim(M1) == 3
    M1, M0 = np.atleast_3d(M1), np.atleast_3d(M0)
    if single:
        M1, M0, W, X0 = M1[None], M0[None], np.asarray(W)[None], np.asarray(X0)[None]
    p = np.asarray(p_seq, dtype=float)
    B, K, d, _ = M1.shape
    W = np.broadcast_to(W, (B, d, d))
    X = np.empty((B, K + 1, d, d))
    X[:, 0] = X0
    for k in range(K):  # a recursion in k; everything else is batched
        Xk = X[:, k]
        X[:, k + 1] = (p[k] * np.einsum("bij,bjl,bml->bim", M1[:, k], Xk, M1[:, k])
                       + (1.0 - p[k]) * np.einsum("bij,bjl,bml->bim", M0[:, k], Xk, M0[:, k])
                       + sigma2 * np.einsum("bij,bjl,bml->bim", W, Xk, W))
    return X[0] if single else X


def error_mse(X) -> np.ndarray:
    """E||e||^2 = tr(L X L^T), L = [I, -I], for second moments X of z̄ = [x; x_f].

    Parameters
    ----------
    X : ndarray (..., 2n, 2n)
        Second moments E z̄ z̄^T (any leading shape).

    Returns
    -------
    ndarray (...)
        E||e||^2 per matrix.
    """
    X = np.asarray(X, dtype=float)
    n = X.shape[-1] // 2
    return (np.trace(X[..., :n, :n], axis1=-2, axis2=-1) + np.trace(X[..., n:, n:], axis1=-2, axis2=-1)
            - 2.0 * np.trace(X[..., :n, n:], axis1=-2, axis2=-1))
