"""Compiled (numba) kernels of the `markov` paper: the conditional (Rao-Blackwellised) estimator
of ``E||P_k||`` (:func:`.estimators.rb_mean_norm`, eq. 4 along the trailing loss run).

The numpy form of :func:`.estimators.rb_mean_norm` keeps, for every path, the ``k - 1`` matrices
``h^{k-1-i}(P_{i+1})`` and pushes them all through ``h`` (eq. 4) at every ``k``: ``O(N T^2)`` tiny
matrix products, each a separate BLAS call. :func:`rb_norm_kernel` runs the same recursion path
by path in one compiled loop, with the arithmetic of the numpy form:

* ``h(X) = A X A' + Q`` as ``(A X) A'`` with every dot product accumulated left to right by fused
  multiply-adds (``fastmath={"contract"}``, no reassociation), which is what OpenBLAS's small
  ``dgemm`` kernels do (the unit test compares both bit for bit on this machine);
* ``||X||`` by the closed forms of :func:`.model.sym_norm` (``n = 2, 3``), ``inf`` for non-finite;
* the weighted sum over the last reception time by numpy's pairwise summation (``np.sum``).

:func:`riccati_step_2x1` is the step of eqs. (4)-(5) of :func:`.estimators.rb_trace_grid` for two
states and one output, with the rounding of numpy's forms (:func:`.model.riccati_g`,
:func:`.model.riccati_h`) on this platform: ``A X`` and ``X A'`` accumulated left to right by fused
multiply-adds (OpenBLAS's small ``dgemm``), ``P C'`` from the last coordinate down (its ``dgemv``),
``C (P C')`` without a fused multiply-add (its ``ddot``); the unit test compares both bit for bit.

Compiled code is cached on disk by numba (next to this file).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ...engines.intrinsics import fma

__all__ = ["rb_norm_kernel", "pairwise_sum", "riccati_step_2x1", "riccati_branch_2x1"]


@njit(cache=True, boundscheck=False)
def _pairwise_block(a, lo, n):
    """numpy's pairwise summation of ``a[lo:lo+n]`` for ``n <= 128`` (8 partial sums, then the rest)."""
    if n < 8:
        res = 0.0
        for i in range(n):
            res += a[lo + i]
        return res
    r0 = a[lo]
    r1 = a[lo + 1]
    r2 = a[lo + 2]
    r3 = a[lo + 3]
    r4 = a[lo + 4]
    r5 = a[lo + 5]
    r6 = a[lo + 6]
    r7 = a[lo + 7]
    i = 8
    stop = n - (n % 8)
    while i < stop:
        r0 += a[lo + i]
        r1 += a[lo + i + 1]
        r2 += a[lo + i + 2]
        r3 += a[lo + i + 3]
        r4 += a[lo + i + 4]
        r5 += a[lo + i + 5]
        r6 += a[lo + i + 6]
        r7 += a[lo + i + 7]
        i += 8
    res = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
    while i < n:
        res += a[lo + i]
        i += 1
    return res


STACK_DEPTH = 128  # frames of the pairwise split tree (its depth is about log2(n / 128) + 2)


def pairwise_sum(a, lo, n):
    """``np.sum(a[lo:lo+n])`` with numpy's pairwise summation (:func:`_pairwise_sum_into` with fresh
    work arrays).

    Parameters
    ----------
    a : ndarray
        One-dimensional float array.
    lo, n : int
        First index and length of the range.

    Returns
    -------
    float
        The sum, rounded as ``np.sum`` rounds it.
    """
    frames, vals = _pairwise_work()
    return _pairwise_sum_into(np.ascontiguousarray(a, dtype=float), lo, n, frames, vals)


def _pairwise_work():
    """Work arrays of :func:`_pairwise_sum_into`: allocated by the caller, not in compiled code (each
    ``np.empty`` form is one more overload to compile on a cold cache)."""
    return np.empty((STACK_DEPTH, 3), np.int64), np.empty(STACK_DEPTH)


@njit(cache=True, boundscheck=False)
def _pairwise_sum_into(a, lo, n, frames, vals):
    """``np.sum(a[lo:lo+n])`` with numpy's pairwise summation: blocks of at most 128 summed by
    :func:`_pairwise_block`, longer ranges split at ``n2 = n // 2 - (n // 2) % 8`` and the halves added
    (left + right). Written with an explicit stack (``frames``: ``(lo, n, state)`` rows, ``vals``:
    partial sums): numba's on-disk cache does not support recursion. Every range, a single block
    too, goes through the stack so that :func:`_pairwise_block` is compiled for one signature only.
    """
    top, nv = 0, 0
    frames[0, 0], frames[0, 1], frames[0, 2] = lo, n, 0
    while top >= 0:
        l, m, st = frames[top, 0], frames[top, 1], frames[top, 2]
        if m <= 128:
            vals[nv] = _pairwise_block(a, l, m)
            nv += 1
            top -= 1
            continue
        n2 = m // 2
        n2 -= n2 % 8
        if st == 0:  # push the left half
            frames[top, 2] = 1
            top += 1
            frames[top, 0], frames[top, 1], frames[top, 2] = l, n2, 0
        elif st == 1:  # push the right half
            frames[top, 2] = 2
            top += 1
            frames[top, 0], frames[top, 1], frames[top, 2] = l + n2, m - n2, 0
        else:  # both halves done: left + right
            right = vals[nv - 1]
            left = vals[nv - 2]
            nv -= 2
            vals[nv] = left + right
            nv += 1
            top -= 1
    return vals[0]


@njit(cache=True, boundscheck=False, fastmath={"contract"})
def _h_inplace(X, A, Q, tmp):
    """``X <- A X A' + Q`` (eq. 4), products accumulated left to right (as the BLAS kernel does)."""
    n = A.shape[0]
    for i in range(n):
        for j in range(n):
            s = A[i, 0] * X[0, j]
            for l in range(1, n):
                s += A[i, l] * X[l, j]
            tmp[i, j] = s
    for i in range(n):
        for j in range(n):
            s = tmp[i, 0] * A[j, 0]
            for l in range(1, n):
                s += tmp[i, l] * A[j, l]
            X[i, j] = s + Q[i, j]


@njit(cache=True, boundscheck=False)
def _copy_into(dst, src):
    """``dst[:, :] = src`` element by element: numba's slice assignment compiles its shape-mismatch
    error message (dozens of string overloads, seconds of cold compile) for a copy of n x n floats."""
    n = src.shape[0]
    for i in range(n):
        for j in range(n):
            dst[i, j] = src[i, j]


@njit(cache=True, boundscheck=False)
def _norm(X, which_trace):
    """:func:`.model.sym_norm` (largest eigenvalue, closed forms for n = 2, 3) or the trace of one matrix."""
    n = X.shape[0]
    if which_trace:
        s = 0.0
        for i in range(n):
            s += X[i, i]
        return s
    for i in range(n):
        for j in range(n):
            if not math.isfinite(X[i, j]):
                return np.inf
    if n == 1:
        return X[0, 0]
    if n == 2:
        a, d = X[0, 0], X[1, 1]
        b = 0.5 * (X[0, 1] + X[1, 0])
        t = a - d
        return 0.5 * (a + d) + math.sqrt(0.25 * (t * t) + b * b)
    # n == 3: model._largest_eigenvalue_3x3 on 0.5 (X + X'), scalars only
    s00 = 0.5 * (X[0, 0] + X[0, 0])
    s01 = 0.5 * (X[0, 1] + X[1, 0])
    s02 = 0.5 * (X[0, 2] + X[2, 0])
    s10 = 0.5 * (X[1, 0] + X[0, 1])
    s11 = 0.5 * (X[1, 1] + X[1, 1])
    s12 = 0.5 * (X[1, 2] + X[2, 1])
    s20 = 0.5 * (X[2, 0] + X[0, 2])
    s21 = 0.5 * (X[2, 1] + X[1, 2])
    s22 = 0.5 * (X[2, 2] + X[2, 2])
    q = (s00 + s11 + s22) / 3.0
    z = q * 0.0  # off-diagonal entries of q I (nan if q is not finite, as in numpy)
    d00, d01, d02 = s00 - q, s01 - z, s02 - z
    d10, d11, d12 = s10 - z, s11 - q, s12 - z
    d20, d21, d22 = s20 - z, s21 - z, s22 - q
    # np.sum over the 9 squares: numpy's pairwise sum of 9 terms (8 partial sums, then the ninth)
    ssq = (((d00 * d00 + d01 * d01) + (d02 * d02 + d10 * d10)) + ((d11 * d11 + d12 * d12) + (d20 * d20 + d21 * d21))
           ) + d22 * d22
    p = math.sqrt(ssq / 6.0)
    if not p > 0:
        return q
    b00, b11, b22 = d00 / p, d11 / p, d22 / p
    b01, b02, b12 = d01 / p, d02 / p, d12 / p
    det = b00 * (b11 * b22 - b12 * b12) - b01 * (b01 * b22 - b12 * b02) + b02 * (b01 * b12 - b11 * b02)
    r = det / 2.0
    if r != r:
        r = 0.0
    if r < -1.0:  # clip to [-1, 1] by comparisons (min/max would compile two more overloads)
        r = -1.0
    elif r > 1.0:
        r = 1.0
    phi = math.acos(r) / 3.0
    return q + 2.0 * p * math.cos(phi)


def rb_norm_kernel(P, arrivals, A, Q, W, which_trace, out):
    """Per-path values of :func:`.estimators.rb_mean_norm` (eq. 4 along the trailing loss run).

    Parameters
    ----------
    P : ndarray, shape (N, T+1, n, n)
        Covariances ``P_1..P_{T+1}`` along each path (C-contiguous float64).
    arrivals : ndarray of bool, shape (N, T)
        ``gamma_1..gamma_T`` per path.
    A, Q : ndarray, shape (n, n)
        System matrix and process noise covariance.
    W : ndarray, shape (T+1, T)
        ``W[k-1, i-1]``: the weight of the last reception ``i`` for ``P_k`` (the probability of
        the trailing loss run).
    which_trace : bool
        The trace of ``P_k`` instead of its norm.
    out : ndarray, shape (N, T+1)
        Filled in place.

    Returns
    -------
    out : ndarray ``(N, T+1)``
        The per-path values (the ``out`` argument).
    """
    T, n = P.shape[1] - 1, A.shape[0]
    frames, vals = _pairwise_work()
    # work arrays from here rather than np.empty in the compiled loop (fewer overloads to compile)
    return _rb_norm_paths(P, arrivals, A, Q, W, which_trace, out, np.empty((max(T, 1), n, n)), np.empty((n, n)),
                          np.empty(max(T, 1)), frames, vals)


@njit(cache=True, boundscheck=False)
def _rb_norm_paths(P, arrivals, A, Q, W, which_trace, out, H, tmp, row, frames, vals):
    """The loop of :func:`rb_norm_kernel` over paths and ``k``; ``H`` ``(T, n, n)``, ``tmp`` ``(n, n)``,
    ``row`` ``(T,)``, ``frames`` and ``vals`` (:func:`_pairwise_work`) are work arrays."""
    N, T1 = P.shape[0], P.shape[1]
    T = T1 - 1
    for a in range(N):
        out[a, 0] = _norm(P[a, 0], which_trace)
        for k in range(2, T + 2):
            for c in range(k - 2):
                _h_inplace(H[c], A, Q, tmp)
            _copy_into(H[k - 2], P[a, k - 1])
            for c in range(k - 1):
                if arrivals[a, c]:
                    row[c] = W[k - 1, c] * _norm(H[c], which_trace)
                else:
                    row[c] = 0.0
            out[a, k - 1] = _pairwise_sum_into(row, 0, k - 1, frames, vals)
    return out


def riccati_step_2x1(P, received, A, C, Q, R):
    """One step of eqs. (4)-(5) for a batch of paths of a system with 2 states and 1 output.

    ``g(P)`` (eq. 5, :func:`.model.riccati_g`, symmetrised) where ``received``, else ``h(P)`` (eq. 4,
    :func:`.model.riccati_h`), matrix by matrix in one compiled loop, with the rounding of those numpy
    forms (module docstring): the same numbers as ``np.where(received, g(P), h(P))``.

    Parameters
    ----------
    P : ndarray, shape (N, 2, 2)
        Covariances.
    received : ndarray of bool, shape (N,)
        ``gamma_k`` per path.
    A, Q : ndarray, shape (2, 2)
        System matrix and process noise covariance.
    C : ndarray, shape (1, 2)
        Output matrix.
    R : ndarray, shape (1, 1)
        Measurement noise variance.

    Returns
    -------
    ndarray, shape (N, 2, 2)
        The covariances one step on.

    Raises
    ------
    ValueError
        If the shapes are not those of a 2-state, 1-output system.
    """
    P = np.ascontiguousarray(P, dtype=float)
    received = np.ascontiguousarray(received, dtype=np.bool_)
    A, C, Q, R = (np.ascontiguousarray(x, dtype=float) for x in (A, C, Q, R))
    if (P.ndim != 3 or P.shape[1:] != (2, 2) or received.shape != P.shape[:1] or A.shape != (2, 2)
            or C.shape != (1, 2) or Q.shape != (2, 2) or R.shape != (1, 1)):
        raise ValueError("riccati_step_2x1 needs P (N, 2, 2), received (N,), A and Q (2, 2), C (1, 2), R (1, 1)")
    out = np.empty_like(P)
    _riccati_step_2x1(P, received, A, C, Q, R, out)
    return out



def riccati_branch_2x1(P, A, C, Q, R):
    """``np.concatenate([g(P), h(P)])`` for 2 states and 1 output: every path's reception, then its loss
    (the branching of the exact tree of :mod:`.exact`), in one compiled loop with the rounding of
    :func:`riccati_step_2x1` (the same numbers as numpy's :func:`.model.riccati_g`, :func:`.model.riccati_h`).

    Parameters
    ----------
    P : ndarray, shape (N, 2, 2)
        Covariances.
    A, Q : ndarray, shape (2, 2)
        System matrix and process noise covariance.
    C : ndarray, shape (1, 2)
        Output matrix.
    R : ndarray, shape (1, 1)
        Measurement noise variance.

    Returns
    -------
    ndarray, shape (2N, 2, 2)
        ``g`` of every matrix, then ``h`` of every matrix.

    Raises
    ------
    ValueError
        If the shapes are not those of a 2-state, 1-output system.
    """
    P = np.ascontiguousarray(P, dtype=float)
    A, C, Q, R = (np.ascontiguousarray(x, dtype=float) for x in (A, C, Q, R))
    if (P.ndim != 3 or P.shape[1:] != (2, 2) or A.shape != (2, 2) or C.shape != (1, 2) or Q.shape != (2, 2)
            or R.shape != (1, 1)):
        raise ValueError("riccati_branch_2x1 needs P (N, 2, 2), A and Q (2, 2), C (1, 2), R (1, 1)")
    out = np.empty((2 * len(P), 2, 2))
    _riccati_branch_2x1(P, A, C, Q, R, out)
    return out

@njit(boundscheck=False, inline="always")
def _riccati_2x1(x00, x01, x10, x11, g, A, C, Q, R):
    """``g(X)`` (``g`` true) or ``h(X)`` of one 2 x 2 matrix ``X`` (entries in row order), one output:
    explicit FMAs, no fastmath (module docstring); returns the four entries of the result."""
    a00, a01, a10, a11 = A[0, 0], A[0, 1], A[1, 0], A[1, 1]
    if g:  # P - P C' (C P C' + R)^{-1} C P: the scalar innovation divides
        c0, c1 = C[0, 0], C[0, 1]
        u0 = fma(x00, c0, x01 * c1)  # P C' (gemv: last coordinate first)
        u1 = fma(x10, c0, x11 * c1)
        s = (c0 * u0 + c1 * u1) + R[0, 0]  # C (P C') (dot: no FMA), + R
        v0 = u0 / s
        v1 = u1 / s
        x00 = x00 - u0 * v0
        x01 = x01 - u0 * v1
        x10 = x10 - u1 * v0
        x11 = x11 - u1 * v1
    t00 = fma(a01, x10, a00 * x00)  # A X (left to right by FMA)
    t01 = fma(a01, x11, a00 * x01)
    t10 = fma(a11, x10, a10 * x00)
    t11 = fma(a11, x11, a10 * x01)
    o00 = fma(t01, a01, t00 * a00) + Q[0, 0]  # (A X) A' + Q
    o01 = fma(t01, a11, t00 * a10) + Q[0, 1]
    o10 = fma(t11, a01, t10 * a00) + Q[1, 0]
    o11 = fma(t11, a11, t10 * a10) + Q[1, 1]
    if g:  # riccati_g symmetrises, riccati_h does not
        return 0.5 * (o00 + o00), 0.5 * (o01 + o10), 0.5 * (o10 + o01), 0.5 * (o11 + o11)
    return o00, o01, o10, o11


@njit(cache=True, boundscheck=False)
def _riccati_step_2x1(P, received, A, C, Q, R, out):
    """The loop of :func:`riccati_step_2x1` on checked arguments."""
    for b in range(P.shape[0]):
        x00, x01, x10, x11 = P[b, 0, 0], P[b, 0, 1], P[b, 1, 0], P[b, 1, 1]
        if received[b]:  # a constant flag in each call: two branch-free bodies
            y = _riccati_2x1(x00, x01, x10, x11, True, A, C, Q, R)
        else:
            y = _riccati_2x1(x00, x01, x10, x11, False, A, C, Q, R)
        out[b, 0, 0], out[b, 0, 1], out[b, 1, 0], out[b, 1, 1] = y


@njit(cache=True, boundscheck=False)
def _riccati_branch_2x1(P, A, C, Q, R, out):
    """The loop of :func:`riccati_branch_2x1` on checked arguments."""
    N = P.shape[0]
    for b in range(N):
        x00, x01, x10, x11 = P[b, 0, 0], P[b, 0, 1], P[b, 1, 0], P[b, 1, 1]
        y = _riccati_2x1(x00, x01, x10, x11, True, A, C, Q, R)
        out[b, 0, 0], out[b, 0, 1], out[b, 1, 0], out[b, 1, 1] = y
        y = _riccati_2x1(x00, x01, x10, x11, False, A, C, Q, R)
        out[N + b, 0, 0], out[N + b, 0, 1], out[N + b, 1, 0], out[N + b, 1, 1] = y
