"""Compiled (numba) kernel of the evader's pairwise Frank-Wolfe solver, eq (24) of the `hinf` paper.

Imported lazily by :func:`.evader.min_fused_trace_pairwise`, so that the steps that do not use it do not
import numba. The kernel replays, per instance and in the same floating-point order, the numpy expressions
of :func:`.evader._min_fused_trace_pairwise_numpy`, so that its results are bit-identical.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .filter_kernels import fma

__all__ = ["pairwise_kernel"]


# --------------------------------------------------------------------------- compiled kernels (numba)
# The kernels below replay, per instance and in the same floating-point order, the numpy expressions of the
# solvers above, so that their results are bit-identical: ``einsum("...n,...nij->...ij")`` sums the weights
# sequentially, ``Ai @ Ai`` (numpy's stacked 2x2 matmul through OpenBLAS) rounds ``fma(a_i1, b_1j, a_i0 b_0j)``
# and ``einsum("...ij,...nji->...n")`` adds ``(t_00 + t_10) + (t_01 + t_11)``. No fastmath; ``fma`` is
# :func:`.filter_kernels.fma`, the correctly rounded ``llvm.fma``.
@njit(cache=True, error_model="numpy")
def _fused_A(M, lam, A):
    """``A = sum_n lam_n M_n`` (sequential, as ``einsum``) into ``A (2, 2)``."""
    for i in range(2):
        for j in range(2):
            acc = 0.0
            for n in range(M.shape[0]):
                acc += lam[n] * M[n, i, j]
            A[i, j] = acc


@njit(cache=True, error_model="numpy")
def _inv2_into(A, Ai):
    """``inv2`` of :mod:`.algebra` for one matrix."""
    d = A[0, 0] * A[1, 1] - A[0, 1] * A[1, 0]
    Ai[0, 0] = A[1, 1] / d
    Ai[1, 1] = A[0, 0] / d
    Ai[0, 1] = -A[0, 1] / d
    Ai[1, 0] = -A[1, 0] / d


@njit(cache=True, error_model="numpy")
def _trace_grad(M, Ai, C, grad):
    """``grad_n = -tr(Ai Ai M_n)`` as ``-einsum("ij,nji->n", Ai @ Ai, M)``; ``C`` receives ``Ai @ Ai``."""
    for i in range(2):
        for j in range(2):
            C[i, j] = fma(Ai[i, 1], Ai[1, j], Ai[i, 0] * Ai[0, j])
    for n in range(M.shape[0]):
        grad[n] = -((C[0, 0] * M[n, 0, 0] + C[1, 0] * M[n, 0, 1]) + (C[0, 1] * M[n, 1, 0] + C[1, 1] * M[n, 1, 1]))


@njit(cache=True, error_model="numpy")
def _argmin(x):
    """``np.argmin`` (first occurrence; a nan wins)."""
    best = 0
    if np.isnan(x[0]):
        return 0
    for i in range(1, x.shape[0]):
        if np.isnan(x[i]):
            return i
        if x[i] < x[best]:
            best = i
    return best


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
    A = np.empty((2, 2))
    Ai = np.empty((2, 2))
    C = np.empty((2, 2))
    grad = np.empty(n)
    masked = np.empty(n)
    cands = np.empty(4)
    fv = np.empty(4)
    for r in range(m):
        M = Minv[r]
        lr = lam[r]
        for _ in range(n_iter):
            _fused_A(M, lr, A)
            _inv2_into(A, Ai)
            _trace_grad(M, Ai, C, grad)
            s = _argmin(grad)
            for q in range(n):
                masked[q] = -grad[q] if lr[q] > 0 else np.inf  # argmax(x) == argmin(-x) incl. first occurrence
            v = _argmin(masked)
            tmax = lr[v]
            D00 = M[s, 0, 0] - M[v, 0, 0]
            D01 = M[s, 0, 1] - M[v, 0, 1]
            D10 = M[s, 1, 0] - M[v, 1, 0]
            D11 = M[s, 1, 1] - M[v, 1, 1]
            a = A[0, 0] + A[1, 1]
            c = A[0, 0] * A[1, 1] - A[0, 1] * A[1, 0]
            b = D00 + D11
            e = D00 * D11 - D01 * D10
            d = A[0, 0] * D11 + A[1, 1] * D00 - 2 * A[0, 1] * D01
            qa, qb, qc = b * e, 2 * a * e, -(b * c - a * d)
            disc = np.sqrt(qb * qb - 4 * qa * qc)
            lin = -qc / qb
            if np.abs(qa) > 0:
                r1 = (-qb + disc) / (2 * qa)
                r2 = (-qb - disc) / (2 * qa)
            else:
                r1 = lin
                r2 = lin
            cands[0] = 0.0
            cands[1] = tmax
            cands[2] = r1
            cands[3] = r2
            for q in range(4):
                x = cands[q]
                if np.isfinite(x):
                    cands[q] = min(max(x, 0.0), tmax)
                else:
                    cands[q] = 0.0
                x = cands[q]
                f = (a + b * x) / (c + d * x + e * (x * x))
                fv[q] = f if f > 0 else np.inf
            t = cands[_argmin(fv)]
            if s == v:
                t = 0.0
            lr[s] += t
            lr[v] -= t
            lr[v] = max(lr[v], 0.0)
        _fused_A(M, lr, A)
        _inv2_into(A, Ai)
        trace[r] = Ai[0, 0] + Ai[1, 1]
    return trace
