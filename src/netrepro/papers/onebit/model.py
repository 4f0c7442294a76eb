"""The state model and the general Bayesian information recursions of the paper.

* Moments of :math:`\\theta_k` (31)-(33) and the SNR convention (not defined in the paper;
  config key ``snr_definition``): ``"stationary"`` (default) SNR =
  sigma_theta_inf^2 / sigma_eta^2 with sigma_theta_inf^2 = sigma_z^2 / (1 - alpha^2) from (33);
  ``"innovation"`` SNR = sigma_z^2 / sigma_eta^2.
* Recursive Bayesian information matrices (BIMs) for filtering (7), prediction (14) and
  smoothing (16)-(19) in general vector form, with the blocks (8)-(10); the printed forms of
  (14), (16), (18) (errata E1-E3) and the Kalman/RTS covariances they must reproduce.

Conventions: ``D11, D12, D22`` are the blocks (8)-(10) of the transition
``p(theta_k | theta_{k-1})``; rows of ``D12`` belong to ``theta_{k-1}``, ``D21 = D12^T``. The
prediction and smoothing recursions are implemented in their *corrected* form. The random walk
is parameterised by ``eps = 1 - alpha`` so that ``1 - alpha^2 = eps (2 - eps)`` stays exact as
``alpha -> 1``.
"""

from __future__ import annotations

import math

import numpy as np

from ...errors import InputError

__all__ = [
    "SNR_DEFINITIONS",
    "snr_grid",
    "theta_mean",
    "theta_variance",
    "stationary_variance",
    "sigma_z2_from_snr",
    "axis_shift_db",
    "linear_gaussian_blocks",
    "filtering_bim_step",
    "prediction_bim_step",
    "smoothing_bim_step",
    "smoothing_gain_step",
    "filtering_bims",
    "prediction_bims",
    "smoothing_bims",
    "smoothing_bims_via_gain",
    "printed_prediction_step",
    "printed_smoothing_gain_step",
    "printed_smoothing_bim_step",
    "kalman_covariances",
    "vector_check",
    "prior_check",
]

SNR_DEFINITIONS = ("stationary", "innovation")


def snr_grid(start: float, stop: float, step: float):
    """The SNR grid ``start, start + step, ..., stop`` (dB), exact multiples of ``step``.

    Parameters
    ----------
    start, stop, step : float
        Grid ends and spacing in dB.

    Returns
    -------
    ndarray
        ``start + step * arange(n + 1)`` with ``n = round((stop - start) / step)``.
    """
    n = int(round((stop - start) / step))
    return start + step * np.arange(n + 1)


# ============================================================================ theta moments, SNR
def theta_mean(k, alpha: float, mu0: float):
    r"""Mean of :math:`\theta_k`, eq. (31): :math:`\alpha^k \mu_0`.

    Parameters
    ----------
    k : array_like
        Time steps.
    alpha : float
        Transition coefficient.
    mu0 : float
        Prior mean of :math:`\theta_0`.

    Returns
    -------
    ndarray
        :math:`E[\theta_k]`.
    """
    return alpha ** np.asarray(k, dtype=float) * mu0


def theta_variance(k, eps: float, sigma0: float, sigma_z2):
    r"""Variance of :math:`\theta_k` (corrected eq. (32)).

    .. math::

        \mathrm{Var}[\theta_k] = \alpha^{2k}\sigma_0^2 + \sum_{i=1}^{k}\alpha^{2(k-i)}\sigma_z^2
        = \alpha^{2k}\sigma_0^2 + \frac{1-\alpha^{2k}}{1-\alpha^2}\sigma_z^2 ,

    with :math:`\alpha = 1 - \varepsilon`. The printed (32) stops the sum at
    ``k - 1`` (erratum E4); its limit would then be :math:`\alpha^2\sigma_z^2/(1-\alpha^2)`,
    not (33). Evaluated with ``expm1``/``log1p`` so that ``alpha -> 1`` is exact.

    Parameters
    ----------
    k : array_like
        Time steps.
    eps : float
        ``1 - alpha`` of the random walk (21).
    sigma0 : float
        Prior standard deviation of :math:`\theta_0`.
    sigma_z2 : float or ndarray
        Transition noise variance :math:`\sigma_z^2`.

    Returns
    -------
    ndarray
        :math:`\mathrm{Var}[\theta_k]`, broadcast shape of ``k`` and ``sigma_z2``.
    """
    k = np.asarray(k, dtype=float)
    log_a2k = 2.0 * k * math.log1p(-eps)
    one_minus = -np.expm1(log_a2k)
    om2 = eps * (2.0 - eps)
    series = one_minus / om2 if om2 > 0 else k
    return np.exp(log_a2k) * sigma0**2 + series * sigma_z2


def stationary_variance(eps: float, sigma_z2):
    r"""Eq. (33): :math:`\sigma^2_{\theta,\infty} = \sigma_z^2/(1-\alpha^2)`, with :math:`1-\alpha^2 = \varepsilon(2-\varepsilon)`.

    Parameters
    ----------
    eps : float
        ``1 - alpha`` of the random walk (21).
    sigma_z2 : float or ndarray
        Transition noise variance :math:`\sigma_z^2`.

    Returns
    -------
    ndarray
        :math:`\sigma^2_{\theta,\infty}`.
    """
    return np.asarray(sigma_z2, dtype=float) / (eps * (2.0 - eps))


def sigma_z2_from_snr(snr_db, eps: float, sigma_eta: float = 1.0, definition: str = "stationary"):
    r"""Transition noise variance :math:`\sigma_z^2` for an SNR in dB.

    ``"stationary"``: SNR = :math:`\sigma^2_{\theta,\infty}/\sigma_\eta^2`, so
    :math:`\sigma_z^2 = \mathrm{SNR}\,\sigma_\eta^2\,\varepsilon(2-\varepsilon)` (via (33)).
    ``"innovation"``: SNR = :math:`\sigma_z^2/\sigma_\eta^2`.

    Parameters
    ----------
    snr_db : array_like
        SNR in dB.
    eps : float
        ``1 - alpha`` of the random walk (21).
    sigma_eta : float
        Noise standard deviation.
    definition : {'stationary', 'innovation'}
        SNR convention.

    Returns
    -------
    ndarray
        :math:`\sigma_z^2`, shape of ``snr_db``.

    Raises
    ------
    InputError
        If ``definition`` is not one of :data:`SNR_DEFINITIONS`.
    """
    if definition not in SNR_DEFINITIONS:
        raise InputError(f"definition must be one of {SNR_DEFINITIONS}, got {definition!r}")
    snr = 10.0 ** (np.asarray(snr_db, dtype=float) / 10.0)
    if definition == "stationary":
        return snr * sigma_eta**2 * eps * (2.0 - eps)
    return snr * sigma_eta**2


# ============================================================================ general vector BIMs
def axis_shift_db(eps: float) -> float:
    r"""SNR-axis shift between the two SNR readings at fixed alpha: :math:`10\log_{10}(1-\alpha^2)`, by (33).

    With :math:`\sigma^2_{\theta,\infty} = \sigma_z^2/(1-\alpha^2)`, the innovation SNR
    :math:`\sigma_z^2/\sigma_\eta^2` equals the stationary SNR
    :math:`\sigma^2_{\theta,\infty}/\sigma_\eta^2` times :math:`1-\alpha^2 = \varepsilon(2-\varepsilon)`.

    Parameters
    ----------
    eps : float
        ``1 - alpha``, in (0, 1].

    Returns
    -------
    float
        The shift in dB (negative): innovation SNR = stationary SNR + shift.
    """
    return 10.0 * math.log10(eps * (2.0 - eps))


def _as_mat(x):
    return np.atleast_2d(np.asarray(x, dtype=float))


def linear_gaussian_blocks(A, Q):
    r"""Blocks (8)-(10) for :math:`\theta_k = A\theta_{k-1} + z_k`, :math:`z_k \sim N(0, Q)`.

    .. math::

        D^{11} = A^T Q^{-1} A,\quad D^{12} = -A^T Q^{-1},\quad D^{22} = Q^{-1};

    the scalar case is eq. (22). Returns ``(D11, D12, D22)``.

    Parameters
    ----------
    A : array_like (M, M)
        Transition matrix.
    Q : array_like (M, M)
        Transition noise covariance (positive definite).

    Returns
    -------
    tuple of ndarray (M, M)
        ``(D11, D12, D22)``.

    Raises
    ------
    InputError
        If ``A`` is not square or ``Q`` has another shape.
    """
    A, Q = _as_mat(A), _as_mat(Q)
    if A.shape[0] != A.shape[1] or Q.shape != A.shape:
        raise InputError(f"A must be square and Q of the same shape; got A {A.shape}, Q {Q.shape}")
    Qi = np.linalg.inv(Q)
    return A.T @ Qi @ A, -A.T @ Qi, Qi


def _sym(M):
    return 0.5 * (M + M.T)


def filtering_bim_step(J_prev, D11, D12, D22, F):
    r"""One step of the filtering BIM recursion, eq. (7).

    .. math::

        J_{k|k} = D^{22}_k + E[F(\theta_k)] - D^{21}_k (J_{k-1|k-1} + D^{11}_k)^{-1} D^{12}_k,
        \quad D^{21} = D^{12\,T}.

    Parameters
    ----------
    J_prev : array_like (M, M)
        :math:`J_{k-1|k-1}`.
    D11, D12, D22 : array_like (M, M)
        Blocks (8)-(10) of the transition (see :func:`linear_gaussian_blocks`).
    F : array_like (M, M)
        Expected measurement information :math:`E[F(\theta_k)]`.

    Returns
    -------
    ndarray (M, M)
        :math:`J_{k|k}`.
    """
    D12 = _as_mat(D12)
    return _sym(_as_mat(D22) + _as_mat(F) - D12.T @ np.linalg.solve(_as_mat(J_prev) + _as_mat(D11), D12))


def prediction_bim_step(J_prev, D11, D12, D22):
    r"""One step of the prediction BIM recursion, eq. (14) corrected.

    .. math::

        J_{l|k} = D^{22}_l - D^{21}_l (D^{11}_l + J_{l-1|k})^{-1} D^{12}_l .

    The printed (14) has :math:`D^{12}(\cdot)^{-1}D^{21}`, which propagates
    with :math:`A^T` instead of :math:`A` (erratum E1).

    Parameters
    ----------
    J_prev : array_like (M, M)
        :math:`J_{l-1|k}`.
    D11, D12, D22 : array_like (M, M)
        Blocks (8)-(10) of the transition (see :func:`linear_gaussian_blocks`).

    Returns
    -------
    ndarray (M, M)
        :math:`J_{l|k}`.
    """
    D12 = _as_mat(D12)
    return _sym(_as_mat(D22) - D12.T @ np.linalg.solve(_as_mat(J_prev) + _as_mat(D11), D12))


def smoothing_bim_step(J_ll, J_next_smooth, J_next_pred, D11, D12, D22):
    r"""One backward step of the smoothing BIM, eq. (16) corrected.

    .. math::

        J_{l|k} = J_{l|l} + D^{11}_{l+1}
        - D^{12}_{l+1}(D^{22}_{l+1} + J_{l+1|k} - J_{l+1|l})^{-1} D^{21}_{l+1}

    (the Schur complement of the joint information of
    :math:`(\theta_l, \theta_{l+1})`); the printed (16) swaps
    :math:`D^{12}` and :math:`D^{21}` (erratum E2).

    Parameters
    ----------
    J_ll : array_like (M, M)
        Filtering BIM :math:`J_{l|l}`.
    J_next_smooth : array_like (M, M)
        :math:`J_{l+1|k}`.
    J_next_pred : array_like (M, M)
        One-step prediction BIM :math:`J_{l+1|l}`.
    D11, D12, D22 : array_like (M, M)
        Blocks (8)-(10) of the transition (see :func:`linear_gaussian_blocks`).

    Returns
    -------
    ndarray (M, M)
        :math:`J_{l|k}`.
    """
    D12 = _as_mat(D12)
    X = _as_mat(D22) + _as_mat(J_next_smooth) - _as_mat(J_next_pred)
    return _sym(_as_mat(J_ll) + _as_mat(D11) - D12 @ np.linalg.solve(X, D12.T))


def smoothing_gain_step(kappa_next, D11, D12, D22, F_next):
    r"""One backward step of the smoothing gain, eqs. (18)-(19) corrected.

    .. math::

        \kappa(l|k) = D^{11}_{l+1} - D^{12}_{l+1}(D^{22}_{l+1} + E[F(\theta_{l+1})]
        + \kappa(l+1|k))^{-1} D^{21}_{l+1},

    with :math:`\kappa(k|k) = 0`, which gives (19). The printed (18)-(19)
    swap :math:`D^{12}` and :math:`D^{21}` (erratum E3).

    Parameters
    ----------
    kappa_next : array_like (M, M)
        :math:`\kappa(l+1|k)`.
    D11, D12, D22 : array_like (M, M)
        Blocks (8)-(10) of the transition (see :func:`linear_gaussian_blocks`).
    F_next : array_like (M, M)
        :math:`E[F(\theta_{l+1})]`.

    Returns
    -------
    ndarray (M, M)
        :math:`\kappa(l|k)`.
    """
    D12 = _as_mat(D12)
    X = _as_mat(D22) + _as_mat(F_next) + _as_mat(kappa_next)
    return _sym(_as_mat(D11) - D12 @ np.linalg.solve(X, D12.T))


def _seq(x, n):
    x = np.asarray(x, dtype=float)
    if x.ndim == 3:
        if len(x) != n:
            raise InputError(f"a time-varying argument needs {n} matrices, got {len(x)}")
        return x
    return np.broadcast_to(_as_mat(x), (n,) + _as_mat(x).shape)


def filtering_bims(J0, D11, D12, D22, F, n_steps: int):
    r"""Filtering BIMs ``J_{0|0}, ..., J_{n|n}`` by (7); returns shape ``(n+1, M, M)``.

    ``D11, D12, D22, F`` are constant ``(M, M)`` or time-varying ``(n, M, M)``
    (entry ``k-1`` is used in step ``k``). ``J0`` is the prior information (12).

    Parameters
    ----------
    J0 : array_like (M, M)
        Prior information :math:`J_{0|0}`, (12).
    D11, D12, D22, F : array_like
        Constant ``(M, M)`` or time-varying ``(n_steps, M, M)``.
    n_steps : int
        Number of steps.

    Returns
    -------
    ndarray (n_steps+1, M, M)
        :math:`J_{0|0}, \dots, J_{n|n}`.

    Raises
    ------
    InputError
        If a time-varying argument does not hold ``n_steps`` matrices.
    """
    D11, D12, D22, F = (_seq(x, n_steps) for x in (D11, D12, D22, F))
    out = [_as_mat(J0)]
    for k in range(n_steps):
        out.append(filtering_bim_step(out[-1], D11[k], D12[k], D22[k], F[k]))
    return np.stack(out)


def prediction_bims(J_kk, D11, D12, D22, n_ahead: int):
    r"""Prediction BIMs ``J_{k|k}, J_{k+1|k}, ..., J_{k+n|k}`` by the corrected (14).

    Parameters
    ----------
    J_kk : array_like (M, M)
        Filtering BIM :math:`J_{k|k}`.
    D11, D12, D22 : array_like (M, M)
        Blocks (8)-(10) of the transition (see :func:`linear_gaussian_blocks`).
    n_ahead : int
        Prediction horizon.

    Returns
    -------
    ndarray (n_ahead+1, M, M)
        :math:`J_{k|k}, \dots, J_{k+n|k}`.
    """
    out = [_as_mat(J_kk)]
    for _ in range(n_ahead):
        out.append(prediction_bim_step(out[-1], D11, D12, D22))
    return np.stack(out)


def smoothing_bims(J_filt, D11, D12, D22, F):
    """Smoothing BIMs ``J_{l|K}``, l = 0..K, by the corrected backward recursion (16).

    ``J_filt`` are the filtering BIMs ``(K+1, M, M)`` from :func:`filtering_bims`
    with the same ``D11, D12, D22, F`` (constant or ``(K, M, M)``); the one-step
    prediction BIMs ``J_{l+1|l} = J_{l+1|l+1} - E[F]`` are formed internally.

    Parameters
    ----------
    J_filt : ndarray (K+1, M, M)
        Filtering BIMs.
    D11, D12, D22, F : array_like
        Constant ``(M, M)`` or time-varying ``(K, M, M)``.

    Returns
    -------
    ndarray (K+1, M, M)
        :math:`J_{l|K}`, l = 0..K.
    """
    K = len(J_filt) - 1
    D11, D12, D22, F = (_seq(x, K) for x in (D11, D12, D22, F))
    out = [None] * (K + 1)
    out[K] = J_filt[K]
    for l in range(K - 1, -1, -1):
        J_pred = prediction_bim_step(J_filt[l], D11[l], D12[l], D22[l])
        out[l] = smoothing_bim_step(J_filt[l], out[l + 1], J_pred, D11[l], D12[l], D22[l])
    return np.stack(out)


def smoothing_bims_via_gain(J_filt, D11, D12, D22, F):
    r"""Smoothing BIMs by the compact form (17) with the gain (18)-(19) (corrected).

    Parameters
    ----------
    J_filt : ndarray (K+1, M, M)
        Filtering BIMs.
    D11, D12, D22, F : array_like
        Constant ``(M, M)`` or time-varying ``(K, M, M)``.

    Returns
    -------
    ndarray (K+1, M, M)
        :math:`J_{l|K} = J_{l|l} + \kappa(l|K)`, (17).
    """
    K = len(J_filt) - 1
    D11, D12, D22, F = (_seq(x, K) for x in (D11, D12, D22, F))
    M = J_filt.shape[-1]
    kappa = np.zeros((M, M))
    out = [None] * (K + 1)
    out[K] = J_filt[K]
    for l in range(K - 1, -1, -1):
        kappa = smoothing_gain_step(kappa, D11[l], D12[l], D22[l], F[l])
        out[l] = J_filt[l] + kappa
    return np.stack(out)


def printed_prediction_step(J_prev, D11, D12, D22):
    """The printed (14): D12 (D11 + J)^-1 D21 (transposition slip; errata only).

    Parameters
    ----------
    J_prev : array_like (M, M)
        :math:`J_{l-1|k}`.
    D11, D12, D22 : array_like (M, M)
        Blocks (8)-(10) of the transition (see :func:`linear_gaussian_blocks`).

    Returns
    -------
    ndarray (M, M)
        The printed right-hand side of (14).
    """
    D12 = _as_mat(D12)
    return _as_mat(D22) - D12 @ np.linalg.solve(_as_mat(J_prev) + _as_mat(D11), D12.T)


def printed_smoothing_gain_step(kappa_next, D11, D12, D22, F_next):
    r"""The printed (18): D11 - D21 (D22 + F + kappa)^-1 D12 (transposition slip; errata only).

    Parameters
    ----------
    kappa_next : array_like (M, M)
        :math:`\kappa(l+1|k)`.
    D11, D12, D22 : array_like (M, M)
        Blocks (8)-(10) of the transition (see :func:`linear_gaussian_blocks`).
    F_next : array_like (M, M)
        :math:`E[F(\theta_{l+1})]`.

    Returns
    -------
    ndarray (M, M)
        The printed right-hand side of (18).
    """
    D12 = _as_mat(D12)
    X = _as_mat(D22) + _as_mat(F_next) + _as_mat(kappa_next)
    return _as_mat(D11) - D12.T @ np.linalg.solve(X, D12)


def printed_smoothing_bim_step(J_ll, J_next_smooth, J_next_pred, D11, D12, D22):
    """The printed (16): D21 (...)^-1 D12 (transposition slip; errata only).

    Parameters
    ----------
    J_ll, J_next_smooth, J_next_pred : array_like (M, M)
        As in :func:`smoothing_bim_step`.
    D11, D12, D22 : array_like (M, M)
        Blocks (8)-(10) of the transition (see :func:`linear_gaussian_blocks`).

    Returns
    -------
    ndarray (M, M)
        The printed right-hand side of (16).
    """
    D12 = _as_mat(D12)
    X = _as_mat(D22) + _as_mat(J_next_smooth) - _as_mat(J_next_pred)
    return _as_mat(J_ll) + _as_mat(D11) - D12.T @ np.linalg.solve(X, D12)



def kalman_covariances(A, Q, C, R, P0, K):
    """Kalman filter / RTS covariances (covariance form): P_{k|k}, P_{k+1|k}, P_{k|K}.

    Parameters
    ----------
    A, Q : ndarray (M, M)
        Transition matrix and noise covariance.
    C, R : ndarray
        Measurement matrix ``(m, M)`` and noise covariance ``(m, m)``.
    P0 : ndarray (M, M)
        Prior covariance.
    K : int
        Horizon.

    Returns
    -------
    tuple of ndarray
        ``P_{k|k}`` (K+1, M, M), ``P_{k+1|k}`` (K, M, M), ``P_{k|K}`` (K+1, M, M).
    """
    Pf, Pp = [P0], [None]
    for _ in range(K):
        M = A @ Pf[-1] @ A.T + Q
        S = C @ M @ C.T + R
        G = M @ C.T @ np.linalg.inv(S)
        Pf.append((np.eye(len(A)) - G @ C) @ M)
        Pp.append(M)
    Ps = [None] * (K + 1)
    Ps[K] = Pf[K]
    for k in range(K - 1, -1, -1):
        Gs = Pf[k] @ A.T @ np.linalg.inv(Pp[k + 1])
        Ps[k] = Pf[k] + Gs @ (Ps[k + 1] - Pp[k + 1]) @ Gs.T
    return np.stack(Pf), np.stack(Pp[1:]), np.stack(Ps)


def vector_check(vec):
    """The general recursions (7), (14), (16), (17)-(19), corrected and as printed, against Kalman/RTS.

    For a linear-Gaussian model the BIMs are the inverse Kalman/RTS covariances, so each form is
    compared with :func:`kalman_covariances` (errata E1-E3).

    Parameters
    ----------
    vec : dict
        ``A, Q, C, R, P0`` (nested lists) and ``horizon`` (config ``onebit.vector_check``).

    Returns
    -------
    dict
        ``(quantity, form) -> max relative Frobenius error`` of the inverse BIMs over all steps.
    """
    A, Q, C, R, P0 = (np.asarray(vec[k], dtype=float) for k in ("A", "Q", "C", "R", "P0"))
    K = int(vec["horizon"])
    D11, D12, D22 = linear_gaussian_blocks(A, Q)
    F = C.T @ np.linalg.solve(R, C)
    Pf, Pp, Ps = kalman_covariances(A, Q, C, R, P0, K)
    Jf = filtering_bims(np.linalg.inv(P0), D11, D12, D22, F, K)
    inv = np.linalg.inv

    def err(J, P):
        return float(max(np.linalg.norm(inv(j) - p) / np.linalg.norm(p) for j, p in zip(J, P)))

    Jp = np.stack([prediction_bim_step(Jf[k], D11, D12, D22) for k in range(K)])
    Jp_pr = np.stack([printed_prediction_step(Jf[k], D11, D12, D22) for k in range(K)])
    Js16 = smoothing_bims(Jf, D11, D12, D22, F)
    Js18 = smoothing_bims_via_gain(Jf, D11, D12, D22, F)
    # printed forms, each used consistently in its own recursion
    Js16_pr = [None] * (K + 1)
    Js16_pr[K] = Jf[K]
    Js18_pr = [None] * (K + 1)
    Js18_pr[K] = Jf[K]
    kap = np.zeros_like(F)
    for l in range(K - 1, -1, -1):
        Js16_pr[l] = printed_smoothing_bim_step(Jf[l], Js16_pr[l + 1], Jp[l], D11, D12, D22)
        kap = printed_smoothing_gain_step(kap, D11, D12, D22, F)
        Js18_pr[l] = Jf[l] + kap
    return {
        ("filtering", "(7) as printed"): err(Jf, Pf),
        ("prediction", "(14) corrected"): err(Jp, Pp),
        ("prediction", "(14) as printed"): err(Jp_pr, Pp),
        ("smoothing", "(16) corrected"): err(Js16, Ps),
        ("smoothing", "(16) as printed"): err(Js16_pr, Ps),
        ("smoothing", "(17)-(19) corrected"): err(Js18, Ps),
        ("smoothing", "(17)-(19) as printed"): err(Js18_pr, Ps),
    }


def prior_check(P0):
    """(12) for theta_0 ~ N(0, P0): score g = -P0^{-1} theta_0, so E[g g^T] = P0^{-1} Cov(theta_0) P0^{-1} exactly.

    Parameters
    ----------
    P0 : ndarray (M, M)
        Prior covariance.

    Returns
    -------
    tuple of float
        Relative error of ``inv(J_{0|0})`` against ``P0`` with (12) read elementwise (the square of
        each score component) and as the outer product.
    """
    Pi = np.linalg.inv(P0)
    outer = Pi @ P0 @ Pi
    elem = np.diag(np.diag(outer))  # "squared" read elementwise: only the diagonal survives
    rel = lambda J: float(np.linalg.norm(np.linalg.inv(J) - P0) / np.linalg.norm(P0))  # noqa: E731
    return rel(elem), rel(outer)

