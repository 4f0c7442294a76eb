"""Compiled (numba) kernels of the `onebit` paper: the banded point-mass filter and smoother, the
Kalman filter / RTS smoother means and the smoothing gain iteration.

Imported lazily by :func:`netrepro.papers.onebit.estimators.grid_smoother_at`,
:func:`~netrepro.papers.onebit.estimators.kalman_rts` and
:func:`netrepro.papers.onebit.randomwalk.rw_smoothing_gain_iterated` (numba costs import time).
The kernels perform the same floating-point operations in the same order as the numpy/scipy reference
(CSR sparse-times-dense products accumulated row by row from 0, likelihood product, column sums in grid
order, division), so they are bit-identical to it (checked in tests/papers/onebit/test_kernels.py).

The banded smoother works on blocks of ``_BLOCK`` runs (columns): for one block, each grid row's
CSR product is summed in registers (``_VEC`` vectors of 8 doubles) over all its stored entries, in
stored order, ``((0 + a0 s0) + a1 s1) + ...`` per column as scipy; the likelihood product, the column
sums (in grid order) and the division follow on the same block while it is in the cache. This
halves the kernel's time against a row-by-row product that reloads and stores the output row every
few entries. Loops cannot express it: LLVM keeps no accumulator array in registers across the
entry loop (the array may alias the source rows), and numba runs LLVM without SLP vectorisation,
so scalar accumulators stay scalar; hence the block step is written out in LLVM IR
(:func:`_block_step`; on a machine without AVX-512 LLVM splits the 8-double vectors, same
results). No fastmath and no FMA: plain ``fmul``/``fadd``/``fdiv`` in IR are not contracted.
The run dimension is padded to whole blocks (the padding columns repeat run 0 and are never
returned) and each grid row to ``n_pad + 8`` doubles, so that the rows of a block do not share
cache sets (with 2^k-double rows the kernel ran up to 25 % slower). The arguments are checked and
the buffers allocated in Python: ``np.empty`` in compiled code costs compile time in every cold
job, which counts as much as the run time (for the same reason: plain loops, no slice assignment,
no compiled helpers).
"""

from __future__ import annotations

import numpy as np
from llvmlite import ir as llvm_ir
from numba import njit, types
from numba.core import cgutils
from numba.extending import intrinsic

from ...errors import InputError

__all__ = ["band_forward_backward", "kalman_rts_recursions", "smoothing_gain_iterations"]

_VEC = 8              # vectors of 8 doubles (one AVX-512 register each) per block
_BLOCK = 8 * _VEC     # runs (columns) per block
_F64 = llvm_ir.DoubleType()
_I64 = llvm_ir.IntType(64)
_I32 = llvm_ir.IntType(32)
_V8D = llvm_ir.VectorType(_F64, 8)
_V8B = llvm_ir.VectorType(llvm_ir.IntType(8), 8)


@intrinsic
def _block_step(typingctx, ptr, idx, val, src, dst, lik_pos, lik_neg, pos, c0, backward):
    r"""One recursion step on the columns ``c0 .. c0 + _BLOCK - 1`` (compiled code only).

    Forward (``backward=False``): ``dst = (M @ src) * lik``, then ``dst /= dst.sum(axis=0)``.
    Backward (``backward=True``): ``src = dst * lik``, then ``dst = M @ src``, ``dst /= dst.sum(axis=0)``.
    ``M`` is the CSR matrix ``(ptr, idx, val)``; ``lik[i, c]`` is ``lik_pos[i]`` if ``pos[c]`` else
    ``lik_neg[i]``. ``src`` and ``dst`` are C-contiguous ``(n_grid, ld)`` with ``c0 + _BLOCK <= ld``;
    no bounds checks.

    Parameters
    ----------
    typingctx : numba typing context
        Supplied by numba.
    ptr, idx, val, src, dst, lik_pos, lik_neg, pos, c0 : numba types
        Types of the operands (see above); ``pos`` is a bool array, ``c0`` an integer.
    backward : BooleanLiteral
        Which of the two steps (a compile-time constant).

    Returns
    -------
    tuple
        The signature and the code generator numba's ``@intrinsic`` expects.
    """
    arrays = (ptr, idx, val, src, dst, lik_pos, lik_neg, pos)
    kinds = ((types.int64, 1), (types.int64, 1), (types.float64, 1), (types.float64, 2), (types.float64, 2),
             (types.float64, 1), (types.float64, 1), (types.boolean, 1))
    if not isinstance(backward, types.BooleanLiteral) or not isinstance(c0, types.Integer) or not all(
            isinstance(a, types.Array) and a.layout == "C" and (a.dtype, a.ndim) == kind
            for a, kind in zip(arrays, kinds)):
        return None  # raw pointer arithmetic below: only the exact types it was written for
    bw = backward.literal_value
    sig = types.void(ptr, idx, val, src, dst, lik_pos, lik_neg, pos, c0, backward)

    def codegen(context, builder, signature, args):
        ptr_d, idx_d, val_d, src_d, dst_d, lp_d, ln_d, pos_d = [
            context.make_array(t)(context, builder, v).data for t, v in zip(signature.args[:8], args[:8])]
        n_grid, ld = cgutils.unpack_tuple(builder, context.make_array(signature.args[3])(
            context, builder, args[3]).shape, 2)
        c0v = builder.sext(args[8], _I64) if args[8].type != _I64 else args[8]
        undef = llvm_ir.Constant(_V8D, llvm_ir.Undefined)
        zero = llvm_ir.Constant(_V8D, [0.0] * 8)

        def splat(x):
            return builder.shuffle_vector(builder.insert_element(undef, x, _I32(0)), undef,
                                          llvm_ir.Constant(llvm_ir.VectorType(_I32, 8), [0] * 8))

        def vec(base, row, v):  # address of the 8 doubles at base[row, c0 + 8 v]
            off = builder.add(builder.add(builder.mul(row, ld), c0v), _I64(8 * v))
            return builder.bitcast(builder.gep(base, [off]), _V8D.as_pointer())

        def item(base, i):
            return builder.load(builder.gep(base, [i]))

        masks = []
        for v in range(_VEC):
            p = builder.bitcast(builder.gep(pos_d, [builder.add(c0v, _I64(8 * v))]), _V8B.as_pointer())
            masks.append(builder.icmp_unsigned("!=", builder.load(p, align=1), llvm_ir.Constant(_V8B, [0] * 8)))

        def likelihood(i):
            lp, ln = splat(item(lp_d, i)), splat(item(ln_d, i))
            return [builder.select(m, lp, ln) for m in masks]

        colsum = [cgutils.alloca_once_value(builder, zero) for _ in range(_VEC)]
        acc = [cgutils.alloca_once(builder, _V8D) for _ in range(_VEC)]
        if bw:
            with cgutils.for_range(builder, n_grid) as loop:
                lik = likelihood(loop.index)
                for v in range(_VEC):
                    x = builder.load(vec(dst_d, loop.index, v), align=8)
                    builder.store(builder.fmul(x, lik[v]), vec(src_d, loop.index, v), align=8)
        with cgutils.for_range(builder, n_grid) as loop:
            i = loop.index
            for v in range(_VEC):
                builder.store(zero, acc[v])
            with cgutils.for_range(builder, item(ptr_d, builder.add(i, _I64(1))), start=item(ptr_d, i)) as entry:
                a = splat(item(val_d, entry.index))
                row = item(idx_d, entry.index)
                for v in range(_VEC):
                    x = builder.load(vec(src_d, row, v), align=8)
                    builder.store(builder.fadd(builder.load(acc[v]), builder.fmul(a, x)), acc[v])
            lik = None if bw else likelihood(i)
            for v in range(_VEC):
                y = builder.load(acc[v])
                if not bw:
                    y = builder.fmul(y, lik[v])
                builder.store(y, vec(dst_d, i, v), align=8)
                builder.store(builder.fadd(builder.load(colsum[v]), y), colsum[v])
        with cgutils.for_range(builder, n_grid) as loop:
            for v in range(_VEC):
                p = vec(dst_d, loop.index, v)
                builder.store(builder.fdiv(builder.load(p, align=8), builder.load(colsum[v])), p, align=8)
        return context.get_dummy_value()

    return sig, codegen


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

    Returns
    -------
    None
        The results are written into ``stored_post`` and ``stored_beta``.

    Raises
    ------
    InputError
        If the CSR arrays, the likelihoods, ``slot`` or the output arrays do not fit the grid of ``prior``
        and the shape of ``positive``.
    """
    G = len(prior)
    for name, ptr, idx, val in (("forward", f_ptr, f_idx, f_val), ("backward", b_ptr, b_idx, b_val)):
        # the compiled block step reads the grid rows named by the CSR arrays without bounds checks
        if (len(ptr) != G + 1 or ptr[0] != 0 or ptr[-1] != len(idx) or len(val) != len(idx)
                or np.any(np.diff(ptr) < 0) or (len(idx) and (idx.min() < 0 or idx.max() >= G))):
            raise InputError(f"band_forward_backward: the {name} CSR matrix does not fit a grid of {G} points")
    if len(lik_pos) != G or len(lik_neg) != G:
        raise InputError(f"band_forward_backward: the likelihoods need {G} grid points")
    K, n = positive.shape
    if (len(slot) != K + 1 or stored_post.ndim != 3 or stored_post.shape[1:] != (G, n)
            or stored_beta.shape != stored_post.shape or np.max(slot) >= len(stored_post) or not 0 <= stop <= K):
        raise InputError("band_forward_backward: slot, stop or the output arrays do not fit the problem")
    n_pad = -(-n // _BLOCK) * _BLOCK
    pos = np.empty((K, n_pad), dtype=np.bool_)
    pos[:, :n] = positive
    pos[:, n:] = positive[:, :1]  # padding columns repeat run 0 (computed, never returned)
    i64 = lambda a: np.ascontiguousarray(a, dtype=np.int64)  # noqa: E731
    f64 = lambda a: np.ascontiguousarray(a, dtype=np.float64)  # noqa: E731
    _band_forward_backward(i64(f_ptr), i64(f_idx), f64(f_val), i64(b_ptr), i64(b_idx), f64(b_val), f64(lik_pos),
                           f64(lik_neg), pos, f64(prior), i64(slot), int(stop), stored_post, stored_beta,
                           np.empty((2, G, n_pad + 8)))  # + 8: see the module docstring


@njit(cache=True, boundscheck=False, error_model="numpy")
def _band_forward_backward(f_ptr, f_idx, f_val, b_ptr, b_idx, b_val, lik_pos, lik_neg, pos, prior, slot, stop,
                           stored_post, stored_beta, work):
    """:func:`band_forward_backward` on checked arguments: ``pos`` padded to whole blocks, ``work`` two grids."""
    K, n_pad = pos.shape
    G = prior.shape[0]
    n = stored_post.shape[2]
    cur = work[0]
    nxt = work[1]
    for i in range(G):
        for c in range(n_pad):
            cur[i, c] = prior[i]
    last = K  # the filter is needed up to the last stored step only (the backward pass starts from beta = 1)
    while last > 0 and slot[last] < 0:
        last -= 1
    for k in range(last + 1):
        if k > 0:
            for c0 in range(0, n_pad, _BLOCK):
                _block_step(f_ptr, f_idx, f_val, cur, nxt, lik_pos, lik_neg, pos[k - 1], c0, False)
            cur, nxt = nxt, cur
        if slot[k] >= 0:
            for i in range(G):
                for c in range(n):
                    stored_post[slot[k], i, c] = cur[i, c]
    beta = cur
    tmp = nxt
    for i in range(G):
        for c in range(n_pad):
            beta[i, c] = 1.0
    for k in range(K, stop, -1):
        for c0 in range(0, n_pad, _BLOCK):
            _block_step(b_ptr, b_idx, b_val, tmp, beta, lik_pos, lik_neg, pos[k - 1], c0, True)
        if slot[k - 1] >= 0:
            for i in range(G):
                for c in range(n):
                    stored_beta[slot[k - 1], i, c] = beta[i, c]


@njit(cache=True, boundscheck=False, error_model="numpy")
def kalman_rts_recursions(y, alpha, alpha2, P0, sigma_z2, sigma_eta2, mf, ms, work):
    r"""Means of the scalar Kalman filter and RTS smoother of (21) observed through (20), one run per row.

    Variances: :math:`P_{k|k-1} = \alpha^2 P_{k-1} + \sigma_z^2`, :math:`G_k = P_{k|k-1} / (P_{k|k-1} +
    \sigma_\eta^2)`, :math:`P_k = (1 - G_k) P_{k|k-1}` from :math:`P_0`; :math:`C_k = P_k \alpha / P_{k+1|k}`.
    Means: :math:`m_{k|k-1} = \alpha m_{k-1}`, :math:`m_k = m_{k|k-1} + G_k (y_k - m_{k|k-1})` from
    :math:`m_0 = 0`; :math:`m^s_k = m_k + C_k (m^s_{k+1} - m_{k+1|k})` from :math:`m^s_K = m_K`.
    Same operations in the same order as the numpy loop
    :func:`netrepro.papers.onebit.estimators._kalman_rts_numpy`.

    Parameters
    ----------
    y : ndarray (n_runs, K)
        Unquantized measurements (20), k = 1..K.
    alpha, alpha2 : float
        Transition coefficient of (21) and its square (``alpha**2``, computed by the caller as the reference does).
    P0 : float
        Prior variance (the stationary variance).
    sigma_z2, sigma_eta2 : float
        Transition and measurement noise variances.
    mf, ms : ndarray (n_runs, K+1)
        Receive the filtered and smoothed means, k = 0..K (output).
    work : ndarray (5, K+1)
        Work buffer.

    Returns
    -------
    None
        The results are written into ``mf`` and ``ms``.
    """
    n, K = y.shape
    gain, Pf, Pp, C, mp = work[0], work[1], work[2], work[3], work[4]
    P = P0
    Pf[0] = P
    for k in range(1, K + 1):
        Ppk = alpha2 * P + sigma_z2
        G = Ppk / (Ppk + sigma_eta2)
        P = (1.0 - G) * Ppk
        Pp[k] = Ppk
        Pf[k] = P
        gain[k] = G
    for k in range(K):
        C[k] = Pf[k] * alpha / Pp[k + 1]
    for c in range(n):
        m = 0.0
        mf[c, 0] = 0.0
        for k in range(1, K + 1):
            mpk = alpha * m
            mp[k] = mpk
            m = mpk + gain[k] * (y[c, k - 1] - mpk)
            mf[c, k] = m
        ms[c, K] = m
        for k in range(K - 1, -1, -1):
            ms[c, k] = mf[c, k] + C[k] * (ms[c, k + 1] - mp[k + 1])


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
