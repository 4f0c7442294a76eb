"""The evasive target of the `hinf` paper, eqs (19)-(24).

The target knows the agents' positions and the sensor model (not the filters) and moves,
greedily, to where the smallest ellipse over-bounding the intersection of the agents'
uncertainty ellipses (22) is largest.
"""

from __future__ import annotations

import numpy as np

from .algebra import inv2
from .noise import NoiseModel, geometry, noise_information

__all__ = ["overbounding_ellipse", "fused_trace", "min_fused_trace", "evader_move"]


def overbounding_ellipse(A, b, rho):
    """The map ``(q, Q) = F(A, b, rho)`` of eq (23).

    .. math:: Q = [1 + b^T A^{-1} b - \\rho] A^{-1}, \\qquad q = A^{-1} b

    ``{x : x^T A x - 2 b^T x + rho <= 1} = {x : (x - q)^T Q^{-1} (x - q) <= 1}``.

    Parameters
    ----------
    A : ndarray, shape ``(..., 2, 2)``
    b : ndarray, shape ``(..., 2)``
    rho : ndarray, shape ``(...)``

    Returns
    -------
    q : ndarray, shape ``(..., 2)``
    Q : ndarray, shape ``(..., 2, 2)``
    """
    Ai = inv2(A)
    q = (Ai @ b[..., None])[..., 0]
    scale = 1.0 + np.einsum("...i,...i->...", b, q) - rho
    return q, scale[..., None, None] * Ai


def fused_trace(Minv, lam, x_t):
    """``tr Q_fused`` of eq (24) for given weights.

    Parameters
    ----------
    Minv : ndarray, shape ``(..., N, 2, 2)``
        The agents' informations ``M_j^{-1}``.
    lam : ndarray, shape ``(..., N)``
        Weights ``lambda_j`` of eq (24).
    x_t : ndarray, shape ``(..., 2)``
        Common centre of the ellipses.

    Returns
    -------
    ndarray, shape ``(...)``
    """
    A = np.einsum("...n,...nij->...ij", lam, Minv)
    b = (A @ x_t[..., None])[..., 0]
    rho = np.einsum("...i,...i->...", x_t, b)
    _, Q = overbounding_ellipse(A, b, rho)
    return Q[..., 0, 0] + Q[..., 1, 1]


def min_fused_trace(Minv, n_iter: int = 60, step: float = 1.0):
    """Smallest over-bounding ellipse of the intersection (22): ``min_lambda tr (sum_j lam_j M_j^{-1})^{-1}``.

    For ellipses centred on the same point, (24) gives ``Q = (sum_j lam_j M_j^{-1})^{-1}``; its
    trace is convex in ``lam`` on the simplex. Minimised by exponentiated-gradient (mirror) descent,
    vectorised over the leading axes.

    Parameters
    ----------
    Minv : ndarray, shape ``(..., N, 2, 2)``
    n_iter : int
        Mirror-descent iterations.
    step : float
        Step of the normalised exponentiated gradient.

    Returns
    -------
    trace : ndarray, shape ``(...)``
        The smallest trace seen over the iterations.
    lam : ndarray, shape ``(..., N)``
        The last weights.
    """
    n = Minv.shape[-3]
    lam = np.full(Minv.shape[:-2], 1.0 / n)
    best = None
    for _ in range(n_iter):
        A = np.einsum("...n,...nij->...ij", lam, Minv)
        Ai = inv2(A)
        tr = Ai[..., 0, 0] + Ai[..., 1, 1]
        best = tr if best is None else np.minimum(best, tr)
        AiAi = Ai @ Ai
        grad = -np.einsum("...ij,...nji->...n", AiAi, Minv)  # d tr A^{-1} / d lam_n
        g = grad / np.maximum(np.abs(grad).max(-1, keepdims=True), 1e-300)
        lam = lam * np.exp(-step * g)
        lam = lam / lam.sum(-1, keepdims=True)
    A = np.einsum("...n,...nij->...ij", lam, Minv)
    Ai = inv2(A)
    best = np.minimum(best, Ai[..., 0, 0] + Ai[..., 1, 1])
    return best, lam


def evader_move(x_t, agents, model: NoiseModel, step: float, n_headings: int, n_iter: int = 60):
    """Greedy evasive move, eqs (19) and (21): maximise ``tr Q_fused`` over the next position.

    Candidates are ``x_t`` itself and ``x_t + step (cos phi, sin phi)`` for ``n_headings``
    equally spaced headings; the target knows each agent's position and the sensor model,
    not the filters (Section V).

    Parameters
    ----------
    x_t : ndarray, shape ``(R, 2)``
        Target positions of ``R`` runs.
    agents : ndarray, shape ``(R, N, 2)``
    model : NoiseModel
    step : float
        Step length.
    n_headings : int
        Number of headings.
    n_iter : int
        Iterations of :func:`min_fused_trace`.

    Returns
    -------
    x_next : ndarray, shape ``(R, 2)``
    value : ndarray, shape ``(R,)``
        The maximised ``tr Q_fused``.
    """
    phi = 2 * np.pi * np.arange(n_headings) / n_headings
    offs = np.concatenate([np.zeros((1, 2)), step * np.stack([np.cos(phi), np.sin(phi)], -1)])
    cand = x_t[:, None, :] + offs[None]  # (R, H+1, 2)
    r, th = geometry(cand, agents[:, None, :, :])  # (R, H+1, N)
    Minv = noise_information(r, th, model)
    tr, _ = min_fused_trace(Minv, n_iter)
    best = np.argmax(tr, axis=1)
    idx = np.arange(len(x_t))
    return cand[idx, best], tr[idx, best]
