"""Compiled (numba) kernels of the `onebit` paper: the banded point-mass filter and smoother.

Imported lazily by :func:`netrepro.papers.onebit.estimators.grid_smoother_at` (numba costs import time).
The kernels perform the same floating-point operations in the same order as the numpy/scipy reference
(CSR sparse-times-dense products accumulated row by row from 0, likelihood product, column sums in grid
order, division), so they are bit-identical to it (checked in tests/test_onebit_speed.py).
"""

from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["band_forward_backward"]


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
        Output slot of step k (-1: not stored).
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
        stored_post[slot[0]] = cur
    for k in range(K):
        pos = positive[k]
        for c in range(n):
            colsum[c] = 0.0
        for i in range(G):
            drow = nxt[i]
            for c in range(n):
                drow[c] = 0.0
            for jj in range(f_ptr[i], f_ptr[i + 1]):
                a = f_val[jj]
                srow = cur[f_idx[jj]]
                for c in range(n):
                    drow[c] += a * srow[c]
            lp = lik_pos[i]
            ln = lik_neg[i]
            for c in range(n):
                v = drow[c] * (lp if pos[c] else ln)
                drow[c] = v
                colsum[c] += v
        for i in range(G):
            drow = nxt[i]
            for c in range(n):
                drow[c] = drow[c] / colsum[c]
        cur, nxt = nxt, cur
        if slot[k + 1] >= 0:
            stored_post[slot[k + 1]] = cur
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
            for c in range(n):
                drow[c] = 0.0
            for jj in range(b_ptr[i], b_ptr[i + 1]):
                a = b_val[jj]
                srow = tmp[b_idx[jj]]
                for c in range(n):
                    drow[c] += a * srow[c]
            for c in range(n):
                colsum[c] += drow[c]
        for i in range(G):
            drow = beta[i]
            for c in range(n):
                drow[c] = drow[c] / colsum[c]
        if slot[k - 1] >= 0:
            stored_beta[slot[k - 1]] = beta
