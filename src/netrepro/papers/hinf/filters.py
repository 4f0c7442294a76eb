"""The H-infinity filters of the `hinf` paper: centralized (6), decentralized (9), their Kalman limit, gamma_0.

All filters are written in the information form of Section III: with ``C_i = I_2``,
``S = sum_i C_i^T M_i^{-1} C_i`` and ``y_info = sum_i C_i^T M_i^{-1} y_i``.
"""

from __future__ import annotations

import numpy as np

from ...errors import ModelError
from .algebra import I2, inv2, kernel_operand, min_eig2, sym2, use_compiled

__all__ = [
    "FilterDoesNotExist", "hinf_information", "hinf_update", "hinf_update_batch", "congruence", "decentralized_update", "kalman_update",
    "minimum_attenuation", "steady_state_prior", "gain_norms",
]


class FilterDoesNotExist(ModelError):
    """The H-infinity filter does not exist: gamma is below the minimum attenuation level gamma_0.

    Raised when the information matrix ``Sigma_k^{-1} = Delta_k^{-1} + C^T M^{-1} C - gamma^{-2} L^T Q L``
    of eq (6) (or (9)) is not positive definite at some step.

    Parameters
    ----------
    *args
        The message, as for any exception: it names gamma and the step.
    """


def hinf_information(Delta, S, gamma_inv2: float, Lbar):
    """Information matrix ``Sigma^{-1} = Delta^{-1} + S - gamma^{-2} L^T Q L`` of eq (6).

    The filter exists at this step iff it is positive definite.

    Parameters
    ----------
    Delta, S : ndarray, shape ``(..., 2, 2)``
        Prior covariance ``Delta_k`` and ``C^T M^{-1} C``.
    gamma_inv2 : float
        ``gamma^{-2}``.
    Lbar : ndarray, shape ``(2, 2)``
        ``L^T Q L``.

    Returns
    -------
    ndarray, shape ``(..., 2, 2)``
        The symmetrised information matrix.
    """
    return sym2(inv2(Delta) + S - gamma_inv2 * Lbar)


def hinf_update(xhat, Sigma, y_info, S, A, BWB, gamma_inv2: float, Lbar, check: bool = True,
                kernel: str = "auto"):
    """One step of the centralized H-infinity filter, eq (6), in its information form.

    .. math::

        \\Delta_k &= A \\Sigma_{k-1} A^T + B W_{k-1} B^T \\\\
        K_k &= \\Delta_k (I + C^T M_k^{-1} C \\Delta_k)^{-1} C^T M_k^{-1} \\\\
        \\hat x_k &= A \\hat x_{k-1} + K_k (y_k - C A \\hat x_{k-1}) \\\\
        \\Sigma_k &= \\Delta_k (I - \\gamma^{-2} L_k^T Q_k L_k \\Delta_k + C^T M_k^{-1} C \\Delta_k)^{-1}

    Using ``C^T M^{-1} C = S`` and ``C^T M^{-1} y = y_info`` (the sums of Section III),
    ``K_k (y_k - C A x) = Delta (I + S Delta)^{-1} (y_info - S A x)``.
    With ``gamma_inv2 = 0`` this is the Kalman filter.

    Parameters
    ----------
    xhat : ndarray, shape ``(..., 2)``
        Previous estimate.
    Sigma : ndarray, shape ``(..., 2, 2)``
        Previous ``Sigma_{k-1}``.
    y_info : ndarray, shape ``(..., 2)``
        ``C^T M^{-1} y``.
    S : ndarray, shape ``(..., 2, 2)``
        ``C^T M^{-1} C``.
    A, BWB, Lbar : ndarray, shape ``(2, 2)``
        Target dynamics, ``B W B^T`` and ``Lbar = L^T Q L``.
    gamma_inv2 : float
        ``gamma^{-2}``.
    check : bool
        Raise :class:`FilterDoesNotExist` when ``Sigma_k^{-1}`` is not positive definite.
    kernel : {"auto", "compiled", "numpy"}
        ``"compiled"``: :func:`.filter_kernels.hinf_update_kernel`, the same arithmetic filter by filter
        (bit-identical); ``"numpy"``: the reference form; ``"auto"``: see :func:`.algebra.use_compiled`.

    Returns
    -------
    xhat, Sigma, Delta, min_info_eig : ndarray
        New estimate and ``Sigma_k``, the prior ``Delta_k``, and the smallest eigenvalue of ``Sigma_k^{-1}``.

    Raises
    ------
    FilterDoesNotExist
        If ``check`` and ``Sigma_k^{-1}`` is not positive definite (gamma below gamma_0).
    """
    if use_compiled(kernel, np.size(Sigma) // 4):
        xnew, Sig, Delta, info_eig = _hinf_update_compiled(xhat, Sigma, y_info, S, A, BWB, gamma_inv2, Lbar)
    else:
        xnew, Sig, Delta, info_eig = _hinf_update_numpy(xhat, Sigma, y_info, S, A, BWB, gamma_inv2, Lbar)
    if check and not np.all(info_eig > 0):
        raise FilterDoesNotExist(
            f"Sigma^-1 not positive definite (min eigenvalue {np.min(info_eig):.3g}): gamma below gamma_0")
    return xnew, Sig, Delta, info_eig


def _hinf_update_numpy(xhat, Sigma, y_info, S, A, BWB, gamma_inv2, Lbar):
    """Eq (6) in numpy (the reference form of :func:`hinf_update`): ``xhat, Sigma, Delta, min_info_eig``."""
    Delta = A @ Sigma @ A.T + BWB
    xpred = xhat @ A.T
    G = Delta @ inv2(I2 + S @ Delta)
    xnew = xpred + (G @ (y_info - (S @ xpred[..., None])[..., 0])[..., None])[..., 0]
    Omega = I2 - gamma_inv2 * Lbar @ Delta + S @ Delta
    Sig = sym2(Delta @ inv2(Omega))
    info_eig = min_eig2(hinf_information(Delta, S, gamma_inv2, Lbar))
    return xnew, Sig, Delta, info_eig


def _hinf_update_compiled(xhat, Sigma, y_info, S, A, BWB, gamma_inv2, Lbar):
    """Eq (6) by :func:`.filter_kernels.hinf_update_kernel`, bit-identical to :func:`_hinf_update_numpy`."""
    from .filter_kernels import hinf_update_kernel  # numba: imported by the steps that run a filter

    xhat, Sigma, y_info, S = (np.asarray(a, dtype=float) for a in (xhat, Sigma, y_info, S))
    lead = np.broadcast_shapes(xhat.shape[:-1], Sigma.shape[:-2], y_info.shape[:-1], S.shape[:-2])
    # numpy's ``xhat @ A.T`` is a dgemv (another rounding order) when xhat has a single row per stack
    xpred_gemv = xhat.ndim == 1 or xhat.shape[-2] == 1

    def flat(a, tail):
        return kernel_operand(a, lead + tail).reshape((-1,) + tail)

    xnew, Sig, Delta = np.empty(lead + (2,)), np.empty(lead + (2, 2)), np.empty(lead + (2, 2))
    info_eig = np.empty(lead)
    hinf_update_kernel(flat(xhat, (2,)), flat(Sigma, (2, 2)), flat(y_info, (2,)), flat(S, (2, 2)),
                       *(np.array(m, dtype=float, order="C") for m in (A, BWB)), float(gamma_inv2),
                       np.array(Lbar, dtype=float, order="C"), bool(xpred_gemv), xnew.reshape(-1, 2),
                       Sig.reshape(-1, 2, 2), Delta.reshape(-1, 2, 2), info_eig.reshape(-1))
    return xnew, Sig, Delta, info_eig


def hinf_update_batch(xhat, Sigma, y_info, S, A, BWB, gamma_inv2, Lbar, check: bool = True, kernel: str = "auto"):
    """:func:`hinf_update` of ``F`` filters (their own ``B W B^T`` and gamma) fed the same measurements, stacked.

    Filter ``f`` gets ``hinf_update(xhat[f], Sigma[f], y_info, S, A, BWB[f], gamma_inv2[f], Lbar)``, with the
    same numbers (the compiled form runs :func:`.filter_kernels.hinf_update_batch_kernel` in one call).

    Parameters
    ----------
    xhat : ndarray, shape ``(F, ..., 2)``
        Previous estimates of the ``F`` filters.
    Sigma : ndarray, shape ``(F, ..., 2, 2)``
        Their previous ``Sigma_{k-1}``.
    y_info : ndarray, shape ``(..., 2)``
        ``C^T M^{-1} y``, shared by the filters.
    S : ndarray, shape ``(..., 2, 2)``
        ``C^T M^{-1} C``, shared by the filters.
    A : ndarray, shape ``(2, 2)``
        Target dynamics.
    Lbar : ndarray, shape ``(2, 2)``
        ``L^T Q L``.
    BWB : ndarray, shape ``(F, 2, 2)``
        Each filter's ``B W B^T``.
    gamma_inv2 : array_like, shape ``(F,)``
        Each filter's ``gamma^{-2}`` (0: Kalman filter).
    check : bool
        Raise :class:`FilterDoesNotExist` when some filter's ``Sigma_k^{-1}`` is not positive definite.
    kernel : {"auto", "compiled", "numpy"}
        As in :func:`hinf_update` (``"numpy"``: :func:`hinf_update` filter by filter).

    Returns
    -------
    xhat, Sigma, Delta, min_info_eig : ndarray
        Stacked as :func:`hinf_update` returns them, with the leading axis ``F``.

    Raises
    ------
    FilterDoesNotExist
        If ``check`` and some filter does not exist at this step.
    """
    xhat, Sigma = np.asarray(xhat, dtype=float), np.asarray(Sigma, dtype=float)
    BWB, gamma_inv2 = np.asarray(BWB, dtype=float), np.asarray(gamma_inv2, dtype=float)
    F = xhat.shape[0]
    if use_compiled(kernel, np.size(Sigma) // 4):
        from .filter_kernels import hinf_update_batch_kernel  # numba: imported by the steps that run a filter

        y_info, S = np.asarray(y_info, dtype=float), np.asarray(S, dtype=float)
        lead = np.broadcast_shapes(xhat.shape[1:-1], Sigma.shape[1:-2], y_info.shape[:-1], S.shape[:-2])
        xpred_gemv = xhat.ndim == 2 or xhat.shape[-2] == 1  # as in _hinf_update_compiled, for one filter's xhat
        out = (np.empty((F,) + lead + (2,)), np.empty((F,) + lead + (2, 2)), np.empty((F,) + lead + (2, 2)),
               np.empty((F,) + lead))
        hinf_update_batch_kernel(
            kernel_operand(xhat, (F,) + lead + (2,)).reshape(F, -1, 2),
            kernel_operand(Sigma, (F,) + lead + (2, 2)).reshape(F, -1, 2, 2),
            kernel_operand(y_info, lead + (2,)).reshape(-1, 2), kernel_operand(S, lead + (2, 2)).reshape(-1, 2, 2),
            np.array(A, dtype=float, order="C"), kernel_operand(BWB, (F, 2, 2)), kernel_operand(gamma_inv2, (F,)),
            np.array(Lbar, dtype=float, order="C"), bool(xpred_gemv), out[0].reshape(F, -1, 2),
            out[1].reshape(F, -1, 2, 2), out[2].reshape(F, -1, 2, 2), out[3].reshape(F, -1))
    else:
        each = [hinf_update(xhat[f], Sigma[f], y_info, S, A, BWB[f], float(gamma_inv2[f]), Lbar, check=False,
                            kernel="numpy") for f in range(F)]
        out = tuple(np.stack([e[i] for e in each]) for i in range(4))
    if check and not np.all(out[3] > 0):
        raise FilterDoesNotExist(
            f"Sigma^-1 not positive definite (min eigenvalue {np.min(out[3]):.3g}): gamma below gamma_0")
    return out


def congruence(A, X, kernel: str = "auto"):
    """``A X A^T`` for a stack of 2x2 matrices (the prior's propagation in eqs (6) and (14)), as ``A @ X @ A.T``.

    Parameters
    ----------
    A : ndarray, shape ``(2, 2)``
        Target dynamics.
    X : ndarray, shape ``(..., 2, 2)``
        The matrices.
    kernel : {"auto", "compiled", "numpy"}
        ``"compiled"``: :func:`.filter_kernels.congruence_kernel` (bit-identical to numpy's ``matmul``);
        ``"numpy"``: ``A @ X @ A.T``; ``"auto"``: see :func:`.algebra.use_compiled`.

    Returns
    -------
    ndarray, shape of ``X``
    """
    X = np.asarray(X, dtype=float)
    if not use_compiled(kernel, X.size // 4):
        return A @ X @ A.T
    from .filter_kernels import congruence_kernel  # numba: imported by the steps that run a filter

    out = np.empty(X.shape)
    congruence_kernel(kernel_operand(X, X.shape).reshape(-1, 2, 2), np.array(A, dtype=float, order="C"),
                      out.reshape(-1, 2, 2))
    return out


def decentralized_update(xhat, Sigma, y_tilde, C_tilde, n_agents: int, A, BWB, gamma_inv2, Lbar, check=True):
    """One step of the decentralized H-infinity filter of agent i, eq (9).

    .. math::

        \\tilde K_k &= \\Delta_k (I + N \\tilde C \\Delta_k)^{-1} \\\\
        \\hat x_k &= A \\hat x_{k-1} + N \\tilde K_k (\\tilde y_k - \\tilde C A \\hat x_{k-1}) \\\\
        \\Sigma_k &= \\Delta_k (I - \\gamma^{-2} L_k^T Q_k L_k \\Delta_k + N \\tilde C \\Delta_k)^{-1}

    with ``C_tilde`` and ``y_tilde`` the consensus estimates of the averages (7)-(8).
    It is eq (6) with ``S = N C_tilde`` and ``y_info = N y_tilde``: with exact
    consensus it equals the centralized filter.

    Parameters
    ----------
    xhat, Sigma : ndarray, shapes ``(..., 2)``, ``(..., 2, 2)``
        The agent's previous estimate ``xhat_{k-1}`` and ``Sigma_{k-1}``.
    y_tilde, C_tilde : ndarray, shapes ``(..., 2)``, ``(..., 2, 2)``
        Consensus estimates of the averages (8) and (7).
    n_agents : int
        ``N``.
    A, BWB, Lbar : ndarray, shape ``(2, 2)``
        Target dynamics ``A``, ``B W B^T`` and ``Lbar = L^T Q L``.
    gamma_inv2 : float
        ``gamma^{-2}`` (0: the Kalman filter).
    check : bool
        Raise :class:`FilterDoesNotExist` when ``Sigma_k^{-1}`` is not positive definite.

    Returns
    -------
    xhat, Sigma, Delta, min_info_eig : ndarray
        As :func:`hinf_update`.

    Raises
    ------
    FilterDoesNotExist
        If ``check`` and the filter does not exist at this step.
    """
    return hinf_update(xhat, Sigma, n_agents * y_tilde, n_agents * C_tilde, A, BWB, gamma_inv2, Lbar, check)


def kalman_update(xhat, P, y, M, A, BWB):
    """Textbook Kalman filter with stacked measurements ``y_i = x + m_i``, written independently of (6).

    Used by the tests and the filter checks as the reference for the ``gamma -> infinity`` limit.

    Parameters
    ----------
    xhat, P : ndarray, shapes ``(..., 2)``, ``(..., 2, 2)``
        Previous estimate and covariance.
    y : ndarray, shape ``(..., N, 2)``
        Measurements; stacked ``C = [I; ...; I]``.
    M : ndarray, shape ``(..., N, 2, 2)``
        Their noise covariances.
    A, BWB : ndarray, shape ``(2, 2)``
        Target dynamics ``A`` and process noise covariance ``B W B^T``.

    Returns
    -------
    xhat, P : ndarray
        Updated estimate and covariance.
    """
    n = y.shape[-2]
    Delta = A @ P @ A.T + BWB
    xpred = xhat @ A.T
    C = np.tile(I2, (n, 1))
    lead = M.shape[:-3]
    Mbig = np.zeros(lead + (2 * n, 2 * n))
    for i in range(n):
        Mbig[..., 2 * i:2 * i + 2, 2 * i:2 * i + 2] = M[..., i, :, :]
    Sinn = C @ Delta @ C.T + Mbig
    K = Delta @ C.T @ np.linalg.inv(Sinn)
    innov = y.reshape(lead + (2 * n,)) - (C @ xpred[..., None])[..., 0]
    xnew = xpred + (K @ innov[..., None])[..., 0]
    Pnew = (np.eye(2) - K @ C) @ Delta
    return xnew, sym2(Pnew)


def _exists_numpy(S_seq, Sigma0, A, BWB, gamma_inv2, Lbar):
    """Is ``Sigma_k^{-1}`` of eq (6) positive definite at every step ``k`` of ``S_seq (K, ..., 2, 2)``?"""
    Sig = np.broadcast_to(np.asarray(Sigma0, dtype=float), S_seq.shape[1:]).copy()
    for S in S_seq:
        Delta = A @ Sig @ A.T + BWB
        info = hinf_information(Delta, S, gamma_inv2, Lbar)
        if not np.all(min_eig2(info) > 0):
            return False
        Sig = sym2(inv2(info))
    return True


def minimum_attenuation(S_seq, Sigma0, A, BWB, Lbar, lo=1e-3, hi=1e3, tol=1e-6, kernel="auto"):
    """Minimum attenuation level ``gamma_0`` of eq (6) along a sequence of informations.

    ``gamma_0`` is the infimum of the ``gamma`` for which ``Sigma_k^{-1} > 0`` for every step
    (the existence condition of the a-posteriori H-infinity filter). Feasibility is
    monotone in ``gamma``; found by bisection on ``log gamma``.

    Parameters
    ----------
    S_seq : ndarray, shape ``(K, ..., 2, 2)``
        ``C^T M_k^{-1} C`` for each step (leading axes after time are batched; gamma_0 is the max).
    Sigma0 : ndarray, shape ``(2, 2)``
        Initial ``Sigma_0`` of the recursion.
    A, BWB, Lbar : ndarray, shape ``(2, 2)``
        Target dynamics ``A``, ``B W B^T`` and ``Lbar = L^T Q L``.
    lo, hi : float
        Bracket of the bisection.
    tol : float
        Tolerance on ``log gamma``.
    kernel : {"auto", "compiled", "numpy"}
        ``"compiled"``: each existence test by :func:`.filter_kernels.exists_kernel` (same arithmetic, filter
        by filter, stopping at the first failure; same answer); ``"numpy"``: the reference form; ``"auto"``:
        see :func:`.algebra.use_compiled` (counting every step's matrices).

    Returns
    -------
    float
        ``gamma_0`` (``lo`` if the filter exists at ``lo``, inf if not even at ``hi``).
    """
    S_seq = np.asarray(S_seq, dtype=float)
    if use_compiled(kernel, S_seq.size // 4):
        from .filter_kernels import exists_kernel  # numba: imported by the steps that run a filter

        flat = np.array(S_seq.reshape((S_seq.shape[0], -1, 2, 2)), dtype=float, order="C")
        mats = [np.array(m, dtype=float, order="C") for m in (Sigma0, A, BWB, Lbar)]

        def exists(gamma):
            return exists_kernel(flat, mats[0], mats[1], mats[2], gamma ** -2.0, mats[3])
    else:
        def exists(gamma):
            return _exists_numpy(S_seq, Sigma0, A, BWB, gamma ** -2.0, Lbar)

    if exists(lo):
        return lo
    if not exists(hi):
        return np.inf
    a, b = np.log(lo), np.log(hi)
    while b - a > tol:
        m = 0.5 * (a + b)
        if exists(np.exp(m)):
            b = m
        else:
            a = m
    return float(np.exp(b))


def steady_state_prior(S, W: float, gamma_inv2: float, Lbar, n_iter: int = 3000):
    """Steady-state prior ``Delta`` of the Riccati recursion of eq (6) with ``A = B = I`` (fixed-point iteration).

    Iterates ``Sigma = Delta (I - gamma^-2 Lbar Delta + S Delta)^-1``, ``Delta = Sigma + W I``.

    Parameters
    ----------
    S : ndarray, shape ``(..., 2, 2)``
        ``C^T M^-1 C`` (one per filter).
    W : float
        Design process noise (``W I``).
    gamma_inv2 : float
        ``gamma^-2`` (0: Kalman filter).
    Lbar : ndarray, shape ``(2, 2)``
        ``L^T Q L``.
    n_iter : int
        Iterations from ``Delta = W I``.

    Returns
    -------
    ndarray, shape ``(..., 2, 2)``
    """
    S = np.asarray(S, dtype=float)
    eye = np.broadcast_to(np.eye(2), S.shape)
    Delta = W * eye.copy()
    prev = None
    for i in range(n_iter):
        Sigma = Delta @ np.linalg.inv(eye - gamma_inv2 * Lbar @ Delta + S @ Delta)
        new = 0.5 * (Sigma + np.swapaxes(Sigma, -1, -2)) + W * eye
        if prev is not None and new.tobytes() == prev.tobytes():
            # the iterates now repeat with period 1 or 2, bit for bit (the map is deterministic): the last one
            # of the n_iter is known without computing the rest
            return new if (n_iter - 1 - i) % 2 == 0 else Delta
        prev, Delta = Delta, new
    return Delta


def gain_norms(Delta, S, Minv):
    """Spectral norms of the gain ``K_k = Delta (I + S Delta)^-1 C^T M^-1`` of eq (6) and of ``K~_k`` of eq (9).

    For a filter whose measurement is ``y`` with information ``Minv = C^T M^-1`` (``C = I``),
    ``K_k = Delta (I + S Delta)^-1 Minv``; with exact averages ``N C~ = S``, eq (9)'s
    ``K~_k = Delta (I + N C~ Delta)^-1 = Delta (I + S Delta)^-1``.

    Parameters
    ----------
    Delta : ndarray, shape ``(..., 2, 2)``
        Prior covariance (e.g. :func:`steady_state_prior`).
    S : ndarray, shape ``(..., 2, 2)``
        Information ``C^T M^-1 C`` of the filter (``N C~`` for eq (9)).
    Minv : ndarray, shape ``(..., 2, 2)``
        Information of the measurement the gain multiplies.

    Returns
    -------
    K, K_tilde : ndarray
        Spectral norms, shape ``S.shape[:-2]``.
    """
    G = Delta @ np.linalg.inv(np.eye(2) + S @ Delta)
    return np.linalg.norm(G @ Minv, ord=2, axis=(-2, -1)), np.linalg.norm(G, ord=2, axis=(-2, -1))
