"""Compiled (numba) kernels of the `onebit` paper: the banded point-mass filter and smoother.

Imported lazily by :func:`netrepro.papers.onebit.estimators.grid_smoother_at` (numba costs import time).
The kernels perform the same floating-point operations in the same order as the numpy/scipy reference
(CSR sparse-times-dense products accumulated row by row from 0, likelihood product, column sums in grid
order, division), so they are bit-identical to it (checked in tests/papers/onebit/test_kernels.py).
Plain loops only: array slice assignment and inlined helpers cost seconds of compile time in every cold
job, and the compile time counts as much as the run time.
"""

from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["band_forward_backward", "smoothing_gain_iterations"]


@njit(cache=True, boundscheck=False, error_model="numpy")
def _csr_row_product(ptr, idx, val, i, src, drow):
    """``drow = (M @ src)[i]`` for CSR ``M``, accumulated from 0 in the order of the stored entries (as scipy).

    Four stored entries per pass over ``drow`` (the sum keeps its order: ``(((d + a0 s0) + a1 s1) + ...)``),
    so ``drow`` is loaded and stored once per four products instead of once per product.
    """
    n = drow.shape[0]
    jj = ptr[i]
    end = ptr[i + 1]
    for c in range(n):
        drow[c] = 0.0
    while jj + 4 <= end:
        a0, a1, a2, a3 = val[jj], val[jj + 1], val[jj + 2], val[jj + 3]
        s0, s1, s2, s3 = src[idx[jj]], src[idx[jj + 1]], src[idx[jj + 2]], src[idx[jj + 3]]
        for c in range(n):
            drow[c] = (((drow[c] + a0 * s0[c]) + a1 * s1[c]) + a2 * s2[c]) + a3 * s3[c]
        jj += 4
    while jj < end:
        a = val[jj]
        srow = src[idx[jj]]
        for c in range(n):
            drow[c] += a * srow[c]
        jj += 1


@njit(cache=True, boundscheck=False, error_model="numpy")
def _divide_columns(M, colsum):
    """``M /= colsum`` column by column (normalisation per run)."""
    for i in range(M.shape[0]):
        for c in range(M.shape[1]):
            M[i, c] = M[i, c] / colsum[c]


@njit(cache=True, boundscheck=False, error_model="numpy")
def _store(out, s, M):
    """``out[s] = M`` (a loop: compiles much faster than the slice assignment)."""
    for i in range(M.shape[0]):
        for c in range(M.shape[1]):
            out[s, i, c] = M[i, c]


@njit(cache=True, boundscheck=False, error_model="numpy")
def band_forward_backward(f_ptr, f_idx, f_val, b_ptr, b_idx, b_val, lik_pos, lik_neg, positive, prior, slot,
                          stop, stored_post, stored_beta):
    r"""Forward point-mass filter and backward messages of the 1-bit model (21)/(28) on a banded grid.

    Forward (Chapman-Kolmogorov + Bayes): :math:`p_{k+1} \propto (T^\top p_k)\,\Phi(r_{k+1}x/\sigma_\eta)`;
    backward: :math:`\beta_{k-1} \propto T(\Phi(r_k x/\sigma_\eta)\beta_k)`, each normalised per run.
    Arrays are grid-major ``(n_grid, n_runs)``; the transition is given as two CSR matrices.

    Parameters
    ----------
    f_ptr, f_idx, f_val : ndarray
        CSR (indptr, indices, data, int64/float64) of :math:`T^\top` (forward product).
    b_ptr, b_idx, b_val : ndarray
        CSR of :math:`T` (backward product).
    lik_pos, lik_neg : ndarray (n_grid,)
        :math:`\Phi(x/\sigma_\eta)` and ``1 - lik_pos``: likelihood of r = +1 and r = -1.
    positive : ndarray of bool (K, n_runs)
        ``r_{k+1} > 0`` for k = 0..K-1.
    prior : ndarray (n_grid,)
        Normalised prior masses at k = 0.
    slot : ndarray of int64 (K+1,)
        Output slot of step k (-1: not stored). The forward recursion stops at the last stored step.
    stop : int
        The backward recursion runs k = K..stop+1 (produces beta at steps K-1..stop).
    stored_post, stored_beta : ndarray (n_slots, n_grid, n_runs)
        Receive the filtered masses and the normalised backward messages at the stored steps (output).
    """
    G = prior.shape[0]
    K, n = positive.shape
    cur = np.empty((G, n))
    nxt = np.empty((G, n))
    colsum = np.empty(n)
    for i in range(G):
        for c in range(n):
            cur[i, c] = prior[i]
    if slot[0] >= 0:
        _store(stored_post, slot[0], cur)
    last = K  # the filter is needed up to the last stored step only (the backward pass starts from beta = 1)
    while last > 0 and slot[last] < 0:
        last -= 1
    for k in range(last):
        pos = positive[k]
        for c in range(n):
            colsum[c] = 0.0
        for i in range(G):
            drow = nxt[i]
            _csr_row_product(f_ptr, f_idx, f_val, i, cur, drow)
            lp = lik_pos[i]
            ln = lik_neg[i]
            for c in range(n):
                v = drow[c] * (lp if pos[c] else ln)
                drow[c] = v
                colsum[c] += v
        _divide_columns(nxt, colsum)
        cur, nxt = nxt, cur
        if slot[k + 1] >= 0:
            _store(stored_post, slot[k + 1], cur)
    beta = cur
    tmp = nxt
    for i in range(G):
        for c in range(n):
            beta[i, c] = 1.0
    for k in range(K, stop, -1):
        pos = positive[k - 1]
        for i in range(G):
            lp = lik_pos[i]
            ln = lik_neg[i]
            brow = beta[i]
            trow = tmp[i]
            for c in range(n):
                trow[c] = brow[c] * (lp if pos[c] else ln)
        for c in range(n):
            colsum[c] = 0.0
        for i in range(G):
            drow = beta[i]
            _csr_row_product(b_ptr, b_idx, b_val, i, tmp, drow)
            for c in range(n):
                colsum[c] += drow[c]
        _divide_columns(beta, colsum)
        if slot[k - 1] >= 0:
            _store(stored_beta, slot[k - 1], beta)


@njit(cache=True, error_model="numpy")
def smoothing_gain_iterations(F, s, a2, kappa_star, rtol, n_steps, kappa, last):
    r"""``n_steps`` steps of the smoothing gain (27)/(37)-(38), :math:`\kappa \leftarrow a^2 I/(1 + \sigma_z^2 I)`, :math:`I = F + \kappa`.

    In place on ``kappa`` (one lane per element); ``last[lane]`` receives the last step ``d`` (1-based)
    with ``|kappa / kappa_star - 1| > rtol``. Same operations in the same order as
    :func:`netrepro.papers.onebit.randomwalk.rw_smoothing_gain_step` in a numpy loop.

    Parameters
    ----------
    F : ndarray, shape (lanes,)
        Filter Fisher information of each lane.
    s : ndarray, shape (lanes,)
        :math:`\sigma_z^2` of each lane.
    a2 : float
        :math:`a^2`.
    kappa_star : ndarray, shape (lanes,)
        Fixed point of each lane (the convergence reference).
    rtol : float
        Relative distance from ``kappa_star`` counted as not yet converged.
    n_steps : int
        Number of steps.
    kappa : ndarray, shape (lanes,)
        Start values; overwritten by the values after ``n_steps`` steps.
    last : ndarray of int, shape (lanes,)
        Receives the last step still farther than ``rtol`` from ``kappa_star`` (unchanged if none).

    Returns
    -------
    None
        The results are written into ``kappa`` and ``last``.
    """
    for d in range(1, n_steps + 1):
        for lane in range(kappa.shape[0]):
            info = F[lane] + kappa[lane]
            k = a2 * info / (1.0 + s[lane] * info)
            kappa[lane] = k
            if abs(k / kappa_star[lane] - 1) > rtol:
                last[lane] = d
