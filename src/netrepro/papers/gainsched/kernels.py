"""Compiled time loop of the Monte Carlo of Algorithm 1 (plant (1), (6), filter (8)-(9)), for :mod:`.model`.

The kernel runs the recursion of :func:`.model.simulate` run by run with the random draws given.
Every product of the matrix recursion is evaluated in the rounding order of the BLAS kernels
behind numpy's ``@`` on the reference platform (OpenBLAS, FMA): for ``x @ M.T`` with a
matrix ``M`` of several rows, ``acc = x_0 M_j0`` then ``acc = fma(x_q, M_jq, acc)``; for
``x @ C.T`` with one output row (``gemv``), from the last coordinate down. With at least a
few runs (tested from 7) the errors are then bit-identical to :func:`.model.simulate`, so a
Nelder-Mead search on them takes the same path. ``fma`` is IEEE (correctly rounded) on every
platform; no fastmath.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ...engines.intrinsics import fma

__all__ = ["simulate_kernel", "simulate_kernel_2x1", "KINDS"]

KINDS = {"sine_mid": 0, "lower": 1, "upper": 2}


@njit(cache=True)
def simulate_kernel(A, B, C, D, Z, d1, d2, kind, G0, Gf, H0, Hf, has_gains, p_seq, x0, xf0, u, g, sd):
    """Errors e(k) = x(k) - x_f(k) of Algorithm 1, k = 0..K, for given draws (see :func:`.model.simulate`).

    x(k+1) = A x + B f(Zx) + D x w(k), w = sd g(k); y = xi C x, xi = [u(k) < p(k)] (7);
    x_f(k+1) = G(p) x_f + H(p) y (8)-(9); f of :func:`.model.sector_nonlinearity` (``kind`` of
    :data:`KINDS`, d1, d2 the diagonals of F1, F2).

    Parameters
    ----------
    A, B, C, D, Z : ndarray
        Plant matrices of (1), (2), (6) (n x n, n x nz, m x n, n x n, nz x n).
    d1, d2 : ndarray (nz,)
        Diagonals of the sector bounds F1, F2 of (3).
    kind : int
        Index of the nonlinearity's kind in :data:`KINDS`.
    G0, Gf, H0, Hf : ndarray
        Filter parameters of (9) (n x n, n x n, n x m, n x m); unused without gains.
    has_gains : bool
        False: x_f = 0 throughout (the trivial estimate).
    p_seq : ndarray (K,)
        p(0..K-1).
    x0, xf0 : ndarray (runs, n)
        Initial plant and filter states.
    u, g : ndarray (K, runs)
        Uniform and standard normal draws of each step.
    sd : float
        sigma.

    Returns
    -------
    ndarray (runs, K+1, n)
        The estimation errors e(k) = x(k) - x_f(k).
    """
    R, n = x0.shape
    m = C.shape[0]
    nz = Z.shape[0]
    K = p_seq.shape[0]
    errs = np.empty((R, K + 1, n))
    G = np.empty((K, n, n))
    H = np.empty((K, n, m))
    for k in range(K):
        p = p_seq[k]
        for i in range(n):
            for j in range(n):
                G[k, i, j] = G0[i, j] + p * Gf[i, j]
            for j in range(m):
                H[k, i, j] = H0[i, j] + p * Hf[i, j]
    x = np.empty(n)
    xf = np.empty(n)
    xn = np.empty(n)
    xfn = np.empty(n)
    y = np.empty(m)
    f = np.empty(nz)
    for r in range(R):
        for i in range(n):
            x[i] = x0[r, i]
            xf[i] = xf0[r, i]
            errs[r, 0, i] = x[i] - xf[i]
        for k in range(K):
            p = p_seq[k]
            xi = 1.0 if u[k, r] < p else 0.0
            w = sd * g[k, r]
            for j in range(m):  # y = xi (x @ C.T)
                acc = x[n - 1] * C[j, n - 1]
                for q in range(n - 2, -1, -1):
                    acc = fma(x[q], C[j, q], acc)
                y[j] = xi * acc
            if has_gains:  # x_f @ G.T + y @ H.T
                for i in range(n):
                    a1 = xf[0] * G[k, i, 0]
                    for q in range(1, n):
                        a1 = fma(xf[q], G[k, i, q], a1)
                    a2 = y[0] * H[k, i, 0]
                    for q in range(1, m):
                        a2 = fma(y[q], H[k, i, q], a2)
                    xfn[i] = a1 + a2
                xf, xfn = xfn, xf  # swap the buffers instead of copying (less code to compile)
            for i in range(nz):  # f(x @ Z.T)
                zi = x[0] * Z[i, 0]
                for q in range(1, n):
                    zi = fma(x[q], Z[i, q], zi)
                if kind == 0:  # (F1 + F2)/2 z + (F2 - F1)/2 sin z, the numpy reference's rounding order
                    f[i] = (0.5 * (d1[i] + d2[i])) * zi + (0.5 * (d2[i] - d1[i])) * np.sin(zi)
                elif kind == 1:
                    f[i] = d1[i] * zi
                else:
                    f[i] = d2[i] * zi
            for i in range(n):  # x @ A.T + f @ B.T + w (x @ D.T)
                xa = x[0] * A[i, 0]
                xd = x[0] * D[i, 0]
                for q in range(1, n):
                    xa = fma(x[q], A[i, q], xa)
                    xd = fma(x[q], D[i, q], xd)
                fb = f[0] * B[i, 0]
                for q in range(1, nz):
                    fb = fma(f[q], B[i, q], fb)
                xn[i] = (xa + fb) + w * xd
            x, xn = xn, x
            for i in range(n):
                errs[r, k + 1, i] = x[i] - xf[i]
    return errs


@njit(cache=True)
def simulate_kernel_2x1(A, B, C, D, Z, d1, d2, kind, G0, Gf, H0, Hf, has_gains, p_seq, x0, xf0, u, g, sd):
    """:func:`simulate_kernel` for 2 states, 1 output and 2 nonlinearity channels (the paper's example).

    The same operations in the same order (so the same numbers), the loops over the coordinates
    written out and the states held in scalars rather than work arrays.

    Parameters
    ----------
    A, B, C, D, Z : ndarray
        Plant matrices (2 x 2, 2 x 2, 1 x 2, 2 x 2, 2 x 2).
    d1, d2 : ndarray (2,)
        Diagonals of the sector bounds F1, F2 of (3).
    kind : int
        Index of the nonlinearity's kind in :data:`KINDS`.
    G0, Gf, H0, Hf : ndarray
        Filter parameters of (9) (2 x 2, 2 x 2, 2 x 1, 2 x 1); unused without gains.
    has_gains : bool
        False: x_f = 0 throughout (the trivial estimate).
    p_seq : ndarray (K,)
        p(0..K-1).
    x0, xf0 : ndarray (runs, 2)
        Initial plant and filter states.
    u, g : ndarray (K, runs)
        Uniform and standard normal draws of each step.
    sd : float
        sigma.

    Returns
    -------
    ndarray (runs, K+1, 2)
        The estimation errors e(k) = x(k) - x_f(k).
    """
    R = x0.shape[0]
    K = p_seq.shape[0]
    errs = np.empty((R, K + 1, 2))
    a00, a01, a10, a11 = A[0, 0], A[0, 1], A[1, 0], A[1, 1]
    b00, b01, b10, b11 = B[0, 0], B[0, 1], B[1, 0], B[1, 1]
    e00, e01, e10, e11 = D[0, 0], D[0, 1], D[1, 0], D[1, 1]
    z00, z01, z10, z11 = Z[0, 0], Z[0, 1], Z[1, 0], Z[1, 1]
    c0, c1 = C[0, 0], C[0, 1]
    m0, m1 = 0.5 * (d1[0] + d2[0]), 0.5 * (d1[1] + d2[1])  # sine_mid: (F1 + F2)/2 z + (F2 - F1)/2 sin z
    s0, s1 = 0.5 * (d2[0] - d1[0]), 0.5 * (d2[1] - d1[1])
    for r in range(R):
        x0_, x1_ = x0[r, 0], x0[r, 1]
        f0_, f1_ = xf0[r, 0], xf0[r, 1]
        errs[r, 0, 0] = x0_ - f0_
        errs[r, 0, 1] = x1_ - f1_
        for k in range(K):
            p = p_seq[k]
            xi = 1.0 if u[k, r] < p else 0.0
            w = sd * g[k, r]
            y = xi * fma(x0_, c0, x1_ * c1)  # xi (x @ C.T), gemv order
            if has_gains:  # x_f @ G.T + y @ H.T with G = G0 + p Gf, H = H0 + p Hf
                n0 = fma(f1_, G0[0, 1] + p * Gf[0, 1], f0_ * (G0[0, 0] + p * Gf[0, 0])) + y * (H0[0, 0] + p * Hf[0, 0])
                n1 = fma(f1_, G0[1, 1] + p * Gf[1, 1], f0_ * (G0[1, 0] + p * Gf[1, 0])) + y * (H0[1, 0] + p * Hf[1, 0])
                f0_, f1_ = n0, n1
            zz0 = fma(x1_, z01, x0_ * z00)  # x @ Z.T
            zz1 = fma(x1_, z11, x0_ * z10)
            if kind == 0:
                q0 = m0 * zz0 + s0 * np.sin(zz0)
                q1 = m1 * zz1 + s1 * np.sin(zz1)
            elif kind == 1:
                q0, q1 = d1[0] * zz0, d1[1] * zz1
            else:
                q0, q1 = d2[0] * zz0, d2[1] * zz1
            # x @ A.T + f @ B.T + w (x @ D.T)
            n0 = (fma(x1_, a01, x0_ * a00) + fma(q1, b01, q0 * b00)) + w * fma(x1_, e01, x0_ * e00)
            n1 = (fma(x1_, a11, x0_ * a10) + fma(q1, b11, q0 * b10)) + w * fma(x1_, e11, x0_ * e10)
            x0_, x1_ = n0, n1
            errs[r, k + 1, 0] = x0_ - f0_
            errs[r, k + 1, 1] = x1_ - f1_
    return errs
