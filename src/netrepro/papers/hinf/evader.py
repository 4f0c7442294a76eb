"""The evasive target of the `hinf` paper, eqs (19)-(24).

The target knows the agents' positions and the sensor model (not the filters) and moves,
greedily, to where the smallest ellipse over-bounding the intersection of the agents'
uncertainty ellipses (22) is largest.
"""

from __future__ import annotations

import numpy as np

from .algebra import inv2
from .noise import NoiseModel, geometry, noise_information

__all__ = ["overbounding_ellipse", "fused_trace", "min_fused_trace", "min_fused_trace_pairwise", "fused_trace_bounds",
           "evader_move",
           "evader_decisions"]


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


def _trace_det(A):
    return A[..., 0, 0] + A[..., 1, 1], A[..., 0, 0] * A[..., 1, 1] - A[..., 0, 1] * A[..., 1, 0]


def min_fused_trace_pairwise(Minv, n_iter: int = 60):
    """``min_lambda tr (sum_j lam_j M_j^{-1})^{-1}`` on the simplex by pairwise Frank-Wolfe with exact line search.

    Same problem as :func:`min_fused_trace` (eq (24) for ellipses with a common centre). Each
    iteration moves weight from the worst active vertex (largest partial derivative among
    ``lam_j > 0``) to the best vertex (smallest partial derivative) along ``d = e_s - e_v``.
    Along ``A + t D`` (``D = M_s^{-1} - M_v^{-1}``) a 2x2 matrix has ``tr = a + b t`` and
    ``det = c + d t + e t^2``, so ``f(t) = tr/det`` is minimised exactly: its stationary points
    solve ``b e t^2 + 2 a e t - (b c - a d) = 0``; the best of the roots in ``[0, lam_v]`` and the
    end points is taken. Pairwise Frank-Wolfe converges linearly on a polytope, so the
    Frank-Wolfe gap of :func:`fused_trace_bounds` falls fast (it certifies the result).

    Parameters
    ----------
    Minv : ndarray, shape ``(..., N, 2, 2)``
    n_iter : int
        Iterations.

    Returns
    -------
    trace : ndarray, shape ``(...)``
        ``f`` at the final weights (non-increasing over the iterations).
    lam : ndarray, shape ``(..., N)``
    """
    n = Minv.shape[-3]
    lam = np.full(Minv.shape[:-2], 1.0 / n)
    lead = lam.shape[:-1]
    idx = tuple(np.indices(lead))
    for _ in range(n_iter):
        A = np.einsum("...n,...nij->...ij", lam, Minv)
        Ai = inv2(A)
        grad = -np.einsum("...ij,...nji->...n", Ai @ Ai, Minv)
        s = grad.argmin(-1)
        v = np.where(lam > 0, grad, -np.inf).argmax(-1)
        tmax = lam[idx + (v,)]
        D = Minv[idx + (s,)] - Minv[idx + (v,)]
        a, c = _trace_det(A)
        b, e = _trace_det(D)
        d = A[..., 0, 0] * D[..., 1, 1] + A[..., 1, 1] * D[..., 0, 0] - 2 * A[..., 0, 1] * D[..., 0, 1]
        qa, qb, qc = b * e, 2 * a * e, -(b * c - a * d)
        with np.errstate(divide="ignore", invalid="ignore"):
            disc = np.sqrt(qb * qb - 4 * qa * qc)
            lin = -qc / qb
            r1 = np.where(np.abs(qa) > 0, (-qb + disc) / (2 * qa), lin)
            r2 = np.where(np.abs(qa) > 0, (-qb - disc) / (2 * qa), lin)
            cands = np.stack([np.zeros_like(tmax), tmax, r1, r2], -1)
            cands = np.where(np.isfinite(cands), np.clip(cands, 0.0, tmax[..., None]), 0.0)
            fv = (a[..., None] + b[..., None] * cands) / (c[..., None] + d[..., None] * cands + e[..., None] * cands ** 2)
            fv = np.where(fv > 0, fv, np.inf)  # a non-positive determinant would leave the PD cone
        t = np.take_along_axis(cands, fv.argmin(-1)[..., None], -1)[..., 0]
        t = np.where(s == v, 0.0, t)
        lam[idx + (s,)] += t
        lam[idx + (v,)] -= t
        lam[idx + (v,)] = np.maximum(lam[idx + (v,)], 0.0)
    A = np.einsum("...n,...nij->...ij", lam, Minv)
    Ai = inv2(A)
    return Ai[..., 0, 0] + Ai[..., 1, 1], lam


def fused_trace_bounds(Minv, lam):
    """Value and certified lower bound of ``min_lambda tr (sum_j lam_j M_j^{-1})^{-1}`` at weights ``lam``.

    ``f(lam) = tr A(lam)^{-1}``, ``A = sum_j lam_j M_j^{-1}``, is convex on the simplex (``tr X^{-1}`` is
    convex on positive definite matrices, ``A`` linear in ``lam``), so for any ``lam`` the Frank-Wolfe
    (duality) gap ``g = grad f . lam - min_j (grad f)_j`` bounds the suboptimality:
    ``f(lam) - g <= min f <= f(lam)``, with ``(grad f)_j = -tr(A^{-1} M_j^{-1} A^{-1})``. This is the
    certificate of the inner optimisation of eqs (22)-(24).

    Parameters
    ----------
    Minv : ndarray, shape ``(..., N, 2, 2)``
    lam : ndarray, shape ``(..., N)``
        Weights on the simplex.

    Returns
    -------
    value, lower : ndarray, shape ``(...)``
        ``f(lam)`` and ``f(lam) - g``.
    """
    A = np.einsum("...n,...nij->...ij", lam, Minv)
    Ai = inv2(A)
    value = Ai[..., 0, 0] + Ai[..., 1, 1]
    grad = -np.einsum("...ij,...nji->...n", Ai @ Ai, Minv)
    gap = np.einsum("...n,...n->...", grad, lam) - grad.min(-1)
    return value, value - gap


def evader_decisions(x_t, agents, model: NoiseModel, step: float, n_headings: int, n_iter: int,
                     solver: str = "mirror"):
    """The evader's choice among its candidate steps (eq (19)) with a certificate of the inner minimisation.

    For each decision, every candidate's ``min_lambda tr Q_fused`` is bracketed by
    :func:`min_fused_trace` (upper bound: the best value found in ``n_iter`` iterations) and
    :func:`fused_trace_bounds` (lower bound). The choice (largest upper bound, as
    :func:`evader_move`) is certified when its lower bound is at least every other candidate's
    upper bound: then no amount of further iteration can change it.

    Parameters
    ----------
    x_t : ndarray, shape ``(D, 2)``
        Target positions of ``D`` decisions.
    agents : ndarray, shape ``(D, N, 2)``
    model : NoiseModel
    step : float
    n_headings : int
    n_iter : int
        Iterations of the inner solver.
    solver : {"mirror", "pairwise"}
        :func:`min_fused_trace` or :func:`min_fused_trace_pairwise`.

    Returns
    -------
    dict
        ``choice (D,)`` index of the chosen candidate (0: stand still), ``certified (D,)``,
        ``upper, lower (D, H+1)`` the brackets of each candidate's value, ``gap (D,)`` largest
        ``upper - lower`` over the candidates (the solver's tolerance reached), ``margin (D,)``
        best minus second-best upper bound.
    """
    phi = 2 * np.pi * np.arange(n_headings) / n_headings
    offs = np.concatenate([np.zeros((1, 2)), step * np.stack([np.cos(phi), np.sin(phi)], -1)])
    cand = x_t[:, None, :] + offs[None]
    r, th = geometry(cand, agents[:, None, :, :])
    Minv = noise_information(r, th, model)
    upper, lam = (min_fused_trace_pairwise if solver == "pairwise" else min_fused_trace)(Minv, n_iter)
    _, lower = fused_trace_bounds(Minv, lam)
    lower = np.minimum(lower, upper)
    choice = np.argmax(upper, axis=1)
    idx = np.arange(len(x_t))
    others = upper.copy()
    others[idx, choice] = -np.inf
    second = others.max(axis=1)
    return {"choice": choice, "certified": lower[idx, choice] >= second, "upper": upper, "lower": lower,
            "gap": (upper - lower).max(axis=1), "margin": upper[idx, choice] - second}


def evader_move(x_t, agents, model: NoiseModel, step: float, n_headings: int, n_iter: int = 60,
                solver: str = "mirror"):
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
        Iterations of the inner solver.
    solver : {"mirror", "pairwise"}
        :func:`min_fused_trace` (the configured evader) or :func:`min_fused_trace_pairwise`.

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
    tr, _ = (min_fused_trace_pairwise if solver == "pairwise" else min_fused_trace)(Minv, n_iter)
    best = np.argmax(tr, axis=1)
    idx = np.arange(len(x_t))
    return cand[idx, best], tr[idx, best]
