"""The evasive target of the `hinf` paper, eqs (19)-(24).

The target knows the agents' positions and the sensor model (not the filters) and moves,
greedily, to where the smallest ellipse over-bounding the intersection of the agents'
uncertainty ellipses (22) is largest. The inner minimisation over the weights lambda of (24) is solved
exactly and certified (:func:`min_fused_trace_exact`, the configured ``evader.solver``); mirror descent
(:func:`min_fused_trace`) and pairwise Frank-Wolfe (:func:`min_fused_trace_pairwise`) are kept for the
convergence check (issue 17).
"""

from __future__ import annotations

import numpy as np

from .algebra import inv2, use_compiled
from .noise import NoiseModel, geometry, noise_information

from itertools import combinations

__all__ = ["overbounding_ellipse", "fused_trace", "min_fused_trace", "min_fused_trace_pairwise", "min_fused_trace_exact",
           "fused_trace_bounds", "EXACT_TOLERANCE", "SOLVERS", "evader_move", "fused_trace_along",
           "evader_decisions"]


def overbounding_ellipse(A, b, rho):
    """The map ``(q, Q) = F(A, b, rho)`` of eq (23).

    .. math:: Q = [1 + b^T A^{-1} b - \\rho] A^{-1}, \\qquad q = A^{-1} b

    ``{x : x^T A x - 2 b^T x + rho <= 1} = {x : (x - q)^T Q^{-1} (x - q) <= 1}``.

    Parameters
    ----------
    A : ndarray, shape ``(..., 2, 2)``
        Symmetric positive definite matrices ``A > 0``.
    b : ndarray, shape ``(..., 2)``
        Vectors ``b``.
    rho : ndarray, shape ``(...)``
        Scalars ``rho``.

    Returns
    -------
    q : ndarray, shape ``(..., 2)``
        Centre ``q = A^{-1} b`` of the ellipse.
    Q : ndarray, shape ``(..., 2, 2)``
        Shape matrix ``[1 + b^T A^{-1} b - rho] A^{-1}`` of the ellipse.
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
        The agents' informations ``M_j^{-1}`` (inverse measurement covariances, eq (3)) at a (candidate) target position.
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


def _start_weights(Minv, lam0):
    """``(N, lam, lead)``: agents, a fresh copy of the starting weights (uniform by default), batch shape."""
    n = Minv.shape[-3]
    lam = np.full(Minv.shape[:-2], 1.0 / n) if lam0 is None else np.array(lam0, dtype=float)
    return n, lam, lam.shape[:-1]


def _min_fused_trace_pairwise_numpy(Minv, n_iter: int = 60, lam0=None):
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
    lam0 : ndarray, shape ``(..., N)``, optional
        Starting weights (default: uniform).

    Returns
    -------
    trace : ndarray, shape ``(...)``
        ``f`` at the final weights (non-increasing over the iterations).
    lam : ndarray, shape ``(..., N)``
    """
    n, lam, lead = _start_weights(Minv, lam0)
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


def min_fused_trace_pairwise(Minv, n_iter: int = 60, lam0=None):
    """``min_lambda tr (sum_j lam_j M_j^{-1})^{-1}`` on the simplex by pairwise Frank-Wolfe with exact line search.

    The algorithm of :func:`_min_fused_trace_pairwise_numpy` (the tested numpy reference: see its docstring for
    the method, eq (24)), run per instance by a compiled kernel in the same floating-point order (bit-identical).

    Parameters
    ----------
    Minv : ndarray, shape ``(..., N, 2, 2)``
        The agents' informations ``M_j^{-1}`` (inverse measurement covariances, eq (3)) at a (candidate) target position.
    n_iter : int
        Iterations.
    lam0 : ndarray, shape ``(..., N)``, optional
        Starting weights (default: uniform).

    Returns
    -------
    trace : ndarray, shape ``(...)``
        ``f`` at the final weights (non-increasing over the iterations).
    lam : ndarray, shape ``(..., N)``
        The final weights.
    """
    Minv = np.asarray(Minv, dtype=float)
    n, lam, lead = _start_weights(Minv, lam0)
    Mf = np.ascontiguousarray(np.broadcast_to(Minv, lead + Minv.shape[-3:])).reshape(-1, n, 2, 2)
    lf = np.ascontiguousarray(lam).reshape(-1, n)
    from .evader_kernels import pairwise_kernel  # numba is imported (and the kernel loaded) only when used
    trace = pairwise_kernel(Mf, lf, int(n_iter))
    return trace.reshape(lead), lf.reshape(lead + (n,))


EXACT_TOLERANCE = 1e-12
"""Relative Frank-Wolfe gap (of :func:`fused_trace_bounds`) that :func:`min_fused_trace_exact` guarantees."""

EXACT_COMPILED_MIN_BATCH = 256
"""Fewest instances for which ``kernel="auto"`` of :func:`min_fused_trace_exact` runs its compiled kernel."""


def _sym_coords(Minv):
    """``(a, b, d)`` of the symmetric 2x2 matrices ``[[a, b], [b, d]]``, shape ``(..., 3)``."""
    return np.stack([Minv[..., 0, 0], 0.5 * (Minv[..., 0, 1] + Minv[..., 1, 0]), Minv[..., 1, 1]], -1)


def _polarised_det(s):
    """``H_ij = (a_i d_j + a_j d_i) / 2 - b_i b_j`` for ``s = (a, b, d)`` of shape ``(..., N, 3)``: ``det(sum lam_j S_j)
    = lam^T H lam``."""
    a, b, d = s[..., 0], s[..., 1], s[..., 2]
    return 0.5 * (a[..., :, None] * d[..., None, :] + d[..., :, None] * a[..., None, :]) - b[..., :, None] * b[..., None, :]


def _face_stationary(H, l, combos):
    """Stationary point of ``f = tr A / det A`` on the relative interior of each face ``combos`` of the simplex.

    With ``A = sum_j lam_j S_j`` on a face with vertices ``J`` (``|J| = k <= 3``), ``tr A = l . lam`` and
    ``det A = lam^T H lam``, ``H`` of ``_polarised_det``. The Lagrange condition ``grad f = mu 1`` with
    ``sum lam = 1`` (Euler: ``mu = -f``) reads ``2 (l . lam) H lam = det A (l + (l . lam) 1)``; with
    ``P = adj(H) l``, ``R = adj(H) 1`` its solution is ``L = tr A = sqrt((l . P) / (1 . R))`` and
    ``lam = (P + L R) / 1 . (P + L R)``. No iteration: the point is exact up to rounding. Faces whose ``H`` is
    singular (``S_j`` linearly dependent) have their minimum on a smaller face, which is enumerated too.

    Parameters
    ----------
    H : ndarray, shape ``(m, N, N)``
    l : ndarray, shape ``(m, N)``
        ``tr S_j``.
    combos : ndarray of int, shape ``(C, k)``

    Returns
    -------
    lam : ndarray, shape ``(m, C, k)``
        Not yet checked for feasibility (may be negative or nan).
    h : dict
        ``h[i, j]`` (``i <= j``), shape ``(m, C)``: the entries of ``H`` on each face.
    lj : list
        ``lj[i]``, shape ``(m, C)``: ``tr S_j`` of the face's ``i``-th vertex.
    """
    k = combos.shape[1]
    h = {(i, j): H[:, combos[:, i], combos[:, j]] for i in range(k) for j in range(i, k)}  # (m, C) each
    lj = [l[:, combos[:, i]] for i in range(k)]
    if k == 1:
        adj = {(0, 0): np.ones_like(h[0, 0])}
    elif k == 2:
        adj = {(0, 0): h[1, 1], (1, 1): h[0, 0], (0, 1): -h[0, 1]}
    else:
        adj = {(0, 0): h[1, 1] * h[2, 2] - h[1, 2] ** 2, (1, 1): h[0, 0] * h[2, 2] - h[0, 2] ** 2,
               (2, 2): h[0, 0] * h[1, 1] - h[0, 1] ** 2, (0, 1): h[0, 2] * h[1, 2] - h[0, 1] * h[2, 2],
               (0, 2): h[0, 1] * h[1, 2] - h[0, 2] * h[1, 1], (1, 2): h[0, 1] * h[0, 2] - h[0, 0] * h[1, 2]}

    def e(i, j, m=adj):
        return m[(i, j) if i <= j else (j, i)]

    P = [sum(e(i, j) * lj[j] for j in range(k)) for i in range(k)]
    R = [sum(e(i, j) for j in range(k)) for i in range(k)]
    with np.errstate(divide="ignore", invalid="ignore"):
        L = np.sqrt(sum(lj[i] * P[i] for i in range(k)) / sum(R))
        num = np.stack([P[i] + L * R[i] for i in range(k)], -1)
        lam = num / num.sum(-1, keepdims=True)
    return lam, h, lj


def _newton_polish(s, l, lam, steps: int = 3):
    """Newton steps on the KKT system of ``f = tr A / det A`` restricted to the support of each ``lam`` (size <= 3).

    Refines closed-form points whose face is nearly degenerate (``H`` of ``_face_stationary`` ill-conditioned,
    e.g. two agents at almost the same place), where rounding leaves a Frank-Wolfe gap above the tolerance.
    ``s (M, N, 3)``, ``l (M, N)``, ``lam (M, N)``; returns refined weights (each step kept only if feasible).
    """
    lam = lam.copy()
    k_of = (lam > 0).sum(-1)
    for k in (2, 3):
        rows = np.nonzero(k_of == k)[0]
        if len(rows) == 0:
            continue
        J = np.argsort(-lam[rows], -1)[:, :k]                      # the support
        sj = np.take_along_axis(s[rows], J[..., None], 1)          # (m, k, 3)
        lj = np.take_along_axis(l[rows], J, 1)
        a, b, d = sj[..., 0], sj[..., 1], sj[..., 2]
        H = 0.5 * (a[:, :, None] * d[:, None, :] + d[:, :, None] * a[:, None, :]) - b[:, :, None] * b[:, None, :]
        x = np.take_along_axis(lam[rows], J, 1)
        for _ in range(steps):
            L = np.einsum("mi,mi->m", lj, x)
            h = np.einsum("mij,mj->mi", H, x)
            Q = np.einsum("mi,mi->m", x, h)
            g = lj / Q[:, None] - 2 * L[:, None] * h / Q[:, None] ** 2
            hess = (-2 * (lj[:, :, None] * h[:, None, :] + h[:, :, None] * lj[:, None, :]) / Q[:, None, None] ** 2
                    - 2 * L[:, None, None] * H / Q[:, None, None] ** 2
                    + 8 * L[:, None, None] * h[:, :, None] * h[:, None, :] / Q[:, None, None] ** 3)
            mu = np.einsum("mi,mi->m", g, x)
            K = np.zeros((len(rows), k + 1, k + 1))
            K[:, :k, :k] = hess
            K[:, :k, k] = -1.0
            K[:, k, :k] = 1.0
            rhs = -np.concatenate([g - mu[:, None], (x.sum(-1) - 1.0)[:, None]], -1)
            step = np.einsum("mij,mj->mi", np.linalg.pinv(K), rhs)[:, :k]
            new = x + step
            ok = np.all(new >= 0, -1) & np.all(np.isfinite(new), -1)
            x = np.where(ok[:, None], new, x)
        x = x / x.sum(-1, keepdims=True)
        out = np.zeros((len(rows), lam.shape[-1]))
        np.put_along_axis(out, J, x, 1)
        lam[rows] = out
    return lam


def _best_on_faces_numpy(Hf, lf, combos, rows, best_f, best_lam):
    """The best stationary point over the faces ``combos`` for the instances ``rows`` (in place, numpy form).

    Per instance, the closed-form stationary point of each face (:func:`_face_stationary`), kept if its weights
    are non-negative; the first face of smallest ``f`` replaces ``best_f``, ``best_lam`` (the whole row) if
    strictly smaller. :func:`.evader_kernels.faces_kernel` is its compiled form (bit-identical).
    """
    n, k = lf.shape[1], combos.shape[1]
    lam, h, lj = _face_stationary(Hf[rows], lf[rows], combos)  # lam (m, C, k)
    ok = np.all(np.isfinite(lam), -1) & np.all(lam >= -1e-12, -1)
    lam = np.where(ok[..., None], np.clip(lam, 0.0, None), 1.0 / k)
    lam = lam / lam.sum(-1, keepdims=True)
    tr = sum(lam[..., i] * lj[i] for i in range(k))
    det = sum((1 if i == j else 2) * lam[..., i] * lam[..., j] * h[i, j] for i in range(k) for j in range(i, k))
    with np.errstate(divide="ignore", invalid="ignore"):
        f = np.where(ok & (det > 0), tr / det, np.inf)
    c = f.argmin(-1)
    fc = f[np.arange(len(rows)), c]
    better = fc < best_f[rows]
    full = np.zeros((len(rows), n))
    np.put_along_axis(full, combos[c], lam[np.arange(len(rows)), c], -1)
    upd = rows[better]
    best_f[upd] = fc[better]
    best_lam[upd] = full[better]


def min_fused_trace_exact(Minv, tol: float = EXACT_TOLERANCE, kernel: str = "auto"):
    """Exact ``min_lambda tr (sum_j lam_j M_j^{-1})^{-1}`` on the simplex, eqs (22)-(24), with a certificate.

    Same problem as :func:`min_fused_trace` (the smallest ellipse (24) over-bounding the intersection (22)
    of ellipses with a common centre, its trace ``Q = F(A, b, rho)`` of (23) at ``A = sum_j lam_j M_j^{-1}``),
    solved without iterating. ``f(lam) = tr A^{-1} = tr A / det A`` for 2x2 ``A``; ``tr X^{-1}`` is strictly
    convex and decreasing on positive definite matrices, so the minimiser ``A*`` is unique and lies on the
    boundary of the convex hull of the ``S_j = M_j^{-1}`` in the 3-dimensional space of symmetric 2x2
    matrices: some optimal ``lam`` has at most 3 non-zero weights (a vertex, an edge or a triangle of the
    hull). Every support of size 1, 2 and 3 is enumerated (``N + N(N-1)/2 + N(N-1)(N-2)/6``; 175 for
    ``N = 10``); on each, the stationary point of ``f`` on the face is found in closed form (see
    ``_face_stationary``: a square root, no polynomial root finding), kept if its weights are
    non-negative, and the smallest ``f`` over the kept points is the minimum. Triangles are solved only for
    the instances whose best vertex or edge is not already certified optimal by its Frank-Wolfe gap (the
    optimum is then on a triangle). Vectorised over the leading axes and the supports (no loop over decisions).

    The result is certified by :func:`fused_trace_bounds`: its Frank-Wolfe gap is checked to be at most
    ``tol`` times the value for every instance (``ArithmeticError`` otherwise).

    Parameters
    ----------
    Minv : ndarray, shape ``(..., N, 2, 2)``
        The agents' informations ``M_j^{-1}`` (symmetric positive definite).
    tol : float
        Relative Frank-Wolfe gap guaranteed (default :data:`EXACT_TOLERANCE`).
    kernel : {"auto", "compiled", "numpy"}
        ``"compiled"``: the faces of each size by :func:`.evader_kernels.faces_kernel`, the determinant form and
        the certificate's value and gradient by :func:`.evader_kernels.polarised_det_kernel` and
        :func:`.evader_kernels.bounds_kernel`, the same arithmetic instance by instance (bit-identical); ``"numpy"``: the reference form; ``"auto"``: see
        :func:`.algebra.use_compiled`, and at least :data:`EXACT_COMPILED_MIN_BATCH` instances.

    Returns
    -------
    trace : ndarray, shape ``(...)``
        The minimum ``f(lam)``.
    lam : ndarray, shape ``(..., N)``
        Minimising weights (at most 3 non-zero).
    """
    Minv = np.asarray(Minv, dtype=float)
    n = Minv.shape[-3]
    s = _sym_coords(Minv)                              # (..., N, 3)
    l = s[..., 0] + s[..., 2]                          # tr S_j
    lead = Minv.shape[:-3]
    Mf, sf, lf = Minv.reshape(-1, n, 2, 2), s.reshape(-1, n, 3), l.reshape(-1, n)
    best_f = np.full(len(sf), np.inf)
    best_lam = np.zeros((len(sf), n))
    rows = np.arange(len(sf))  # instances still to be solved
    # "auto": the kernel saves about 2 us per instance; it costs about 0.5 s to compile once (numba's cache keeps it,
    # a cached load is ~0.05 s), so it runs on batches of a few hundred instances (an evader deciding for >= 16 runs)
    compiled = use_compiled(kernel, Minv.size // 4) and (kernel == "compiled" or len(sf) >= EXACT_COMPILED_MIN_BATCH)
    if compiled:
        from .evader_kernels import faces_kernel, polarised_det_kernel  # numba: used where it is already loaded
        Mf, sf = np.ascontiguousarray(Mf), np.ascontiguousarray(sf)
        Hf = np.empty((len(sf), n, n))
        polarised_det_kernel(sf, Hf)                   # (M, N, N), bit-identical to _polarised_det
    else:
        Hf = _polarised_det(sf)                        # (M, N, N)
    bounds = None  # fused_trace_bounds at the current best_lam, once computed (reused while best_lam is unchanged)
    for k in (1, 2, 3):
        if k > n or len(rows) == 0:
            break
        if k == 3:  # triangles only where no vertex or edge is already certified (the Frank-Wolfe gap decides)
            value, lower = bounds = _fused_trace_bounds_flat(Mf, best_lam, compiled)
            rows = np.nonzero(value - lower > 0.01 * tol * np.abs(value))[0]
            if len(rows) == 0:
                break
            bounds = None
        combos = np.asarray(list(combinations(range(n), k)))
        if compiled:
            faces_kernel(np.ascontiguousarray(Hf), np.ascontiguousarray(lf), combos, rows, best_f, best_lam)
        else:
            _best_on_faces_numpy(Hf, lf, combos, rows, best_f, best_lam)
    value, lower = bounds if bounds is not None else _fused_trace_bounds_flat(Mf, best_lam, compiled)
    rough = value - lower > 0.01 * tol * np.abs(value)  # nearly degenerate faces: polish by Newton, keep if better
    if rough.any():
        bad = np.nonzero(rough)[0]
        pol = _newton_polish(sf[bad], lf[bad], best_lam[bad])
        v2, lo2 = _fused_trace_bounds_flat(Mf[bad], pol, compiled)
        keep = v2 - lo2 < (value - lower)[bad]
        best_lam[bad[keep]] = pol[keep]
        value, lower = _fused_trace_bounds_flat(Mf, best_lam, compiled)
    failing = value - lower > tol * np.abs(value)
    if failing.any():  # rare (none in the default runs): the certificate would fail; try harder before raising
        _rescue_degenerate(Mf, sf, lf, best_lam, np.nonzero(failing)[0])
        value, lower = fused_trace_bounds(Mf, best_lam)
    value, lower, best_lam = value.reshape(lead), lower.reshape(lead), best_lam.reshape(lead + (n,))
    if not np.all(value - lower <= tol * np.abs(value)):
        worst = float(np.max((value - lower) / np.abs(value)))
        raise ArithmeticError(f"min_fused_trace_exact: relative Frank-Wolfe gap {worst:.3g} above tolerance {tol:g}")
    return value, best_lam


def _rescue_degenerate(Mf, sf, lf, best_lam, bad, steps: int = 10) -> None:
    """Polish the instances whose Frank-Wolfe gap still exceeds the tolerance; update ``best_lam`` in place.

    Seen at 2000 paired runs of the evasive loop: agents whose informations ``M_j^{-1}`` nearly coincide
    make a face of the hull nearly flat, and the best closed-form point of its supports then sits on an
    edge while the optimum needs the third, almost identical agent (relative gaps 1e-11 to 1.1e-9). Two
    tries, each kept only where it lowers the gap: more Newton steps on the current support, and Newton on
    the support enlarged by each absent agent (given weight 1e-9 to enter it), where that support has at
    most 3 agents. The certificate that follows is unchanged.
    """
    value, lower = fused_trace_bounds(Mf[bad], best_lam[bad])
    gap = value - lower
    starts = [best_lam[bad]]
    k_of = (best_lam[bad] > 0).sum(-1)
    for j in range(best_lam.shape[-1]):
        grown = best_lam[bad].copy()
        absent = (grown[:, j] == 0) & (k_of < 3)
        if absent.any():
            grown[absent, j] = 1e-9
            starts.append(grown / grown.sum(-1, keepdims=True))
    for start in starts:
        pol = _newton_polish(sf[bad], lf[bad], start, steps=steps)
        v2, lo2 = fused_trace_bounds(Mf[bad], pol)
        better = v2 - lo2 < gap
        best_lam[bad[better]] = pol[better]
        gap = np.where(better, v2 - lo2, gap)


def _fused_trace_bounds_flat(Mf, lam, compiled: bool):
    """:func:`fused_trace_bounds` of ``Mf (M, N, 2, 2)``, ``lam (M, N)``; ``compiled``: value and gradient by
    :func:`.evader_kernels.bounds_kernel` (bit-identical), the gap in numpy as there."""
    if not compiled:
        return fused_trace_bounds(Mf, lam)
    from .evader_kernels import bounds_kernel

    Mf = np.ascontiguousarray(Mf, dtype=float)
    lam = np.ascontiguousarray(lam, dtype=float)
    value, grad = np.empty(len(lam)), np.empty(lam.shape)
    bounds_kernel(Mf, lam, value, grad)
    gmin = grad[:, 0].copy()  # grad.min(-1) column by column (a minimum is exact: the same numbers, ~10x faster)
    for j in range(1, grad.shape[1]):
        np.minimum(gmin, grad[:, j], out=gmin)
    gap = np.einsum("...n,...n->...", grad, lam) - gmin
    return value, value - gap


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
        The agents' informations ``M_j^{-1}`` (inverse measurement covariances, eq (3)) at a (candidate) target position.
    lam : ndarray, shape ``(..., N)``
        Weights on the simplex.

    Returns
    -------
    value, lower : ndarray, shape ``(...)``
        ``f(lam)`` and ``f(lam) - g``.
    """
    _, value, grad, gap = _value_gradient_gap(Minv, lam)
    return value, value - gap


def _value_gradient_gap(Minv, lam):
    """``A = sum_j lam_j M_j^{-1}``, ``f = tr A^{-1}``, its gradient and Frank-Wolfe gap at ``lam`` (eq (24));
    shared by the certificate :func:`fused_trace_bounds` and the evader's brackets (:func:`_bracket_at`)."""
    A = np.einsum("...n,...nij->...ij", lam, Minv)
    Ai = inv2(A)
    value = Ai[..., 0, 0] + Ai[..., 1, 1]
    grad = -np.einsum("...ij,...nji->...n", Ai @ Ai, Minv)
    gap = np.einsum("...n,...n->...", grad, lam) - grad.min(-1)
    return A, value, grad, gap


def fused_trace_along(target, agents, model: NoiseModel):
    """The evader's objective along recorded paths: ``tr Q_fused`` of eqs (21)-(24) at every step ``k >= 1``.

    At step ``k`` the target's position is ``x_k`` and the agents are where the evader saw them when it chose
    ``x_k`` (``p_{k-1}``: in :func:`.model.simulate` the target moves first); the value is the minimum over the
    weights lambda of eq (24), solved exactly and certified (:func:`min_fused_trace_exact`). For an evasive
    target this is the value (19) the evader maximised at each step; for any other path, the same objective
    on its positions, so an evader and a non-reactive path can be compared on it.

    Parameters
    ----------
    target : ndarray, shape ``(R, K + 1, 2)``
        Target positions (``simulate(...)["target"]``).
    agents : ndarray, shape ``(R, K + 1, N, 2)``
        Agent positions (``simulate(...)["agents"]``).
    model : NoiseModel
        The noise model (2)-(4).

    Returns
    -------
    ndarray, shape ``(R, K)``
        ``tr Q_fused`` at steps ``1..K``.
    """
    x = np.asarray(target, dtype=float)[:, 1:]
    p = np.asarray(agents, dtype=float)[:, :-1]
    R, K, N = p.shape[0], p.shape[1], p.shape[2]
    r, th = geometry(x.reshape(R * K, 2), p.reshape(R * K, N, 2))
    return min_fused_trace_exact(noise_information(r, th, model))[0].reshape(R, K)


SOLVERS = {"mirror": min_fused_trace, "pairwise": min_fused_trace_pairwise,
           "exact": lambda Minv, n_iter=None, kernel="auto": min_fused_trace_exact(Minv, kernel=kernel)}
"""Inner solvers of the evader by name, each called as ``solver(Minv, n_iter)`` (``exact`` ignores ``n_iter`` and
takes the ``kernel`` of :func:`min_fused_trace_exact`)."""


def _inner(solver: str):
    if solver not in SOLVERS:
        raise ValueError(f"unknown evader solver {solver!r}; expected one of {sorted(SOLVERS)}")
    return SOLVERS[solver]


def evader_decisions(x_t, agents, model: NoiseModel, step: float, n_headings: int, n_iter: int,
                     solver: str = "mirror"):
    """The evader's choice among its candidate steps (eq (19)) with a certificate of the inner minimisation.

    For each decision, every candidate's ``min_lambda tr Q_fused`` is bracketed by the inner
    ``solver`` (upper bound: the value it returns; the iterative solvers after ``n_iter`` iterations) and
    :func:`fused_trace_bounds` at the solver's weights (lower bound). The choice (largest upper bound, as
    :func:`evader_move`) is certified when its lower bound is at least every other candidate's
    upper bound: then no amount of further iteration can change it.

    Parameters
    ----------
    x_t : ndarray, shape ``(D, 2)``
        Target positions of ``D`` decisions.
    agents : ndarray, shape ``(D, N, 2)``
        The ``N`` agents' positions at each decision.
    model : NoiseModel
        The range-bearing noise model of eqs (3)-(4) (``a0``, ``a1``, ``a2``, ``alpha``).
    step : float
        Step length of the target (the candidates' distance from ``x_t``).
    n_headings : int
        Number of equally spaced headings (candidates besides standing still).
    n_iter : int
        Iterations of the inner solver.
    solver : {"mirror", "pairwise", "exact"}
        :func:`min_fused_trace`, :func:`min_fused_trace_pairwise` or :func:`min_fused_trace_exact`.

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
    upper, lam = _inner(solver)(Minv, n_iter)
    if use_compiled("auto", Minv.size // 4):  # the certificate by the compiled kernel (bit-identical)
        n = Minv.shape[-3]
        _, lower = _fused_trace_bounds_flat(Minv.reshape(-1, n, 2, 2), lam.reshape(-1, n), True)
        lower = lower.reshape(upper.shape)
    else:
        _, lower = fused_trace_bounds(Minv, lam)
    lower = np.minimum(lower, upper)
    choice = np.argmax(upper, axis=1)
    idx = np.arange(len(x_t))
    others = upper.copy()
    others[idx, choice] = -np.inf
    second = others.max(axis=1)
    return {"choice": choice, "certified": lower[idx, choice] >= second, "upper": upper, "lower": lower,
            "gap": (upper - lower).max(axis=1), "margin": upper[idx, choice] - second}


CERTIFY_MARGIN = 1e-9
"""Relative margin by which :func:`evader_move` (``solver="exact"``) must separate a candidate's bracket from the
best lower bound to skip its exact solve (see :func:`_certified_exact_values`)."""

CERTIFY_SCALE_MAX = 1e4
"""Largest rounding scale (``tr(A)^2 / det A`` and ``max_j |grad_j| / f``) of a bracket that
:func:`_certified_exact_values` trusts; a run with a larger one has every candidate solved exactly."""


SUPPORT_ROUNDS = 3
"""Active-set corrections of the guessed support in :func:`_support_bracket_numpy` (after the first face)."""


def _bracket_at(Mf, w):
    """``f(w)``, its Frank-Wolfe lower bound, the rounding scale and the gradient at weights ``w`` (eq (24))."""
    A, value, grad, gap = _value_gradient_gap(Mf, w)
    tr, det = _trace_det(A)
    with np.errstate(divide="ignore", invalid="ignore"):
        scale = np.where((det > 0) & (value > 0), np.maximum(tr * tr / det, np.abs(grad).max(-1) / value), np.inf)
    return value, value - gap, scale, grad


def _support_bracket_numpy(Mf, lam0, rounds: int = SUPPORT_ROUNDS):
    """Bracket ``[lower, value]`` of ``min_lambda tr (sum_j lam_j M_j^{-1})^{-1}`` from a guessed support (eq (24)).

    Every point ``w`` of the simplex gives ``lower(w) = f(w) - g(w) <= min f <= f(w) = value(w)`` (``g`` the
    Frank-Wolfe gap, as :func:`fused_trace_bounds`); the bracket is the smallest ``value`` and the largest
    ``lower`` over the points tried: the stationary point of ``f = tr A / det A`` on the face spanned by the
    support of ``lam0`` (at most 3 agents; the closed form of ``_face_stationary``) and up to ``rounds``
    active-set corrections of that support (a vertex with a negative, infeasible weight is dropped; where
    the point is feasible but its gap is above ``1e-12 f``, the vertex of smallest gradient is added or, on a
    triangle, replaces the vertex of smallest weight), or ``lam0`` itself where none of these points is
    feasible. When the support is the
    optimum's, or a correction away (the usual case for candidates a step apart), the bracket is as tight as
    the exact solver's certificate. Also returned: the largest rounding scale
    ``max(tr(A)^2 / det A, max_j |grad_j| / f)`` over the points (see :func:`_certified_exact_values`).

    Parameters
    ----------
    Mf : ndarray, shape ``(M, N, 2, 2)``
        The informations ``M_j^{-1}`` (symmetric positive definite) of ``M`` instances.
    lam0 : ndarray, shape ``(M, N)``
        Weights on the simplex whose support is tried first.
    rounds : int
        Corrections of the support (:data:`SUPPORT_ROUNDS`).

    Returns
    -------
    value, lower, scale : ndarray, shape ``(M,)``
    """
    Mf = np.asarray(Mf, dtype=float)
    lam0 = np.asarray(lam0, dtype=float)
    m, n = lam0.shape
    s = _sym_coords(Mf)
    l = s[..., 0] + s[..., 2]
    value, lower, scale = np.full(m, np.inf), np.full(m, -np.inf), np.zeros(m)
    found = np.zeros(m, dtype=bool)
    sup = lam0 > 0
    active = (sup.sum(-1) >= 1) & (sup.sum(-1) <= 3)
    for _ in range(rounds + 1):
        rows = np.nonzero(active)[0]
        if len(rows) == 0:
            break
        k_of = sup[rows].sum(-1)
        raw = np.zeros((len(rows), n))
        for k in (1, 2, 3):
            sub = np.nonzero(k_of == k)[0]
            if len(sub) == 0:
                continue
            J = np.sort(np.argsort(~sup[rows[sub]], -1, kind="stable")[:, :k], -1)  # the support, ascending
            sJ = np.take_along_axis(s[rows[sub]], J[..., None], 1)
            lJ = np.take_along_axis(l[rows[sub]], J, 1)
            lam, _, _ = _face_stationary(_polarised_det(sJ), lJ, np.arange(k)[None, :])
            part = np.zeros((len(sub), n))
            np.put_along_axis(part, J, lam[:, 0], 1)
            raw[sub] = part
        feas = np.all(np.isfinite(raw) & (raw >= 0), -1)
        nxt = sup[rows].copy()
        if feas.any():
            fr = rows[feas]
            v, lo, sc, g = _bracket_at(Mf[fr], raw[feas])
            value[fr], lower[fr] = np.minimum(value[fr], v), np.maximum(lower[fr], lo)
            scale[fr] = np.maximum(scale[fr], sc)
            found[fr] = True
            loose = ~(v - lo <= 1e-12 * v)
            add = g.argmin(-1)
            i = np.nonzero(feas)[0][loose]
            full = k_of[i] == 3
            drop = np.where(raw[i] > 0, raw[i], np.inf).argmin(-1)
            nxt[i[full], drop[full]] = False
            nxt[i, add[loose]] = True
        bad = np.nonzero(~feas & np.all(~np.isnan(raw), -1))[0]
        if len(bad):
            nxt[bad, np.where(sup[rows[bad]], raw[bad], np.inf).argmin(-1)] = False
        changed = np.any(nxt != sup[rows], -1) & (nxt.sum(-1) >= 1) & (nxt.sum(-1) <= 3)
        sup[rows] = nxt
        active[:] = False
        active[rows[changed]] = True
    if not found.all():  # no feasible face point: the hint itself (a point of the simplex)
        nf = np.nonzero(~found)[0]
        value[nf], lower[nf], scale[nf], _ = _bracket_at(Mf[nf], lam0[nf])
    return value, lower, scale


def _approx_information(cand, agents, model: NoiseModel):
    """``M_j^{-1}`` of eq (3) at candidate positions, without transcendental functions (for brackets only).

    ``M^{-1} = T diag(1/f_r, 1/f_b) T^T`` with ``T`` the rotation by the bearing, whose cosine and sine are
    taken as ``dx / r`` and ``dy / r`` (``r = sqrt(dx^2 + dy^2)``) instead of ``cos(arctan2(dy, dx))``: the
    same matrices up to a few ulps (:func:`.noise.noise_information` is the exact form the solver uses).

    Parameters
    ----------
    cand : ndarray, shape ``(R, C, 2)``
        Candidate target positions.
    agents : ndarray, shape ``(R, N, 2)``
        Agent positions.
    model : NoiseModel
        The range-bearing noise model of eqs (3)-(4).

    Returns
    -------
    ndarray, shape ``(R, C, N, 2, 2)``
        Not finite where a candidate is on an agent (range 0).
    """
    d = np.asarray(cand, dtype=float)[:, :, None, :] - np.asarray(agents, dtype=float)[:, None, :, :]
    dx, dy = d[..., 0], d[..., 1]
    with np.errstate(divide="ignore", invalid="ignore"):
        r = np.sqrt(dx * dx + dy * dy)
        co, si = dx / r, dy / r
        fr = model.a2 * (r - model.a1) ** 2 + model.a0
        ir = 1.0 / fr
        ib = ir / model.alpha
        S = np.empty(r.shape + (2, 2))
        S[..., 0, 0] = co * co * ir + si * si * ib
        S[..., 0, 1] = S[..., 1, 0] = co * si * (ir - ib)
        S[..., 1, 1] = si * si * ir + co * co * ib
    return S


def _candidate_bracket(cand, agents, model: NoiseModel, lam0, compiled: bool, rounds: int = SUPPORT_ROUNDS):
    """Brackets of every candidate's ``min_lambda tr Q_fused`` (eq (24)) from positions and each run's hint.

    :func:`_support_bracket_numpy` (``compiled``: its kernel ``support_bracket_kernel``) on
    :func:`_approx_information`, from the hint ``lam0[i]`` for every candidate of run ``i``; the scale is at
    least ``max(alpha, 1/alpha)``, the condition number of each ``M_j^{-1}`` (the amplification of the few
    ulps by which these informations may differ from the solver's).

    Parameters
    ----------
    cand : ndarray, shape ``(R, C, 2)``
        Candidate target positions.
    agents : ndarray, shape ``(R, N, 2)``
        Agent positions.
    model : NoiseModel
        The range-bearing noise model of eqs (3)-(4).
    lam0 : ndarray, shape ``(R, N)``
        Each run's hint.
    compiled : bool
        Use the compiled kernel.
    rounds : int
        Corrections of the support (:data:`SUPPORT_ROUNDS`).

    Returns
    -------
    value, lower, scale : ndarray, shape ``(R, C)``
    """
    R, C, n = cand.shape[0], cand.shape[1], agents.shape[1]
    S = _approx_information(cand, agents, model).reshape(R * C, n, 2, 2)
    hint = np.repeat(np.asarray(lam0, dtype=float), C, 0)
    if compiled:
        from .evader_kernels import support_bracket_kernel
        value, lower, scale = np.empty(R * C), np.empty(R * C), np.empty(R * C)
        support_bracket_kernel(S, hint, int(rounds), value, lower, scale)
    else:
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            value, lower, scale = _support_bracket_numpy(S, hint, rounds)
    scale = np.maximum(scale, max(model.alpha, 1.0 / model.alpha))
    return value.reshape(R, C), lower.reshape(R, C), scale.reshape(R, C)


def _certified_exact_values(cand, agents, model: NoiseModel, lam_hint=None, margin: float = CERTIFY_MARGIN,
                            kernel: str = "auto"):
    """The evader's candidate values ``min_lambda tr Q_fused`` (eq (24)) where they can decide its move (eq (19)).

    Returns :func:`min_fused_trace_exact`'s value for every candidate that could be the (first) largest, and
    ``-inf`` for the candidates proved smaller than it, so that ``argmax`` over the result and the value there
    are those of the exact solver on every candidate (the reference), bit for bit.

    The method: each candidate is bracketed, ``lower_c <= min f_c <= value_c``, by :func:`_candidate_bracket`
    (:func:`_support_bracket_numpy` on informations formed without transcendental functions, within a few
    ulps of the solver's) from the support of ``lam_hint`` (the optimal weights of the run's previous move: the
    optimum's support rarely changes much over a step); with ``L = max_c lower_c``, a candidate with
    ``value_c (1 + margin) < L (1 - margin)`` is excluded, the others (the contenders, always including the
    candidate attaining ``L``) are solved exactly, on their informations from :func:`.noise.geometry` and
    :func:`.noise.noise_information` as the reference computes them.

    Why the exclusion is safe: let ``v_c`` be the exact solver's value of candidate ``c`` and ``b`` a candidate
    with ``lower_b = L``. The exact solver's ``v`` is ``f`` at a point of the simplex with relative
    Frank-Wolfe gap at most :data:`EXACT_TOLERANCE` (1e-12), so ``min f_c <= v_c <= min f_c (1 + 1e-12)`` up
    to rounding. The bracket's own rounding, including the few ulps by which its informations differ from
    the solver's, is relative and of order ``N eps s`` with ``eps = 2.2e-16``, ``N`` the agents and ``s`` the
    bracket's scale (``tr(A)^2 / det A`` bounds the amplification of the determinant's cancellation,
    ``max_j |grad_j| / f`` that of the gap's, ``alpha`` that of the informations' perturbation), at most
    ``10 * 2.2e-16 * 1e4 ~ 2e-11`` when ``s <= CERTIFY_SCALE_MAX`` (a candidate whose bracket has a larger
    scale or is not finite is neither excluded nor used for ``L``). Hence
    ``v_c <= value_c (1 + 1e-12 + 2e-11) < value_c (1 + margin)`` and
    ``v_b >= lower_b (1 - 2e-11) > L (1 - margin)`` for ``margin = 1e-9``: an excluded ``c`` has
    ``v_c < v_b``, it is neither the argmax nor tied with it. The exact solver's result for an instance does
    not depend on the other instances of its call (per-instance arithmetic; compiled and numpy forms
    bit-identical), and neither do the informations of a candidate (element-wise functions), so solving only
    the contenders gives the same bits (tested). Where the exact solver would fail (``ArithmeticError``) on
    an excluded candidate, the reference raises and this does not. Measured on the configured evasive loop
    (4 agents, 17 candidates, 200 runs): 11-13% of the candidates are solved exactly.

    Parameters
    ----------
    cand : ndarray, shape ``(R, C, 2)``
        The ``C`` candidate positions of ``R`` runs.
    agents : ndarray, shape ``(R, N, 2)``
        The agents' positions.
    model : NoiseModel
        The range-bearing noise model of eqs (3)-(4).
    lam_hint : ndarray, shape ``(R, N)``, optional
        Weights on the simplex whose support is tried for each run's bracket; ``None``: every candidate is
        solved exactly.
    margin : float
        Relative separation required to exclude a candidate (:data:`CERTIFY_MARGIN`); ``inf`` excludes none.
    kernel : {"auto", "compiled", "numpy"}
        Form of the exact solver and the bracket (``"auto"``: compiled where numba is loaded, whatever the
        batch size: the forms are bit-identical).

    Returns
    -------
    value : ndarray, shape ``(R, C)``
        The exact value of each contender, ``-inf`` elsewhere.
    lam : ndarray, shape ``(R, C, N)``
        The exact solver's weights of each contender, 0 elsewhere.
    """
    R, C, n = cand.shape[0], cand.shape[1], agents.shape[1]
    if kernel == "auto":
        kernel = "compiled" if use_compiled("auto", R * C * n) else "numpy"
    if lam_hint is None:
        r, th = geometry(cand, agents[:, None, :, :])
        return min_fused_trace_exact(noise_information(r, th, model), kernel=kernel)
    value, lower, scale = _candidate_bracket(cand, agents, model, lam_hint, kernel == "compiled")
    ok = np.isfinite(value) & np.isfinite(lower) & (scale <= CERTIFY_SCALE_MAX)  # nan scale: not ok
    L = np.where(ok, np.minimum(lower, value), -np.inf).max(axis=1)
    excluded = ok & (value * (1.0 + margin) < (L * (1.0 - margin))[:, None]) & (L > 0)[:, None]
    ri, ci = np.nonzero(~excluded)
    out = np.full((R, C), -np.inf)
    lam = np.zeros((R, C, n))
    r, th = geometry(cand[ri, ci], agents[ri])
    out[ri, ci], lam[ri, ci] = min_fused_trace_exact(noise_information(r, th, model), kernel=kernel)
    return out, lam


def evader_move(x_t, agents, model: NoiseModel, step: float, n_headings: int, n_iter: int = 60,
                solver: str = "mirror", state: dict | None = None):
    """Greedy evasive move, eqs (19) and (21): maximise ``tr Q_fused`` over the next position.

    Candidates are ``x_t`` itself and ``x_t + step (cos phi, sin phi)`` for ``n_headings``
    equally spaced headings; the target knows each agent's position and the sensor model,
    not the filters (Section V).

    Parameters
    ----------
    x_t : ndarray, shape ``(R, 2)``
        Target positions of ``R`` runs.
    agents : ndarray, shape ``(R, N, 2)``
        The ``N`` agents' positions in each run.
    model : NoiseModel
        The range-bearing noise model of eqs (3)-(4) (``a0``, ``a1``, ``a2``, ``alpha``).
    step : float
        Step length.
    n_headings : int
        Number of headings.
    n_iter : int
        Iterations of the inner solver.
    solver : {"mirror", "pairwise", "exact"}
        :func:`min_fused_trace`, :func:`min_fused_trace_pairwise` or :func:`min_fused_trace_exact`
        (``exact`` ignores ``n_iter``).
    state : dict, optional
        ``exact`` only: a dict the caller keeps over the moves of one simulation (start with ``{}``). With it,
        the optimal weights of each run's chosen candidate are kept in ``state["lam"]`` and, at the next move,
        only the candidates that can be the largest are solved exactly (:func:`_certified_exact_values`: the
        same move and value, bit for bit, at a fraction of the cost), where the compiled kernels are used
        (:func:`.algebra.use_compiled`). ``None``: every candidate (the reference).

    Returns
    -------
    x_next : ndarray, shape ``(R, 2)``
        The chosen next target positions.
    value : ndarray, shape ``(R,)``
        The maximised ``tr Q_fused``.
    """
    phi = 2 * np.pi * np.arange(n_headings) / n_headings
    offs = np.concatenate([np.zeros((1, 2)), step * np.stack([np.cos(phi), np.sin(phi)], -1)])
    cand = x_t[:, None, :] + offs[None]  # (R, H+1, 2)
    # certified only in compiled form: in numpy the bracket's per-call overhead exceeds its saving on the small
    # batches of the steps that do not load numba (fig6_paths: 2.98 s with it, 2.11 s without)
    certify = solver == "exact" and state is not None and use_compiled("auto", cand.shape[0] * cand.shape[1]
                                                                        * agents.shape[1])
    if certify:
        hint = state.get("lam")
        if hint is not None and np.shape(hint) != (agents.shape[0], agents.shape[1]):
            hint = None  # another simulation's weights: solve every candidate
        tr, lam = _certified_exact_values(cand, agents, model, hint)
    else:
        r, th = geometry(cand, agents[:, None, :, :])  # (R, H+1, N)
        tr, lam = _inner(solver)(noise_information(r, th, model), n_iter)
    best = np.argmax(tr, axis=1)
    idx = np.arange(len(x_t))
    if certify:
        state["lam"] = lam[idx, best]
    return cand[idx, best], tr[idx, best]

