"""Compiled (numba) kernels: the batched covariance recursion for state dimension 1 to 3, and the
scalar information recursion of the `onebit` paper.

The numpy kernels of :mod:`netrepro.engines.riccati` make a fixed handful of array calls per
time step, so each step streams the whole batch through memory several times and reaches a
few percent of the machine's floating-point peak. These kernels fuse a whole step into one
loop over a cache-resident block of paths; the loop body is straight-line code (the state
dimension is a compile-time constant, so every small loop unrolls) that the compiler
vectorises across paths. Results agree with the numpy kernels to rounding; tests check both
against the textbook recursion and each other.

State layout: the distinct entries of each symmetric ``P`` (upper triangle, row by row,
``n (n + 1) / 2`` of them; see :func:`packed_index`) for a block of paths, entry-major, so
that each entry is a contiguous row over paths. Rows are padded by a few doubles so that the
rows of one block do not map to the same cache sets (with 2^k-double rows the kernel ran up to
4 times slower).

Compiled code is cached on disk by numba (next to this file), so only the first process
that needs a given state dimension pays the compile time (about 1-2 s).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from numba import njit

__all__ = ["packed_index", "packed_prediction", "arrival_words", "small_state_kernel", "scalar_kernel",
           "scalar_information_steps", "BLOCK_PATHS"]

BLOCK_PATHS = 256  # paths per block: state, gains and arrivals of a block stay in the L1/L2 cache
_ROW_PAD = 8  # doubles added to each row of a block buffer (see module docstring)


def packed_index(n: int) -> np.ndarray:
    """``(n, n)`` table of the packed position of entry ``(a, b)`` (upper triangle, row by row).

    Parameters
    ----------
    n : int
        State dimension.

    Returns
    -------
    ndarray of int64, shape ``(n, n)``
        Symmetric: ``idx[a, b] = idx[b, a]`` is the position of ``P_ab`` among the
        ``n (n + 1) / 2`` packed entries.
    """
    idx = np.empty((n, n), dtype=np.int64)
    a_idx, b_idx = np.triu_indices(n)
    idx[a_idx, b_idx] = np.arange(len(a_idx))
    idx[b_idx, a_idx] = np.arange(len(a_idx))
    return idx


def packed_prediction(A: np.ndarray, Q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The prediction ``P -> A P A^T + Q`` as ``(M, q)`` on packed entries: ``p' = M p + q``.

    Entry ``(a, b)`` of ``A P A^T`` is ``sum_{k,l} A_ak A_bl P_kl``; grouping ``P_kl`` and
    ``P_lk`` (one packed entry) with the symmetrised coefficient ``(A_ak A_bl + A_al A_bk) / 2``
    makes the map exact on symmetric matrices, whatever rounding does.

    Parameters
    ----------
    A : array_like, shape ``(n, n)``
        State matrix.
    Q : array_like, shape ``(n, n)`` or scalar
        Process noise covariance (symmetrised).

    Returns
    -------
    M : ndarray, shape ``(c, c)``
        The linear part on packed entries, ``c = n (n + 1) / 2``.
    q : ndarray, shape ``(c,)``
        The packed ``Q``.
    """
    A = np.atleast_2d(np.asarray(A, dtype=float))
    n = A.shape[0]
    Qf = np.broadcast_to(np.atleast_2d(np.asarray(Q, dtype=float)), (n, n))
    idx = packed_index(n)
    a_idx, b_idx = np.triu_indices(n)
    M = np.zeros((len(a_idx), len(a_idx)))
    for e, (a, b) in enumerate(zip(a_idx, b_idx)):
        coef = 0.5 * (np.outer(A[a], A[b]) + np.outer(A[b], A[a]))
        np.add.at(M[e], idx.ravel(), coef.ravel())
    q = 0.5 * (Qf[a_idx, b_idx] + Qf[b_idx, a_idx])
    return M, q


def arrival_words(arrivals: np.ndarray) -> np.ndarray:
    """Arrival flags ``(N, T, channels)`` as ``(N, ceil(T * channels / 8))`` uint64 words, 8 flags each.

    Flag ``(k, j)`` of a path is byte ``b = k * channels + j`` of its row: word ``b >> 3``, byte
    ``b & 7`` (little-endian). Without a copy when ``T * channels`` is a multiple of 8 (the row
    is padded with zeros otherwise). :func:`_transpose_block` turns each word into one byte of
    8 flag bits.

    Parameters
    ----------
    arrivals : ndarray of bool, shape ``(N, T, channels)``
        Arrival flags per path, step and channel.

    Returns
    -------
    ndarray of uint64, shape ``(N, ceil(T * channels / 8))``
        The flags, eight per word (a view when no padding is needed).
    """
    N, T, m = arrivals.shape
    flat = np.ascontiguousarray(arrivals, dtype=bool).reshape(N, T * m).view(np.uint8)
    if (T * m) % 8:
        padded = np.zeros((N, -(-(T * m) // 8) * 8), dtype=np.uint8)
        padded[:, : T * m] = flat
        flat = padded
    return flat.view(np.uint64)


# Multiplying a word of eight 0/1 bytes by this constant moves byte t to bit 63 - t and nothing
# else into the top byte (the partial products land on distinct bits, so there are no carries).
_GATHER_BITS = np.uint64(0x8040201008040201)
_TOP_BYTE = np.uint64(56)


@njit(cache=True, boundscheck=False)
def _transpose_block(words, lo, B, out):
    """``out[w, i]``: the 8 flags of word ``w`` of path ``lo + i`` as the bits of one byte.

    Flag ``b`` (byte ``b & 7`` of word ``b >> 3``) is bit ``7 - (b & 7)``: the kernels read it as
    ``(out[b >> 3, i] >> (7 - (b & 7))) & 1``, which is the same bit for every path of the block.
    """
    for i in range(B):
        for w in range(words.shape[1]):
            out[w, i] = np.uint8((words[lo + i, w] * _GATHER_BITS) >> _TOP_BYTE)


@lru_cache(maxsize=None)
def small_state_kernel(n: int):
    """Compiled recursion for state dimension ``n`` (eq. (4) / (14) of the `intermittent` report).

    ``kernel(p0, M, q, rows_c, rows_r, rows_channel, words, n_channels, T, lost_tolerance, hist, last)``
    runs, for every
    path and step ``k``: for each scalar measurement row ``c`` (noise variance ``r``, gated by
    the arrival of its channel) ``P <- P - gamma (P c^T)(c P) / (c P c^T + r)``, then
    ``P <- M P + q`` (:func:`packed_prediction`); a path with a non-finite entry becomes
    ``inf`` in every entry and stays so, and so does a path whose posterior variance along a row
    misses its exact value by more than ``lost_tolerance * r`` (the update lost the measured
    direction to rounding: :func:`netrepro.engines.riccati.covariance_paths`, "Numerical range"). ``words`` are the arrivals from
    :func:`arrival_words`; ``hist`` is ``(N, T + 1, c)`` (the packed ``P_0 .. P_T``; ``T`` is
    taken from it) and ``last`` (``(N, c)``) receives ``P_T``.

    Parameters
    ----------
    n : int
        State dimension (1 to 3; a compile-time constant of the kernel).

    Returns
    -------
    callable
        The compiled ``kernel`` above (cached per ``n``; it writes into ``hist`` and ``last``).
    """
    c = n * (n + 1) // 2
    idx = tuple(tuple(int(v) for v in row) for row in packed_index(n))
    block = BLOCK_PATHS
    width = block + _ROW_PAD

    # contract: multiply-adds become FMAs (one rounding instead of two; not reassociation)
    @njit(cache=True, boundscheck=False, error_model="numpy", fastmath={"contract"})
    def kernel(p0, M, q, rows_c, rows_r, rows_channel, words, n_channels, T, lost_tolerance, hist, last):
        N = words.shape[0]
        n_rows = rows_c.shape[0]
        keep_all = hist.shape[1] > 0
        p = np.empty((c, width))
        u = np.empty((n, width))
        new = np.empty((c, width))
        flags = np.empty((words.shape[1], width), dtype=np.uint8)
        for lo in range(0, N, block):
            B = min(block, N - lo)
            _transpose_block(words, lo, B, flags)
            for e in range(c):
                for i in range(B):
                    p[e, i] = p0[e]
            if keep_all:
                for i in range(B):
                    for e in range(c):
                        hist[lo + i, 0, e] = p0[e]
            for k in range(T):
                for row in range(n_rows):
                    pos = k * n_channels + rows_channel[row]
                    byte, shift = pos >> 3, 7 - (pos & 7)
                    for i in range(B):
                        s = rows_r[row]
                        for a in range(n):
                            acc = 0.0
                            for b in range(n):
                                acc += rows_c[row, b] * p[idx[a][b], i]
                            u[a, i] = acc
                            s += rows_c[row, a] * acc
                        g = (flags[byte, i] >> shift) & 1
                        w = g / s
                        for a in range(n):
                            t = w * u[a, i]
                            for b in range(a, n):
                                p[idx[a][b], i] -= t * u[b, i]
                        # accuracy check (see riccati.covariance_paths): c P c^T of the stored
                        # posterior against its exact value, r - r^2 / s if updated (a form without
                        # cancellation) and s0 if not; NaN marks the path
                        v = 0.0
                        for a in range(n):
                            acc = 0.0
                            for b in range(n):
                                acc += rows_c[row, b] * p[idx[a][b], i]
                            v += rows_c[row, a] * acc
                        r = rows_r[row]
                        s0 = s - r
                        exact = (r - r * (r / s)) if g else s0
                        lost = (s0 < 0.0) | (abs(v - exact) > lost_tolerance * r)
                        p[0, i] = np.nan if lost else p[0, i]
                for i in range(B):
                    total = 0.0
                    for e in range(c):
                        acc = q[e]
                        for f in range(c):
                            acc += M[e, f] * p[f, i]
                        new[e, i] = acc
                        total += acc
                    finite = np.isfinite(total)
                    for e in range(c):
                        p[e, i] = new[e, i] if finite else np.inf
                if keep_all:
                    for i in range(B):
                        for e in range(c):
                            hist[lo + i, k + 1, e] = p[e, i]
            for i in range(B):
                for e in range(c):
                    last[lo + i, e] = p[e, i]

    return kernel


@lru_cache(maxsize=None)
def scalar_kernel():
    """Compiled scalar recursion (eq. (4) of the `intermittent` report with n = 1), fused.

    ``kernel(p0, a2, q, r_eff, words, T, hist, last)``: per step, for each sensor ``j`` whose
    packet arrived ``p <- r_j p / (p + r_j)``, computed as ``r_j (p / (p + r_j))`` (no overflow
    for any finite ``p``) and ``r_j`` where ``p + r_j`` is ``inf`` (the limit), then
    ``p <- a2 p + q``. One division per update where the numpy kernel's
    ``r / (1 + r / p)`` needs two: the divider bounds this loop. ``words`` from
    :func:`arrival_words`; ``hist`` is ``(N, T + 1)`` or ``(N, 0)``; ``last`` is ``(N,)``.

    Returns
    -------
    callable
        The compiled ``kernel`` above (cached; it writes into ``hist`` and ``last``).
    """
    block = BLOCK_PATHS
    width = block + _ROW_PAD

    @njit(cache=True, boundscheck=False, error_model="numpy")
    def kernel(p0, a2, q, r_eff, words, T, hist, last):
        N = words.shape[0]
        m = r_eff.shape[0]
        keep_all = hist.shape[1] > 0
        p = np.empty(width)
        flags = np.empty((words.shape[1], width), dtype=np.uint8)
        for lo in range(0, N, block):
            B = min(block, N - lo)
            _transpose_block(words, lo, B, flags)
            for i in range(B):
                p[i] = p0
                if keep_all:
                    hist[lo + i, 0] = p0
            for k in range(T):
                for j in range(m):
                    r = r_eff[j]
                    pos = k * m + j
                    byte, shift = pos >> 3, 7 - (pos & 7)
                    for i in range(B):
                        x = p[i]
                        s = x + r
                        post = r * (x / s)
                        post = r if s == np.inf else post
                        p[i] = post if (flags[byte, i] >> shift) & 1 else x
                for i in range(B):
                    p[i] = a2 * p[i] + q
                if keep_all:
                    for i in range(B):
                        hist[lo + i, k + 1] = p[i]
            for i in range(B):
                last[lo + i] = p[i]

    return kernel


@njit(cache=True)
def scalar_information_steps(j, a2, s2, F, J):
    """Scalar information (Fisher/BIM) recursion, one step per row of ``F``: ``j <- 1 / (a2 / j + s2) + F[i]``.

    The filtering BIM of a scalar random walk ``theta_k = a theta_{k-1} + w_k`` (``Var w = s2``)
    observed with Fisher information ``F`` per step: eqs. (24) and (34) of the `onebit` paper,
    the special case of its general (7) with ``D11 = a^2 / s2``, ``D12 = -a / s2``,
    ``D22 = 1 / s2``. In place on ``j`` (one lane per independent recursion); ``J[i]`` receives
    ``j`` after step ``i``. Sequential in the step by nature; compiled because a numpy loop over
    ~1e6 steps of a few dozen lanes is all interpreter overhead. Same operations in the same
    order as that numpy loop, so bit-identical to it.

    Parameters
    ----------
    j : ndarray, shape ``(lanes,)``
        Initial information per lane; updated in place.
    a2 : float
        ``a^2``.
    s2 : ndarray, shape ``(lanes,)``
        Process noise variance per lane.
    F : ndarray, shape ``(steps, lanes)``
        Fisher information of the measurement at each step.
    J : ndarray, shape ``(steps, lanes)``
        Receives ``j`` after each step (output).
    """
    for i in range(F.shape[0]):
        for lane in range(j.shape[0]):
            j[lane] = 1.0 / (a2 / j[lane] + s2[lane]) + F[i, lane]
            J[i, lane] = j[lane]
