"""Compiled (numba) kernels of the H-infinity filter recursions of the `hinf` paper, eqs (6) and (9).

The numpy forms (:func:`.filters._hinf_update_numpy`, :func:`.filters._exists_numpy`) spend their time in
numpy's stacked 2x2 ``matmul``, one BLAS call per matrix. The kernels below run the same recursions matrix by
matrix in the same floating-point order, so that their results are bit-identical (checked by
tests/papers/hinf/test_filter_kernels.py against the numpy forms, tolerance 0):

- a 2x2 by 2x2 product (OpenBLAS ``dgemm``, also ``(n, 2) @ (2, 2)``) rounds ``fma(a_i1, b_1j, a_i0 b_0j)``;
- a 2x2 matrix by a vector (``dgemv``, also a single row times a 2x2 matrix) rounds ``fma(a_i0, v_0, a_i1 v_1)``;
- BLAS adds the product to a zeroed output (``beta = 0``), which turns ``-0.0`` into ``+0.0``: ``+ 0.0`` below;
- the element-wise parts (``inv2``, ``sym2``, ``min_eig2`` of :mod:`.algebra`) are replayed operation by
  operation. No fastmath.

Imported lazily by :mod:`.filters`, so that steps that run no filter do not import numba.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ...engines.intrinsics import fma

__all__ = ["hinf_update_kernel", "hinf_update_batch_kernel", "congruence_kernel", "exists_kernel", "sigma_gradient_kernel", "noise_information_kernel",
           "rotate_kernel"]


@njit(cache=True, error_model="numpy")
def _mm(a00, a01, a10, a11, b00, b01, b10, b11):
    """``a @ b`` of 2x2 matrices as numpy's ``matmul`` (``dgemm``) rounds it (``+ 0.0``: C = 0 + AB)."""
    return (fma(a01, b10, a00 * b00) + 0.0, fma(a01, b11, a00 * b01) + 0.0,
            fma(a11, b10, a10 * b00) + 0.0, fma(a11, b11, a10 * b01) + 0.0)


@njit(cache=True, error_model="numpy")
def _mv(a00, a01, a10, a11, v0, v1):
    """``a @ v`` of a 2x2 matrix and a vector as numpy's ``matmul`` (``dgemv``) rounds it."""
    return fma(a00, v0, a01 * v1) + 0.0, fma(a10, v0, a11 * v1) + 0.0


@njit(cache=True, error_model="numpy")
def _inv2(a00, a01, a10, a11):
    """:func:`.algebra.inv2`: ``adj(a) / det(a)``."""
    d = a00 * a11 - a01 * a10
    return a11 / d, -a01 / d, -a10 / d, a00 / d


@njit(cache=True, error_model="numpy")
def _min_eig2(a00, a01, a10, a11):
    """:func:`.algebra.min_eig2` (smallest eigenvalue of the symmetric part)."""
    s00 = 0.5 * (a00 + a00)
    s01 = 0.5 * (a01 + a10)
    s11 = 0.5 * (a11 + a11)
    tr = s00 + s11
    diff = s00 - s11
    return 0.5 * tr - np.sqrt(0.25 * diff * diff + s01 * s01)


@njit(cache=True, error_model="numpy")
def _prior(s00, s01, s10, s11, A, BWB):
    """``Delta = A Sigma A^T + B W B^T`` (eq (6)), products left to right."""
    t00, t01, t10, t11 = _mm(A[0, 0], A[0, 1], A[1, 0], A[1, 1], s00, s01, s10, s11)
    d00, d01, d10, d11 = _mm(t00, t01, t10, t11, A[0, 0], A[1, 0], A[0, 1], A[1, 1])
    return d00 + BWB[0, 0], d01 + BWB[0, 1], d10 + BWB[1, 0], d11 + BWB[1, 1]


@njit(cache=True, error_model="numpy")
def _information(d00, d01, d10, d11, S00, S01, S10, S11, g00, g01, g10, g11):
    """:func:`.filters.hinf_information`: ``sym2(inv2(Delta) + S - gamma^{-2} L^T Q L)``."""
    i00, i01, i10, i11 = _inv2(d00, d01, d10, d11)
    u00 = (i00 + S00) - g00
    u01 = (i01 + S01) - g01
    u10 = (i10 + S10) - g10
    u11 = (i11 + S11) - g11
    return 0.5 * (u00 + u00), 0.5 * (u01 + u10), 0.5 * (u10 + u01), 0.5 * (u11 + u11)


@njit(cache=True, error_model="numpy")
def hinf_update_kernel(xhat, Sigma, y_info, S, A, BWB, gamma_inv2, Lbar, xpred_gemv, xnew, Sig, Delta, info_eig):
    """:func:`.filters.hinf_update` (eq (6), information form) on ``B`` flattened filters, into the outputs.

    Parameters
    ----------
    xhat, y_info : ndarray ``(B, 2)``
        Previous estimates ``xhat_{k-1}`` and the informations ``C^T M^{-1} y`` of the ``B`` filters.
    Sigma, S : ndarray ``(B, 2, 2)``
        Previous ``Sigma_{k-1}`` and ``C^T M^{-1} C`` of the ``B`` filters.
    A, BWB, Lbar : ndarray ``(2, 2)``
        Target dynamics ``A``, ``B W B^T`` and ``Lbar = L^T Q L``.
    gamma_inv2 : float
        ``gamma^{-2}`` (0: the Kalman filter).
    xpred_gemv : bool
        ``xhat @ A.T`` is a ``dgemv`` in numpy (one row per stack), else a ``dgemm``.
    xnew : ndarray ``(B, 2)``
        Receives the new estimates.
    Sig, Delta : ndarray ``(B, 2, 2)``
        Receive ``Sigma_k`` and ``Delta_k``.
    info_eig : ndarray ``(B,)``
        Receives the smallest eigenvalue of ``Sigma_k^{-1}``.
    """
    gL00, gL01, gL10, gL11 = gamma_inv2 * Lbar[0, 0], gamma_inv2 * Lbar[0, 1], gamma_inv2 * Lbar[1, 0], gamma_inv2 * Lbar[1, 1]
    for b in range(xhat.shape[0]):
        (xnew[b, 0], xnew[b, 1], Sig[b, 0, 0], Sig[b, 0, 1], Sig[b, 1, 0], Sig[b, 1, 1], Delta[b, 0, 0], Delta[b, 0, 1],
         Delta[b, 1, 0], Delta[b, 1, 1], info_eig[b]) = _hinf_one(
            xhat[b, 0], xhat[b, 1], Sigma[b, 0, 0], Sigma[b, 0, 1], Sigma[b, 1, 0], Sigma[b, 1, 1], y_info[b, 0],
            y_info[b, 1], S[b, 0, 0], S[b, 0, 1], S[b, 1, 0], S[b, 1, 1], A, BWB, gL00, gL01, gL10, gL11, xpred_gemv)


@njit(cache=True, error_model="numpy")
def hinf_update_batch_kernel(xhat, Sigma, y_info, S, A, BWB, gamma_inv2, Lbar, xpred_gemv, xnew, Sig, Delta,
                             info_eig):
    """:func:`hinf_update_kernel` for ``F`` filters of their own ``B W B^T`` and gamma fed the same measurements.

    Parameters
    ----------
    xhat : ndarray ``(F, B, 2)``
        Previous estimates of the ``F`` filters (``B`` flattened runs and agents each).
    Sigma : ndarray ``(F, B, 2, 2)``
        Their previous ``Sigma_{k-1}``.
    y_info : ndarray ``(B, 2)``
        ``C^T M^{-1} y``, shared by the ``F`` filters.
    S : ndarray ``(B, 2, 2)``
        ``C^T M^{-1} C``, shared by the ``F`` filters.
    A : ndarray ``(2, 2)``
        Target dynamics.
    BWB : ndarray ``(F, 2, 2)``
        Each filter's design ``B W B^T``.
    gamma_inv2 : ndarray ``(F,)``
        Each filter's ``gamma^{-2}`` (0: Kalman filter).
    Lbar : ndarray ``(2, 2)``
        ``L^T Q L``.
    xpred_gemv : bool
        As in :func:`hinf_update_kernel` (one filter's ``xhat @ A.T``).
    xnew : ndarray ``(F, B, 2)``
        Receives the new estimates.
    Sig, Delta : ndarray ``(F, B, 2, 2)``
        Receive ``Sigma_k`` and ``Delta_k``.
    info_eig : ndarray ``(F, B)``
        Receives the smallest eigenvalue of ``Sigma_k^{-1}``.
    """
    for f in range(xhat.shape[0]):
        g, bwb = gamma_inv2[f], BWB[f]
        gL00, gL01, gL10, gL11 = g * Lbar[0, 0], g * Lbar[0, 1], g * Lbar[1, 0], g * Lbar[1, 1]
        for b in range(xhat.shape[1]):
            (xnew[f, b, 0], xnew[f, b, 1], Sig[f, b, 0, 0], Sig[f, b, 0, 1], Sig[f, b, 1, 0], Sig[f, b, 1, 1],
             Delta[f, b, 0, 0], Delta[f, b, 0, 1], Delta[f, b, 1, 0], Delta[f, b, 1, 1], info_eig[f, b]) = _hinf_one(
                xhat[f, b, 0], xhat[f, b, 1], Sigma[f, b, 0, 0], Sigma[f, b, 0, 1], Sigma[f, b, 1, 0], Sigma[f, b, 1, 1],
                y_info[b, 0], y_info[b, 1], S[b, 0, 0], S[b, 0, 1], S[b, 1, 0], S[b, 1, 1], A, bwb, gL00, gL01, gL10,
                gL11, xpred_gemv)


@njit(cache=True, error_model="numpy")
def _hinf_one(x0, x1, s00, s01, s10, s11, y0, y1, S00, S01, S10, S11, A, BWB, gL00, gL01, gL10, gL11, xpred_gemv):
    """One filter of :func:`hinf_update_kernel`: ``xnew (2), Sigma_k (4), Delta_k (4)`` row-major and the eigenvalue."""
    d00, d01, d10, d11 = _prior(s00, s01, s10, s11, A, BWB)
    if xpred_gemv:  # xpred = xhat @ A.T
        p0, p1 = _mv(A[0, 0], A[0, 1], A[1, 0], A[1, 1], x0, x1)
    else:
        p0 = fma(x1, A[0, 1], x0 * A[0, 0]) + 0.0
        p1 = fma(x1, A[1, 1], x0 * A[1, 0]) + 0.0
    sd00, sd01, sd10, sd11 = _mm(S00, S01, S10, S11, d00, d01, d10, d11)
    m00, m01, m10, m11 = _inv2(1.0 + sd00, 0.0 + sd01, 0.0 + sd10, 1.0 + sd11)
    G00, G01, G10, G11 = _mm(d00, d01, d10, d11, m00, m01, m10, m11)
    q0, q1 = _mv(S00, S01, S10, S11, p0, p1)
    c0, c1 = _mv(G00, G01, G10, G11, y0 - q0, y1 - q1)
    l00, l01, l10, l11 = _mm(gL00, gL01, gL10, gL11, d00, d01, d10, d11)
    o00, o01, o10, o11 = _inv2((1.0 - l00) + sd00, (0.0 - l01) + sd01, (0.0 - l10) + sd10, (1.0 - l11) + sd11)
    e00, e01, e10, e11 = _mm(d00, d01, d10, d11, o00, o01, o10, o11)
    f00, f01, f10, f11 = _information(d00, d01, d10, d11, S00, S01, S10, S11, gL00, gL01, gL10, gL11)
    return (p0 + c0, p1 + c1, 0.5 * (e00 + e00), 0.5 * (e01 + e10), 0.5 * (e10 + e01), 0.5 * (e11 + e11),
            d00, d01, d10, d11, _min_eig2(f00, f01, f10, f11))


@njit(cache=True, error_model="numpy")
def congruence_kernel(X, A, out):
    """``A X A^T`` of ``B`` flattened 2x2 matrices as numpy's ``A @ X @ A.T`` rounds it (two ``dgemm``), into ``out``.

    Parameters
    ----------
    X : ndarray ``(B, 2, 2)``
        The matrices.
    A : ndarray ``(2, 2)``
        The transformation (target dynamics).
    out : ndarray ``(B, 2, 2)``
        Receives ``A X A^T``.
    """
    for b in range(X.shape[0]):
        t00, t01, t10, t11 = _mm(A[0, 0], A[0, 1], A[1, 0], A[1, 1], X[b, 0, 0], X[b, 0, 1], X[b, 1, 0], X[b, 1, 1])
        out[b, 0, 0], out[b, 0, 1], out[b, 1, 0], out[b, 1, 1] = _mm(t00, t01, t10, t11, A[0, 0], A[1, 0], A[0, 1],
                                                                     A[1, 1])


@njit(cache=True, error_model="numpy")
def exists_kernel(S_seq, Sigma0, A, BWB, gamma_inv2, Lbar):
    """Does the filter (6) exist along ``S_seq``: is ``Sigma_k^{-1} > 0`` at every step, for every filter?

    The covariance recursion of :func:`.filters.minimum_attenuation`, filter by filter (a conjunction, so
    the order does not change the answer).

    Parameters
    ----------
    S_seq : ndarray ``(K, B, 2, 2)``
        ``C^T M_k^{-1} C`` of ``B`` filters at each step.
    Sigma0, A, BWB, Lbar : ndarray ``(2, 2)``
        Initial ``Sigma_0`` (every filter's), target dynamics ``A``, ``B W B^T`` and ``Lbar = L^T Q L``.
    gamma_inv2 : float
        ``gamma^{-2}`` of the attenuation level tested.

    Returns
    -------
    bool
        True iff ``Sigma_k^{-1} = Delta_k^{-1} + S_k - gamma^{-2} L^T Q L`` has a positive smallest
        eigenvalue at every step of every filter.
    """
    gL00, gL01, gL10, gL11 = gamma_inv2 * Lbar[0, 0], gamma_inv2 * Lbar[0, 1], gamma_inv2 * Lbar[1, 0], gamma_inv2 * Lbar[1, 1]
    for b in range(S_seq.shape[1]):
        s00, s01, s10, s11 = Sigma0[0, 0], Sigma0[0, 1], Sigma0[1, 0], Sigma0[1, 1]
        for k in range(S_seq.shape[0]):
            d00, d01, d10, d11 = _prior(s00, s01, s10, s11, A, BWB)
            f00, f01, f10, f11 = _information(d00, d01, d10, d11, S_seq[k, b, 0, 0], S_seq[k, b, 0, 1],
                                              S_seq[k, b, 1, 0], S_seq[k, b, 1, 1], gL00, gL01, gL10, gL11)
            if not _min_eig2(f00, f01, f10, f11) > 0:
                return False
            i00, i01, i10, i11 = _inv2(f00, f01, f10, f11)
            s00, s01, s10, s11 = 0.5 * (i00 + i00), 0.5 * (i01 + i10), 0.5 * (i10 + i01), 0.5 * (i11 + i11)
    return True


@njit(cache=True, error_model="numpy")
def sigma_gradient_kernel(Delta, dDelta, S, dS, gamma_inv2, Lbar, Sigma, dSigma):
    """:func:`.motion.sigma_gradient` (eqs (14)-(16), corrected) on ``B`` flattened filters, into the outputs.

    Parameters
    ----------
    Delta, dDelta, S, dS : ndarray ``(B, 2, 2)``
        ``Delta_k``, ``Delta_k^z`` (eq (14)), ``C^T M^{-1} C`` and ``C^T (dM^{-1}/dz) C`` of the ``B`` filters.
    gamma_inv2 : float
        ``gamma^{-2}``.
    Lbar : ndarray ``(2, 2)``
        ``L^T Q L``.
    Sigma, dSigma : ndarray ``(B, 2, 2)``
        Receive ``Sigma_k`` and ``Sigma_k^z``.
    """
    gL00, gL01, gL10, gL11 = gamma_inv2 * Lbar[0, 0], gamma_inv2 * Lbar[0, 1], gamma_inv2 * Lbar[1, 0], gamma_inv2 * Lbar[1, 1]
    for b in range(Delta.shape[0]):
        d00, d01, d10, d11 = Delta[b, 0, 0], Delta[b, 0, 1], Delta[b, 1, 0], Delta[b, 1, 1]
        z00, z01, z10, z11 = dDelta[b, 0, 0], dDelta[b, 0, 1], dDelta[b, 1, 0], dDelta[b, 1, 1]
        S00, S01, S10, S11 = S[b, 0, 0], S[b, 0, 1], S[b, 1, 0], S[b, 1, 1]
        # Omega = I + S Delta - gamma^-2 Lbar Delta
        sd00, sd01, sd10, sd11 = _mm(S00, S01, S10, S11, d00, d01, d10, d11)
        l00, l01, l10, l11 = _mm(gL00, gL01, gL10, gL11, d00, d01, d10, d11)
        o00, o01, o10, o11 = _inv2((1.0 + sd00) - l00, (0.0 + sd01) - l01, (0.0 + sd10) - l10, (1.0 + sd11) - l11)
        e00, e01, e10, e11 = _mm(d00, d01, d10, d11, o00, o01, o10, o11)  # Delta Omega^-1
        a00, a01, a10, a11 = _mm(z00, z01, z10, z11, o00, o01, o10, o11)
        t00, t01, t10, t11 = _mm(e00, e01, e10, e11, dS[b, 0, 0], dS[b, 0, 1], dS[b, 1, 0], dS[b, 1, 1])
        t00, t01, t10, t11 = _mm(t00, t01, t10, t11, e00, e01, e10, e11)
        u00, u01, u10, u11 = _mm(S00, S01, S10, S11, z00, z01, z10, z11)
        v00, v01, v10, v11 = _mm(gL00, gL01, gL10, gL11, z00, z01, z10, z11)
        w00, w01, w10, w11 = _mm(e00, e01, e10, e11, u00 - v00, u01 - v01, u10 - v10, u11 - v11)
        w00, w01, w10, w11 = _mm(w00, w01, w10, w11, o00, o01, o10, o11)
        dSigma[b, 0, 0] = (a00 - t00) - w00
        dSigma[b, 0, 1] = (a01 - t01) - w01
        dSigma[b, 1, 0] = (a10 - t10) - w10
        dSigma[b, 1, 1] = (a11 - t11) - w11
        Sigma[b, 0, 0], Sigma[b, 0, 1], Sigma[b, 1, 0], Sigma[b, 1, 1] = e00, e01, e10, e11


@njit(cache=True, error_model="numpy")
def noise_information_kernel(c, s, rinv_r, rinv_b, d_r, d_b, derivatives, Minv, dMinv_dr, dMinv_dtheta):
    """:func:`.noise.noise_information` (eqs (3), (17)-(18), corrected) on ``B`` flattened sensors, into the outputs.

    ``M^{-1} = T R^{-1} T^T`` with ``T = [[c, -s], [s, c]]`` and the diagonal ``R^{-1} = diag(rinv_r, rinv_b)``;
    with ``derivatives``, ``dM^{-1}/dr = T diag(d_r, d_b) T^T`` and ``dM^{-1}/dtheta = Psi + Psi^T``,
    ``Psi = J M^{-1}``, ``J = [[0, -1], [1, 0]]``.

    Parameters
    ----------
    c, s, rinv_r, rinv_b, d_r, d_b : ndarray ``(B,)``
        ``cos theta``, ``sin theta``, the diagonals of ``R^{-1}`` and of ``R^{-2} diag(1, alpha) g``.
    derivatives : bool
        Also compute the derivatives (else ``dMinv_dr`` and ``dMinv_dtheta`` are not written).
    Minv, dMinv_dr, dMinv_dtheta : ndarray ``(B, 2, 2)``
        Receive ``M^{-1}`` and (with ``derivatives``) its derivatives.
    """
    for b in range(c.shape[0]):
        cb, sb = c[b], s[b]
        ns = -sb
        t00, t01, t10, t11 = _mm(cb, ns, sb, cb, rinv_r[b], 0.0, 0.0, rinv_b[b])
        m00, m01, m10, m11 = _mm(t00, t01, t10, t11, cb, sb, ns, cb)
        Minv[b, 0, 0], Minv[b, 0, 1], Minv[b, 1, 0], Minv[b, 1, 1] = m00, m01, m10, m11
        if derivatives:
            t00, t01, t10, t11 = _mm(cb, ns, sb, cb, d_r[b], 0.0, 0.0, d_b[b])
            r00, r01, r10, r11 = _mm(t00, t01, t10, t11, cb, sb, ns, cb)
            dMinv_dr[b, 0, 0], dMinv_dr[b, 0, 1], dMinv_dr[b, 1, 0], dMinv_dr[b, 1, 1] = r00, r01, r10, r11
            p00, p01, p10, p11 = _mm(0.0, -1.0, 1.0, 0.0, m00, m01, m10, m11)
            dMinv_dtheta[b, 0, 0] = p00 + p00
            dMinv_dtheta[b, 0, 1] = p01 + p10
            dMinv_dtheta[b, 1, 0] = p10 + p01
            dMinv_dtheta[b, 1, 1] = p11 + p11


@njit(cache=True, error_model="numpy")
def rotate_kernel(c, s, v0, v1, out):
    """``T(theta) v`` with ``T = [[c, -s], [s, c]]`` of eq (3) on ``B`` flattened sensors, as numpy's ``matmul`` rounds it.

    The last step of :func:`.noise.sample_noise` (``rotation(theta) @ local[..., None]``, a ``dgemv`` per
    sensor): ``out_i = fma(T_i0, v_0, T_i1 v_1) + 0.0``.

    Parameters
    ----------
    c, s, v0, v1 : ndarray ``(B,)``
        ``cos theta``, ``sin theta`` and the vector's components.
    out : ndarray ``(B, 2)``
        Receives ``T v``.
    """
    for b in range(c.shape[0]):
        out[b, 0], out[b, 1] = _mv(c[b], -s[b], s[b], c[b], v0[b], v1[b])
