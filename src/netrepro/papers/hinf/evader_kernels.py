"""Compiled (numba) kernels of the evader's inner solvers, eq (24) of the `hinf` paper.

``pairwise_kernel``: the pairwise Frank-Wolfe solver; ``faces_kernel``: the enumeration of the faces of the
simplex of the exact solver; ``polarised_det_kernel`` and ``bounds_kernel``: the exact solver's determinant form
and the value and gradient of its Frank-Wolfe certificate. Imported lazily by :func:`.evader.min_fused_trace_pairwise` and
:func:`.evader.min_fused_trace_exact`, so that the steps that do not use them do not import numba. Each kernel
replays, per instance and in the same floating-point order, the numpy expressions of its reference
(:func:`.evader._min_fused_trace_pairwise_numpy`, :func:`.evader._best_on_faces_numpy`,
:func:`.evader._polarised_det`, :func:`.evader.fused_trace_bounds`), so that its results
are bit-identical. Both are written on scalars (no helper functions, no scratch arrays): numba compiles them
faster, a cost a process pays once when it loads a kernel cold.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ...engines.intrinsics import fma

__all__ = ["pairwise_kernel", "faces_kernel", "polarised_det_kernel", "bounds_kernel", "support_bracket_kernel"]


# --------------------------------------------------------------------------- compiled kernel (numba)
# The kernel replays, per instance and in the same floating-point order, the numpy expressions of the solver,
# so that its results are bit-identical: ``einsum("...n,...nij->...ij")`` sums the weights sequentially,
# ``Ai @ Ai`` (numpy's stacked 2x2 matmul through OpenBLAS) rounds ``fma(a_i1, b_1j, a_i0 b_0j)`` and
# ``einsum("...ij,...nji->...n")`` adds ``(t_00 + t_10) + (t_01 + t_11)``. No fastmath; ``fma`` is
# :func:`netrepro.engines.intrinsics.fma`, the correctly rounded ``llvm.fma``. Written as one function on scalars (no
# helper functions, no scratch 2x2 arrays): numba then compiles it in about a third less time, which a
# process that loads it cold pays once.
@njit(cache=True, error_model="numpy", inline="always")
def _fused_matrix(Minv, lam, r):
    """The fused information ``A = sum_q lam[r, q] M_q^{-1}`` of instance ``r`` (eq (24)), entry by entry.

    Parameters
    ----------
    Minv : ndarray, shape (m, n, 2, 2)
        The agents' inverse informations ``M_q^{-1}`` per instance.
    lam : ndarray, shape (m, n)
        The weights ``lambda``.
    r : int
        The instance.

    Returns
    -------
    tuple of float
        ``(A00, A01, A10, A11)``, each summed over ``q`` in order (the rounding of the kernels' reference forms).
    """
    n = lam.shape[1]
    A00 = 0.0
    A01 = 0.0
    A10 = 0.0
    A11 = 0.0
    for q in range(n):
        A00 += lam[r, q] * Minv[r, q, 0, 0]
    for q in range(n):
        A01 += lam[r, q] * Minv[r, q, 0, 1]
    for q in range(n):
        A10 += lam[r, q] * Minv[r, q, 1, 0]
    for q in range(n):
        A11 += lam[r, q] * Minv[r, q, 1, 1]
    return A00, A01, A10, A11


@njit(cache=True, error_model="numpy", inline="always")
def _trace_and_gradient(A00, A01, A10, A11, c, Minv, r, grad):
    """``f = tr A^{-1}`` and its gradient ``-tr(A^{-1} A^{-1} M_q^{-1})`` at the fused matrix ``A`` of instance ``r`` (eq (24)).

    ``A^{-1} @ A^{-1}`` is rounded as numpy's stacked ``matmul`` (:func:`netrepro.engines.intrinsics.fma`).

    Parameters
    ----------
    A00, A01, A10, A11 : float
        The fused matrix ``A`` (:func:`_fused_matrix`).
    c : float
        Its determinant ``A00 A11 - A01 A10``.
    Minv : ndarray, shape (m, n, 2, 2)
        The agents' inverse informations ``M_q^{-1}`` per instance.
    r : int
        The instance.
    grad : ndarray, shape (n,)
        Output: the gradient over the agents.

    Returns
    -------
    float
        ``f`` at ``A``.
    """
    i00 = A11 / c
    i11 = A00 / c
    i01 = -A01 / c
    i10 = -A10 / c
    C00 = fma(i01, i10, i00 * i00)
    C01 = fma(i01, i11, i00 * i01)
    C10 = fma(i11, i10, i10 * i00)
    C11 = fma(i11, i11, i10 * i01)
    for q in range(Minv.shape[1]):
        grad[q] = -((C00 * Minv[r, q, 0, 0] + C10 * Minv[r, q, 0, 1])
                    + (C01 * Minv[r, q, 1, 0] + C11 * Minv[r, q, 1, 1]))
    return i00 + i11


@njit(cache=True, error_model="numpy")
def pairwise_kernel(Minv, lam, n_iter):
    """:func:`min_fused_trace_pairwise` on ``Minv (M, N, 2, 2)`` from ``lam (M, N)`` (updated in place).

    Parameters
    ----------
    Minv : ndarray ``(M, N, 2, 2)``
        Per decision ``M`` and agent ``N`` the information matrices of the fused trace (22)-(24).
    lam : ndarray ``(M, N)``
        Starting weights on the simplex; overwritten with the final weights.
    n_iter : int
        Pairwise Frank-Wolfe iterations.

    Returns
    -------
    trace : ndarray ``(M,)``
        The fused trace at the final weights.
    """
    m, n = lam.shape
    trace = np.empty(m)
    grad = np.empty(n)
    for r in range(m):
        for _ in range(n_iter):
            # A = sum_n lam_n M_n (sequential, as einsum)
            A00, A01, A10, A11 = _fused_matrix(Minv, lam, r)
            c = A00 * A11 - A01 * A10
            _trace_and_gradient(A00, A01, A10, A11, c, Minv, r, grad)
            # s = argmin(grad), v = argmax over lam > 0 (np.argmin/argmax: first occurrence, a nan wins)
            s = 0
            if not np.isnan(grad[0]):
                for q in range(1, n):
                    if np.isnan(grad[q]):
                        s = q
                        break
                    if grad[q] < grad[s]:
                        s = q
            v = 0
            bv = -grad[0] if lam[r, 0] > 0 else np.inf
            if not np.isnan(bv):
                for q in range(1, n):
                    x = -grad[q] if lam[r, q] > 0 else np.inf
                    if np.isnan(x):
                        v = q
                        break
                    if x < bv:
                        v = q
                        bv = x
            tmax = lam[r, v]
            D00 = Minv[r, s, 0, 0] - Minv[r, v, 0, 0]
            D01 = Minv[r, s, 0, 1] - Minv[r, v, 0, 1]
            D10 = Minv[r, s, 1, 0] - Minv[r, v, 1, 0]
            D11 = Minv[r, s, 1, 1] - Minv[r, v, 1, 1]
            a = A00 + A11
            b = D00 + D11
            e = D00 * D11 - D01 * D10
            d = A00 * D11 + A11 * D00 - 2 * A01 * D01
            qa, qb, qc = b * e, 2 * a * e, -(b * c - a * d)
            disc = np.sqrt(qb * qb - 4 * qa * qc)
            lin = -qc / qb
            if np.abs(qa) > 0:
                r1 = (-qb + disc) / (2 * qa)
                r2 = (-qb - disc) / (2 * qa)
            else:
                r1 = lin
                r2 = lin
            # candidates 0, tmax, r1, r2: clipped to [0, tmax] (0 if not finite); the first smallest positive f
            t = 0.0
            bf = 0.0
            for q in range(4):
                x = 0.0 if q == 0 else (tmax if q == 1 else (r1 if q == 2 else r2))
                x = min(max(x, 0.0), tmax) if np.isfinite(x) else 0.0
                f = (a + b * x) / (c + d * x + e * (x * x))
                f = f if f > 0 else np.inf
                if q == 0:
                    t = x
                    bf = f
                elif not np.isnan(bf) and (np.isnan(f) or f < bf):
                    t = x
                    bf = f
            if s == v:
                t = 0.0
            lam[r, s] += t
            lam[r, v] -= t
            lam[r, v] = max(lam[r, v], 0.0)
        A00, A01, A10, A11 = _fused_matrix(Minv, lam, r)
        d = A00 * A11 - A01 * A10
        trace[r] = A11 / d + A00 / d
    return trace


@njit(cache=True, error_model="numpy")
def faces_kernel(H, l, combos, rows, best_f, best_lam):
    """The best stationary point over the faces ``combos`` of the simplex, for the instances ``rows``.

    The compiled form of :func:`.evader._best_on_faces_numpy` (eqs (22)-(24); see
    :func:`.evader.min_fused_trace_exact`): per instance and face, the closed-form stationary point of
    ``f = tr A / det A`` of :func:`.evader._face_stationary`, kept if its weights are non-negative, and the
    first face of smallest ``f``, which replaces the instance's best if strictly smaller. Same floating-point
    operations in the same order as the numpy form (Python ``sum`` starts from ``0``; a sum over the face's
    vertices is sequential), so the results are bit-identical.

    Parameters
    ----------
    H : ndarray ``(M, N, N)``
        ``det(sum lam_j S_j) = lam^T H lam`` per instance.
    l : ndarray ``(M, N)``
        ``tr S_j``.
    combos : ndarray of int ``(C, k)``
        The faces (``k <= 3`` vertices each).
    rows : ndarray of int ``(m,)``
        Instances to solve.
    best_f : ndarray ``(M,)``
        Best value so far; updated in place.
    best_lam : ndarray ``(M, N)``
        Its weights; updated in place (a row is replaced as a whole).

    Returns
    -------
    None
    """
    C, k = combos.shape
    n = l.shape[1]
    for r in rows:
        bf = np.inf
        bc = -1
        b0 = b1 = b2 = 0.0
        for ci in range(C):
            j0 = combos[ci, 0]
            j1 = combos[ci, 1] if k > 1 else j0
            j2 = combos[ci, 2] if k > 2 else j0
            l0, l1, l2 = l[r, j0], l[r, j1], l[r, j2]
            h00, h01, h02 = H[r, j0, j0], H[r, j0, j1], H[r, j0, j2]
            h11, h12, h22 = H[r, j1, j1], H[r, j1, j2], H[r, j2, j2]
            lam1 = lam2 = 0.0
            if k == 1:
                P0 = 0.0 + 1.0 * l0
                L = np.sqrt((0.0 + l0 * P0) / (0.0 + 1.0))
                num0 = P0 + L * 1.0
                lam0 = num0 / num0
            elif k == 2:
                # adj(H) of the face: [[h11, -h01], [-h01, h00]]
                a00, a01, a11 = h11, -h01, h00
                P0 = (0.0 + a00 * l0) + a01 * l1
                P1 = (0.0 + a01 * l0) + a11 * l1
                R0 = (0.0 + a00) + a01
                R1 = (0.0 + a01) + a11
                L = np.sqrt(((0.0 + l0 * P0) + l1 * P1) / ((0.0 + R0) + R1))
                num0 = P0 + L * R0
                num1 = P1 + L * R1
                s = num0 + num1
                lam0 = num0 / s
                lam1 = num1 / s
            else:
                a00 = h11 * h22 - h12 * h12
                a11 = h00 * h22 - h02 * h02
                a22 = h00 * h11 - h01 * h01
                a01 = h02 * h12 - h01 * h22
                a02 = h01 * h12 - h02 * h11
                a12 = h01 * h02 - h00 * h12
                P0 = ((0.0 + a00 * l0) + a01 * l1) + a02 * l2
                P1 = ((0.0 + a01 * l0) + a11 * l1) + a12 * l2
                P2 = ((0.0 + a02 * l0) + a12 * l1) + a22 * l2
                R0 = ((0.0 + a00) + a01) + a02
                R1 = ((0.0 + a01) + a11) + a12
                R2 = ((0.0 + a02) + a12) + a22
                L = np.sqrt((((0.0 + l0 * P0) + l1 * P1) + l2 * P2) / (((0.0 + R0) + R1) + R2))
                num0 = P0 + L * R0
                num1 = P1 + L * R1
                num2 = P2 + L * R2
                s = (num0 + num1) + num2
                lam0 = num0 / s
                lam1 = num1 / s
                lam2 = num2 / s
            ok = np.isfinite(lam0) and lam0 >= -1e-12
            if k > 1:
                ok = ok and np.isfinite(lam1) and lam1 >= -1e-12
            if k > 2:
                ok = ok and np.isfinite(lam2) and lam2 >= -1e-12
            if ok:  # np.clip(lam, 0.0, None): -0.0 -> +0.0
                lam0 = lam0 if lam0 > 0.0 else 0.0
                lam1 = lam1 if lam1 > 0.0 else 0.0
                lam2 = lam2 if lam2 > 0.0 else 0.0
            else:
                lam0 = lam1 = lam2 = 1.0 / k
            s = lam0
            if k > 1:
                s += lam1
            if k > 2:
                s += lam2
            lam0, lam1, lam2 = lam0 / s, lam1 / s, lam2 / s
            tr = 0.0 + lam0 * l0
            det = 0.0 + 1.0 * lam0 * lam0 * h00
            if k > 1:
                tr += lam1 * l1
                det += 2.0 * lam0 * lam1 * h01
            if k > 2:
                tr += lam2 * l2
                det += 2.0 * lam0 * lam2 * h02
            if k > 1:
                det += 1.0 * lam1 * lam1 * h11
            if k > 2:
                det += 2.0 * lam1 * lam2 * h12
                det += 1.0 * lam2 * lam2 * h22
            f = tr / det if ok and det > 0 else np.inf
            # argmin over the faces: first occurrence, a nan wins (np.argmin)
            if bc == -1 or (not np.isnan(bf) and (np.isnan(f) or f < bf)):
                bc, bf, b0, b1, b2 = ci, f, lam0, lam1, lam2
        if bf < best_f[r]:
            best_f[r] = bf
            for q in range(n):
                best_lam[r, q] = 0.0
            best_lam[r, combos[bc, 0]] = b0
            if k > 1:
                best_lam[r, combos[bc, 1]] = b1
            if k > 2:
                best_lam[r, combos[bc, 2]] = b2


@njit(cache=True, error_model="numpy")
def polarised_det_kernel(s, H):
    """:func:`.evader._polarised_det` of ``s (M, N, 3)`` into ``H (M, N, N)``, the same operations in the same order.

    ``H_ij = (a_i d_j + d_i a_j) / 2 - b_i b_j`` for ``s = (a, b, d)`` (the symmetric 2x2 matrices ``S_j`` of
    eq (24)), so that ``det(sum_j lam_j S_j) = lam^T H lam``. Written into ``H`` (allocated by the caller).

    Parameters
    ----------
    s : ndarray ``(M, N, 3)``
        ``(a, b, d)`` of ``S_j = [[a, b], [b, d]]``.
    H : ndarray ``(M, N, N)``
        Output.

    Returns
    -------
    None
    """
    m, n = s.shape[0], s.shape[1]
    for r in range(m):
        for i in range(n):
            ai = s[r, i, 0]
            bi = s[r, i, 1]
            di = s[r, i, 2]
            for j in range(n):
                H[r, i, j] = 0.5 * (ai * s[r, j, 2] + di * s[r, j, 0]) - bi * s[r, j, 1]


@njit(cache=True, error_model="numpy")
def bounds_kernel(Minv, lam, value, grad):
    """Value and gradient of :func:`.evader.fused_trace_bounds` per instance, bit-identical to its numpy form.

    ``A = sum_j lam_j M_j^{-1}`` (``einsum``: sequential sum over the agents), ``A^{-1}`` by
    :func:`.algebra.inv2` (``adj(A) / det A``), ``value = tr A^{-1}`` and
    ``grad_j = -tr(A^{-1} A^{-1} M_j^{-1})`` (``A^{-1} @ A^{-1}`` rounded as numpy's stacked ``matmul``:
    ``fma(a_i1, b_1j, a_i0 b_0j)``; the trace of the product as ``einsum("...ij,...nji->...n")`` adds it), the
    same operations as :func:`pairwise_kernel`. The gap (a dot product and a minimum) stays in numpy.

    Parameters
    ----------
    Minv : ndarray ``(M, N, 2, 2)``
        The informations ``M_j^{-1}`` of eq (24).
    lam : ndarray ``(M, N)``
        Weights on the simplex.
    value : ndarray ``(M,)``
        Output: ``f(lam) = tr A^{-1}``.
    grad : ndarray ``(M, N)``
        Output: the gradient of ``f``.

    Returns
    -------
    None
    """
    for r in range(lam.shape[0]):
        A00, A01, A10, A11 = _fused_matrix(Minv, lam, r)
        value[r] = _trace_and_gradient(A00, A01, A10, A11, A00 * A11 - A01 * A10, Minv, r, grad[r])


@njit(cache=True, error_model="numpy", inline="always")
def _nmin(a, b):
    """``np.minimum(a, b)`` on scalars (a nan wins)."""
    return a if (np.isnan(a) or a <= b) else b


@njit(cache=True, error_model="numpy", inline="always")
def _nmax(a, b):
    """``np.maximum(a, b)`` on scalars (a nan wins)."""
    return a if (np.isnan(a) or a >= b) else b


@njit(cache=True, error_model="numpy", inline="always")
def _bracket_point(Minv, r, w, grad):
    """``(f(w), f(w) - gap(w), scale)`` of :func:`.evader._bracket_at` for instance ``r``; ``grad`` filled.

    Not the rounding of the numpy form (one reciprocal of the determinant, plain products): a bracket.
    """
    n = w.shape[0]
    A00 = 0.0
    A01 = 0.0
    A10 = 0.0
    A11 = 0.0
    for q in range(n):
        A00 += w[q] * Minv[r, q, 0, 0]
        A01 += w[q] * Minv[r, q, 0, 1]
        A10 += w[q] * Minv[r, q, 1, 0]
        A11 += w[q] * Minv[r, q, 1, 1]
    c = A00 * A11 - A01 * A10
    ic = 1.0 / c
    i00 = A11 * ic
    i11 = A00 * ic
    i01 = -A01 * ic
    i10 = -A10 * ic
    C00 = i00 * i00 + i01 * i10
    C01 = i00 * i01 + i01 * i11
    C10 = i10 * i00 + i11 * i10
    C11 = i10 * i01 + i11 * i11
    f = i00 + i11
    gl = 0.0
    gmin = np.inf
    gabs = 0.0
    nan = False
    for q in range(n):
        g = -((C00 * Minv[r, q, 0, 0] + C10 * Minv[r, q, 0, 1]) + (C01 * Minv[r, q, 1, 0] + C11 * Minv[r, q, 1, 1]))
        grad[q] = g
        nan = nan or np.isnan(g)
        gl += g * w[q]
        gmin = min(gmin, g)
        gabs = max(gabs, abs(g))
    if nan:
        return f, np.nan, np.nan
    scale = max((A00 + A11) * (A00 + A11) * ic, gabs / f) if (c > 0 and f > 0) else np.inf
    return f, f - (gl - gmin), scale


@njit(cache=True, error_model="numpy")
def support_bracket_kernel(Minv, lam0, rounds, value, lower, scale):
    """:func:`.evader._support_bracket_numpy` per instance: a bracket of the fused trace's minimum (eq (24)).

    The same algorithm as the numpy form: the stationary point of ``f = tr A / det A`` on the face spanned by
    the support of ``lam0`` (the closed form of :func:`.evader._face_stationary`) and up to ``rounds``
    active-set corrections of the support, or the hint ``lam0`` where no such point is feasible; the smallest
    ``f``, the largest Frank-Wolfe lower bound and the largest rounding scale over the points. Not necessarily
    the same rounding (a bracket, not a result: :func:`.evader._certified_exact_values` allows for rounding).

    Parameters
    ----------
    Minv : ndarray ``(M, N, 2, 2)``
        The informations ``M_j^{-1}``.
    lam0 : ndarray ``(M, N)``
        Weights on the simplex whose support is tried first.
    rounds : int
        Corrections of the support.
    value, lower, scale : ndarray ``(M,)``
        Outputs: the bracket ``[lower, value]`` and the scale ``max(tr(A)^2 / det A, max_j |grad_j| / f)``.

    Returns
    -------
    None
    """
    m, n = lam0.shape
    w = np.empty(n)
    raw = np.empty(n)
    grad = np.empty(n)
    sup = np.empty(n, dtype=np.bool_)
    J = np.empty(3, dtype=np.int64)
    for r in range(m):
        k = 0
        for q in range(n):
            sup[q] = lam0[r, q] > 0
            if sup[q]:
                k += 1
        bv, bl, bs = np.inf, -np.inf, 0.0
        found = False
        active = 1 <= k <= 3
        for _ in range(rounds + 1):
            if not active:
                break
            k = 0
            for q in range(n):
                raw[q] = 0.0
                if sup[q]:
                    J[k] = q
                    k += 1
            # the face's stationary point in closed form (as faces_kernel, on scalars)
            j0 = J[0]
            j1 = J[1] if k > 1 else j0
            j2 = J[2] if k > 2 else j0
            a0, d0 = Minv[r, j0, 0, 0], Minv[r, j0, 1, 1]
            a1, d1 = Minv[r, j1, 0, 0], Minv[r, j1, 1, 1]
            a2, d2 = Minv[r, j2, 0, 0], Minv[r, j2, 1, 1]
            b0 = 0.5 * (Minv[r, j0, 0, 1] + Minv[r, j0, 1, 0])
            b1 = 0.5 * (Minv[r, j1, 0, 1] + Minv[r, j1, 1, 0])
            b2 = 0.5 * (Minv[r, j2, 0, 1] + Minv[r, j2, 1, 0])
            l0, l1, l2 = a0 + d0, a1 + d1, a2 + d2
            x1 = x2 = 0.0
            if k == 1:
                n0 = l0 + np.sqrt(l0 * l0)
                x0 = n0 / n0
            else:
                h00 = a0 * d0 - b0 * b0
                h11 = a1 * d1 - b1 * b1
                h01 = 0.5 * (a0 * d1 + d0 * a1) - b0 * b1
                if k == 2:
                    P0 = h11 * l0 - h01 * l1
                    P1 = h00 * l1 - h01 * l0
                    R0 = h11 - h01
                    R1 = h00 - h01
                    L = np.sqrt((l0 * P0 + l1 * P1) / (R0 + R1))
                    n0 = P0 + L * R0
                    n1 = P1 + L * R1
                    tot = n0 + n1
                    x0 = n0 / tot
                    x1 = n1 / tot
                else:
                    h22 = a2 * d2 - b2 * b2
                    h02 = 0.5 * (a0 * d2 + d0 * a2) - b0 * b2
                    h12 = 0.5 * (a1 * d2 + d1 * a2) - b1 * b2
                    c00 = h11 * h22 - h12 * h12
                    c11 = h00 * h22 - h02 * h02
                    c22 = h00 * h11 - h01 * h01
                    c01 = h02 * h12 - h01 * h22
                    c02 = h01 * h12 - h02 * h11
                    c12 = h01 * h02 - h00 * h12
                    P0 = c00 * l0 + c01 * l1 + c02 * l2
                    P1 = c01 * l0 + c11 * l1 + c12 * l2
                    P2 = c02 * l0 + c12 * l1 + c22 * l2
                    R0 = c00 + c01 + c02
                    R1 = c01 + c11 + c12
                    R2 = c02 + c12 + c22
                    L = np.sqrt((l0 * P0 + l1 * P1 + l2 * P2) / (R0 + R1 + R2))
                    n0 = P0 + L * R0
                    n1 = P1 + L * R1
                    n2 = P2 + L * R2
                    tot = n0 + n1 + n2
                    x0 = n0 / tot
                    x1 = n1 / tot
                    x2 = n2 / tot
            raw[j0] = x0
            if k > 1:
                raw[j1] = x1
            if k > 2:
                raw[j2] = x2
            has_nan = np.isnan(x0) or np.isnan(x1) or np.isnan(x2)
            feasible = (np.isfinite(x0) and x0 >= 0.0 and np.isfinite(x1) and x1 >= 0.0
                        and np.isfinite(x2) and x2 >= 0.0)
            changed = False
            if feasible:
                for q in range(n):
                    w[q] = raw[q]
                v, lo, sc = _bracket_point(Minv, r, w, grad)
                bv, bl, bs = _nmin(bv, v), _nmax(bl, lo), _nmax(bs, sc)
                found = True
                if not (v - lo <= 1e-12 * v):
                    add = 0  # np.argmin: first occurrence, a nan wins
                    for q in range(1, n):
                        if np.isnan(grad[add]):
                            break
                        if np.isnan(grad[q]) or grad[q] < grad[add]:
                            add = q
                    if k == 3:  # np.where(raw > 0, raw, inf).argmin()
                        drop = 0
                        best = np.inf
                        for q in range(n):
                            x = raw[q] if raw[q] > 0 else np.inf
                            if x < best:
                                best = x
                                drop = q
                        if sup[drop]:
                            sup[drop] = False
                            changed = True
                    if not sup[add]:
                        sup[add] = True
                        changed = True
            elif not has_nan:  # drop the support's vertex of most negative weight
                drop = -1
                for q in range(n):
                    if sup[q] and (drop == -1 or raw[q] < raw[drop]):
                        drop = q
                sup[drop] = False
                changed = True
            k = 0
            for q in range(n):
                if sup[q]:
                    k += 1
            active = changed and 1 <= k <= 3
        if not found:  # no feasible face point: the hint itself (a point of the simplex)
            for q in range(n):
                w[q] = lam0[r, q]
            bv, bl, bs = _bracket_point(Minv, r, w, grad)
        value[r] = bv
        lower[r] = bl
        scale[r] = bs
