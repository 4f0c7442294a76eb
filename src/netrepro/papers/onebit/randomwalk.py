"""The scalar random walk (21) with unquantized (20) or 1-bit (28) measurements.

Filtering (24)/(34), prediction (25)/(35) and smoothing-gain (27)/(37)-(38) recursions in
information-stable form, their steady-state fixed points (39)-(46), the smoothing lag, the
information ratios (47)-(49) of Figs 1-2 and their alpha -> 1 limit, the transient from the
prior (31)-(34), and the time-varying bounds over a finite horizon.
"""

from __future__ import annotations

import math

import numpy as np

from ...errors import InputError, ModelError
from .fisher import expected_fisher_1bit, expected_fisher_interpolator
from .model import kalman_covariances, sigma_z2_from_snr, stationary_variance, theta_variance

__all__ = [
    "rw_filtering_step",
    "rw_prediction_step",
    "rw_smoothing_gain_step",
    "rw_filtering_fixed_point",
    "rw_smoothing_gain_fixed_point",
    "rw_lag_needed",
    "rw_lag_iterated",
    "information_ratios",
    "information_ratios_limit",
    "iterate_transient",
    "window_bounds",
    "rw_scalar_check",
    "variance_sum_check",
]


def _db(x):
    return 10.0 * np.log10(x)


# ============================================================================ scalar random walk
def rw_filtering_step(J_prev, F, eps: float, sigma_z2):
    r"""Filtering BIM of the random walk, eqs. (24) / (34), in information-stable form.

    .. math::

        J_{k|k} = \frac{1}{\sigma_z^2} + F - \Big(\frac{\alpha}{\sigma_z^2}\Big)^2
        \Big(J_{k-1|k-1} + \frac{\alpha^2}{\sigma_z^2}\Big)^{-1}
        = \Big(\frac{\alpha^2}{J_{k-1|k-1}} + \sigma_z^2\Big)^{-1} + F

    (matrix inversion lemma; the right form avoids cancelling terms of size
    ``1/sigma_z^2`` when alpha -> 1). ``F`` is ``1/sigma_eta^2`` for (24) and
    ``E[F_q]`` for (34). Vectorised over all arguments.

    Parameters
    ----------
    J_prev : float or ndarray
        :math:`J_{k-1|k-1}`.
    F : float or ndarray
        Information per measurement: ``1/sigma_eta^2`` (unquantized) or :math:`E[F_q]` (1-bit).
    eps : float
        ``1 - alpha`` of the random walk (21).
    sigma_z2 : float or ndarray
        Transition noise variance :math:`\sigma_z^2`.

    Returns
    -------
    ndarray
        :math:`J_{k|k}`.
    """
    a2 = (1.0 - eps) ** 2
    return 1.0 / (a2 / J_prev + sigma_z2) + F


def rw_prediction_step(J_prev, eps: float, sigma_z2):
    r"""Prediction BIM of the random walk, eqs. (25) / (35): :math:`(\alpha^2/J_{l-1|k} + \sigma_z^2)^{-1}`.

    Parameters
    ----------
    J_prev : float or ndarray
        :math:`J_{l-1|k}`.
    eps : float
        ``1 - alpha`` of the random walk (21).
    sigma_z2 : float or ndarray
        Transition noise variance :math:`\sigma_z^2`.

    Returns
    -------
    ndarray
        :math:`J_{l|k}`.
    """
    return 1.0 / ((1.0 - eps) ** 2 / J_prev + sigma_z2)


def rw_smoothing_gain_step(kappa_next, F_next, eps: float, sigma_z2):
    r"""Smoothing gain of the random walk, eqs. (27) / (37)-(38), in stable form.

    .. math::

        \kappa(l|k) = \frac{\alpha^2}{\sigma_z^2} - \Big(\frac{\alpha}{\sigma_z^2}\Big)^2
        \Big(\frac{1}{\sigma_z^2} + F + \kappa(l+1|k)\Big)^{-1}
        = \frac{\alpha^2 I}{1 + \sigma_z^2 I},\quad I = F + \kappa(l+1|k),

    where in (38) the bracket reads :math:`1/\sigma_z^2 + E[F_q] - J_{l+1|l+1,q} + J_{l+1|k,q}`,
    the same number since :math:`J_{l+1|k,q} - J_{l+1|l+1,q} = \kappa_q(l+1|k)` by (36).

    Parameters
    ----------
    kappa_next : float or ndarray
        :math:`\kappa(l+1|k)`.
    F_next : float or ndarray
        Information per measurement at step l+1.
    eps : float
        ``1 - alpha`` of the random walk (21).
    sigma_z2 : float or ndarray
        Transition noise variance :math:`\sigma_z^2`.

    Returns
    -------
    ndarray
        :math:`\kappa(l|k)`.
    """
    info = F_next + kappa_next
    return (1.0 - eps) ** 2 * info / (1.0 + sigma_z2 * info)


def rw_filtering_fixed_point(F, eps: float, sigma_z2):
    r"""Steady-state filtering BIM (41)/(42): the positive fixed point of (24)/(34).

    With the predicted variance :math:`M = \alpha^2/J + \sigma_z^2` the fixed
    point solves :math:`F M^2 + (1 - \alpha^2 - \sigma_z^2 F) M - \sigma_z^2 = 0`,
    :math:`J = 1/M + F`; the root is taken in the cancellation-free form.

    Parameters
    ----------
    F : float or ndarray
        Information per measurement: ``1/sigma_eta^2`` (unquantized) or :math:`E[F_q]` (1-bit).
    eps : float
        ``1 - alpha`` of the random walk (21).
    sigma_z2 : float or ndarray
        Transition noise variance :math:`\sigma_z^2`.

    Returns
    -------
    ndarray
        Steady-state :math:`\tilde J_{k|k}`.
    """
    F = np.asarray(F, dtype=float)
    s = np.asarray(sigma_z2, dtype=float)
    b = eps * (2.0 - eps) - s * F
    root = np.sqrt(b * b + 4.0 * F * s)
    with np.errstate(divide="ignore", invalid="ignore"):
        M = np.where(b >= 0, 2.0 * s / (b + root), (root - b) / (2.0 * F))
    return 1.0 / M + F


def rw_smoothing_gain_fixed_point(F, eps: float, sigma_z2):
    r"""Steady-state smoothing gain :math:`\kappa_\infty` (Delta -> infinity) of (27)/(38).

    The positive root of :math:`\sigma_z^2\kappa^2 + (1 - \alpha^2 + \sigma_z^2F)\kappa - \alpha^2F = 0`;
    the asymptotic smoothing BIM (45)/(46) is :math:`\tilde J_{k|k} + \kappa_\infty`.

    Parameters
    ----------
    F : float or ndarray
        Information per measurement: ``1/sigma_eta^2`` (unquantized) or :math:`E[F_q]` (1-bit).
    eps : float
        ``1 - alpha`` of the random walk (21).
    sigma_z2 : float or ndarray
        Transition noise variance :math:`\sigma_z^2`.

    Returns
    -------
    ndarray
        :math:`\kappa_\infty`.
    """
    F = np.asarray(F, dtype=float)
    s = np.asarray(sigma_z2, dtype=float)
    a2 = (1.0 - eps) ** 2
    b = eps * (2.0 - eps) + s * F
    return 2.0 * a2 * F / (b + np.sqrt(b * b + 4.0 * s * a2 * F))


def rw_lag_needed(F, eps: float, sigma_z2, tol_db: float):
    r"""Smallest lag Delta with :math:`10\log_{10}(J_{s,\infty}/J_{k|k+\Delta}) \le` ``tol_db`` (steady state).

    :math:`J_{k|k+\Delta} = \tilde J_{k|k} + \kappa_\Delta`, where :math:`\kappa_\Delta`
    is Delta steps of (27)/(38) from :math:`\kappa = 0`. That map is a Moebius
    transformation :math:`T(x) = (\alpha^2 x + \alpha^2F)/(\sigma_z^2 x + 1 + \sigma_z^2 F)` with fixed points
    :math:`x_+ = \kappa_\infty > 0 > x_-`, so
    :math:`(\kappa_n - x_+)/(\kappa_n - x_-) = K^n\, x_+/x_-` with
    :math:`K = (\alpha^2 - \sigma_z^2 x_+)/(1 + \sigma_z^2(F + x_+))`, solved for ``n``.

    Parameters
    ----------
    F : float or ndarray
        Information per measurement: ``1/sigma_eta^2`` (unquantized) or :math:`E[F_q]` (1-bit).
    eps : float
        ``1 - alpha`` of the random walk (21).
    sigma_z2 : float or ndarray
        Transition noise variance :math:`\sigma_z^2`.
    tol_db : float
        Tolerance in dB.

    Returns
    -------
    ndarray of int64
        The smallest lag Delta (0 if the filter is already within ``tol_db``).
    """
    F, s = np.broadcast_arrays(np.asarray(F, dtype=float), np.asarray(sigma_z2, dtype=float))
    Jf = rw_filtering_fixed_point(F, eps, s)
    xp = rw_smoothing_gain_fixed_point(F, eps, s)
    a2 = (1.0 - eps) ** 2
    xm = -a2 * F / (s * xp)
    target = (Jf + xp) * 10.0 ** (-tol_db / 10.0) - Jf
    w0 = xp / xm
    with np.errstate(divide="ignore", invalid="ignore"):
        wt = (target - xp) / (target - xm)
        logK = np.log1p(-eps * (2.0 - eps) - s * xp) - np.log1p(s * (F + xp))
        n = np.ceil(np.log(wt / w0) / logK - 1e-9)
    return np.where(target <= 0, 0, n).astype(np.int64)


def rw_lag_iterated(F, eps: float, sigma_z2, tol_db: float, max_steps: int = 10_000_000):
    r"""The same lag as :func:`rw_lag_needed`, by iterating (27)/(38) (vectorised over the grid).

    Parameters
    ----------
    F : float or ndarray
        Information per measurement: ``1/sigma_eta^2`` (unquantized) or :math:`E[F_q]` (1-bit).
    eps : float
        ``1 - alpha`` of the random walk (21).
    sigma_z2 : float or ndarray
        Transition noise variance :math:`\sigma_z^2`.
    tol_db : float
        Tolerance in dB.
    max_steps : int
        Iteration limit.

    Returns
    -------
    ndarray of int64
        The smallest lag Delta.

    Raises
    ------
    ModelError
        If the lag is not reached within ``max_steps``.
    """
    F, s = np.broadcast_arrays(np.asarray(F, dtype=float), np.asarray(sigma_z2, dtype=float))
    Jf = rw_filtering_fixed_point(F, eps, s)
    target = (Jf + rw_smoothing_gain_fixed_point(F, eps, s)) * 10.0 ** (-tol_db / 10.0)
    kappa = np.zeros_like(F)
    lag = np.where(Jf >= target, 0, -1).astype(np.int64)
    n = 0
    while np.any(lag < 0):
        n += 1
        if n > max_steps:
            raise ModelError(f"rw_lag_iterated: no convergence within {max_steps} steps")
        kappa = rw_smoothing_gain_step(kappa, F, eps, s)
        lag = np.where((lag < 0) & (Jf + kappa >= target), n, lag)
    return lag


# ============================================================================ ratios (47)-(49)
def information_ratios(snr_db, eps: float, sigma_eta: float = 1.0, definition: str = "stationary",
                       efq=None) -> dict:
    r"""Steady-state BIMs and the ratios (47)-(49) for ``alpha = 1 - eps`` on an SNR grid.

    .. math::

        \rho_{SL} = \tilde J_{k|k+\Delta,q}/\tilde J_{k|k+\Delta,\infty},\quad
        \rho_F = \tilde J_{k|k,q}/\tilde J_{k|k,\infty},\quad
        \rho_S = \tilde J_{k|k+\Delta,q}/\tilde J_{k|k,\infty}.

    :math:`E[F_q]` is taken under the stationary law of :math:`\theta_k`
    (mean 0 by (31), variance (33)); the unquantized information is (23).

    Parameters
    ----------
    snr_db : array_like
        SNR grid in dB.
    eps : float
        ``1 - alpha`` of the random walk (21).
    sigma_eta : float
        Noise standard deviation.
    definition : {'stationary', 'innovation'}
        SNR convention.
    efq : array_like, optional
        Precomputed :math:`\sigma_\eta^2E[F_q]` on the grid.

    Returns
    -------
    dict of ndarray
        ``sigma_z2, var_ratio, efq, j_f_inf, j_f_q, j_s_inf, j_s_q, rho_sl_db, rho_f_db, rho_s_db``.
    """
    snr_db = np.asarray(snr_db, dtype=float)
    s = sigma_z2_from_snr(snr_db, eps, sigma_eta, definition)
    var_ratio = stationary_variance(eps, s) / sigma_eta**2
    e = expected_fisher_1bit(var_ratio) if efq is None else np.asarray(efq, dtype=float)
    Fq, Fi = e / sigma_eta**2, np.full_like(s, 1.0 / sigma_eta**2)
    jfi, jfq = rw_filtering_fixed_point(Fi, eps, s), rw_filtering_fixed_point(Fq, eps, s)
    jsi = jfi + rw_smoothing_gain_fixed_point(Fi, eps, s)
    jsq = jfq + rw_smoothing_gain_fixed_point(Fq, eps, s)
    return dict(sigma_z2=s, var_ratio=var_ratio, efq=e, j_f_inf=jfi, j_f_q=jfq, j_s_inf=jsi, j_s_q=jsq,
                rho_sl_db=_db(jsq / jsi), rho_f_db=_db(jfq / jfi), rho_s_db=_db(jsq / jfi))


def information_ratios_limit(snr_db) -> dict:
    r"""The alpha -> 1 limit of (47)-(49) at fixed stationary SNR.

    With :math:`\sigma_z^2 = \mathrm{SNR}\,\sigma_\eta^2(1-\alpha^2) \to 0`,
    :math:`\tilde J_{k|k} = \sqrt{F/\sigma_z^2}\,(1 + O(\sqrt{F\sigma_z^2}) + O((1-\alpha)/\sqrt{F\sigma_z^2}))`
    and :math:`\kappa_\infty/\tilde J_{k|k} \to 1`, hence

    .. math::

        \rho_F = \rho_{SL} = \sqrt{\sigma_\eta^2 E[F_q]},\qquad \rho_S = 2\sqrt{\sigma_\eta^2 E[F_q]} ,

    i.e. :math:`\sqrt{2/\pi}` (-0.98 dB) and :math:`2\sqrt{2/\pi}` (+2.03 dB) at low SNR.

    Parameters
    ----------
    snr_db : array_like
        Stationary SNR grid in dB.

    Returns
    -------
    dict of ndarray
        ``efq, rho_sl_db, rho_f_db, rho_s_db``.
    """
    snr_db = np.asarray(snr_db, dtype=float)
    e = expected_fisher_1bit(10.0 ** (snr_db / 10.0))
    half = 0.5 * _db(e)
    return dict(efq=e, rho_sl_db=half, rho_f_db=half.copy(), rho_s_db=half + _db(2.0))


# ============================================================================ transients (31)-(34)
def iterate_transient(snr_db, eps: float, sigma0: float, mu0: float, sigma_eta: float, n_steps: int,
                      rtol: float, record=None, definition: str = "stationary", chunk: int = 100_000) -> dict:
    r"""Long iteration of the filtering BIMs (24) and (34) from the prior (12).

    :math:`J_{0|0} = 1/\sigma_0^2`; step ``k`` uses :math:`E[F_q(\theta_k)]` under
    :math:`N(\alpha^k\mu_0, \mathrm{Var}[\theta_k])`, (31)-(32) corrected. The
    expectation comes from :func:`expected_fisher_interpolator` (mean 0 only,
    so ``mu0`` must be 0 here). Vectorised over the SNR grid, sequential in k.

    Parameters
    ----------
    snr_db : array_like
        SNR grid in dB.
    eps : float
        ``1 - alpha`` of the random walk (21).
    sigma0, mu0 : float
        Prior standard deviation and mean (``mu0`` must be 0).
    sigma_eta : float
        Noise standard deviation.
    n_steps : int
        Steps iterated.
    rtol : float
        Relative distance to the fixed point counted as converged.
    record : sequence of int, optional
        Steps recorded in ``trace``.
    definition : str
        SNR convention.
    chunk : int
        Steps per vectorised chunk.

    Returns
    -------
    dict
        ``j_f_q, j_f_inf`` (final iterates), ``k_conv_q, k_conv_inf, k_conv_var``
        (last step outside ``rtol`` of the fixed point, + 1), and if ``record``
        (sorted step indices) is given, ``trace`` with arrays ``(len(record), n_snr)``
        for ``var_ratio, efq_ratio, j_f_q_ratio, j_f_inf_ratio``.

    Raises
    ------
    InputError
        If ``mu0`` is not 0.
    """
    if mu0 != 0.0:
        raise InputError("iterate_transient: the interpolated (29) assumes mu0 = 0")
    from ...engines.kernels import scalar_information_steps  # numba: only the steps that iterate
    snr_db = np.atleast_1d(np.asarray(snr_db, dtype=float))
    s = sigma_z2_from_snr(snr_db, eps, sigma_eta, definition)
    var_inf = stationary_variance(eps, s)
    efq_fn = expected_fisher_interpolator()
    e_inf = expected_fisher_1bit(var_inf / sigma_eta**2)
    Fq_inf, Fi = e_inf / sigma_eta**2, 1.0 / sigma_eta**2
    jq_star, ji_star = rw_filtering_fixed_point(Fq_inf, eps, s), rw_filtering_fixed_point(Fi, eps, s)
    n = len(s)
    j = np.full(2 * n, 1.0 / sigma0**2)            # lanes: [1-bit (34) | unquantized (24)]
    j_star = np.concatenate([jq_star, np.broadcast_to(ji_star, (n,))])
    s2 = np.concatenate([s, s])
    a2 = (1.0 - eps) ** 2
    last = np.zeros(2 * n, dtype=np.int64)
    record = [] if record is None else sorted(int(r) for r in record)
    rec = np.asarray(record, dtype=np.int64)
    trace = {key: np.full((len(record), n), np.nan) for key in ("var_ratio", "efq_ratio", "j_f_q_ratio",
                                                                "j_f_inf_ratio")}

    def _record(ks, var, Fq, J):
        sel = np.isin(ks, rec)
        idx = np.searchsorted(rec, ks[sel])
        trace["var_ratio"][idx] = var[sel] / var_inf
        trace["efq_ratio"][idx] = Fq[sel] * sigma_eta**2 / e_inf
        trace["j_f_q_ratio"][idx] = J[sel, :n] / jq_star
        trace["j_f_inf_ratio"][idx] = J[sel, n:] / ji_star

    v0 = np.full((1, n), sigma0**2)
    _record(np.array([0]), v0, efq_fn(v0 / sigma_eta**2) / sigma_eta**2, j[None, :])
    for start in range(1, n_steps + 1, chunk):
        ks = np.arange(start, min(start + chunk, n_steps + 1))
        var = theta_variance(ks[:, None], eps, sigma0, s[None, :])
        Fq = efq_fn(var / sigma_eta**2) / sigma_eta**2
        F2 = np.concatenate([Fq, np.full_like(Fq, Fi)], axis=1)
        J = np.empty_like(F2)
        scalar_information_steps(j, a2, s2, F2, J)
        outside = np.abs(J / j_star - 1.0) > rtol
        any_out = outside.any(axis=0)
        last_in_chunk = len(ks) - 1 - np.argmax(outside[::-1], axis=0)
        last = np.where(any_out, ks[last_in_chunk], last)
        if len(rec):
            _record(ks, var, Fq, J)
    jq, ji, last_q, last_i = j[:n], j[n:], last[:n], last[n:]
    # variance: closed form of the last k with |Var_k / var_inf - 1| > rtol
    gap = np.abs(sigma0**2 - var_inf) / var_inf
    with np.errstate(divide="ignore"):
        k_var = np.where(gap > rtol, np.floor(np.log(rtol / gap) / (2.0 * math.log1p(-eps))) + 1, 0)
    return dict(snr_db=snr_db, sigma_z2=s, j_f_q=jq, j_f_inf=ji, j_f_q_star=jq_star, j_f_inf_star=ji_star,
                k_conv_q=last_q + 1, k_conv_inf=last_i + 1, k_conv_var=k_var.astype(np.int64),
                var_final=theta_variance(n_steps, eps, sigma0, s), var_inf=var_inf, trace=trace, record=record)


def window_bounds(F, eps, s, sigma0_2, horizon, window):
    """Average over the window of 1/J_{k|k} and 1/J_{k|K} (time-varying, exact horizon).

    Parameters
    ----------
    F : float or ndarray
        Information per measurement: ``1/sigma_eta^2`` (unquantized) or :math:`E[F_q]` (1-bit).
    eps : float
        ``1 - alpha`` of the random walk (21).
    s : float
        Transition noise variance.
    sigma0_2 : float
        Prior variance.
    horizon : int
        Last step K.
    window : tuple of int
        ``(start, stop)`` of the averaging window.

    Returns
    -------
    tuple of float
        Window means of the filtering bound :math:`1/J_{k|k}` ((24)/(34)) and the smoothing bound :math:`1/J_{k|K}` ((26)-(27)/(36)-(38)).
    """
    J = np.empty(horizon + 1)
    J[0] = 1.0 / sigma0_2
    for k in range(1, horizon + 1):
        J[k] = rw_filtering_step(J[k - 1], F, eps, s)
    kap = np.zeros(horizon + 1)
    for l in range(horizon - 1, -1, -1):
        kap[l] = rw_smoothing_gain_step(kap[l + 1], F, eps, s)
    w = slice(window[0], window[1])
    return float(np.mean(1.0 / J[w])), float(np.mean(1.0 / (J + kap)[w]))


def rw_scalar_check(eps, s, F, K):
    """Smoothing variances of the scalar random walk with information F per step, three ways, vs RTS.

    Returns the max relative error of ``1/J_{l|K}`` against the RTS smoother with noise variance ``1/F``
    (the BIM recursions are exactly the Kalman/RTS recursions in information form) for
    (26)-(27) verbatim, (36)-(38) read as one equation, and (36)-(37) with (37) read on its own.

    Parameters
    ----------
    eps : float
        ``1 - alpha`` of the random walk (21).
    s : float
        Transition noise variance.
    F : float
        Information per measurement.
    K : int
        Horizon.

    Returns
    -------
    tuple of float
        Max relative errors for (27), (36)-(38) as one equation, and (37) read alone.
    """
    a = 1.0 - eps
    J = np.empty(K + 1)
    J[0] = 1.0
    for k in range(1, K + 1):
        J[k] = 1 / s + F - (a / s) ** 2 / (J[k - 1] + a * a / s)        # (24)/(34) verbatim
    k27 = np.zeros(K + 1)
    J38 = np.empty(K + 1)
    J38[K] = J[K]
    k37_literal = np.zeros(K + 1)
    for l in range(K - 1, -1, -1):
        k27[l] = a * a / s - (a / s) ** 2 / (1 / s + F + k27[l + 1])     # (27) verbatim
        J38[l] = J[l] + a * a / s - (a / s) ** 2 / (1 / s + F - J[l + 1] + J38[l + 1])  # (36)-(38), one equation
        k37_literal[l] = a * a / s - (a / s) ** 2                          # (37) read on its own
    _, _, Ps = kalman_covariances(np.array([[a]]), np.array([[s]]), np.array([[1.0]]), np.array([[1.0 / F]]),
                                 np.array([[1.0]]), K)
    Ps = Ps[:, 0, 0]

    def rel(J_):
        return float(np.max(np.abs(1 / J_ - Ps) / Ps))

    return rel(J + k27), rel(J38), rel(J + k37_literal)



def variance_sum_check(eps: float, sigma_z2: float, sigma0: float, n_steps: int = 200):
    r"""The printed and the corrected eq. (32) against the exact recursion (erratum E4).

    The exact variance obeys :math:`\mathrm{Var}_k = \alpha^2\mathrm{Var}_{k-1} + \sigma_z^2`; the
    printed (32) sums :math:`\alpha^{2(k-i)}\sigma_z^2` over ``i = 1..k-1`` (it misses
    :math:`z_k`), the corrected one (:func:`~netrepro.papers.onebit.model.theta_variance`) over
    ``i = 1..k``.

    Parameters
    ----------
    eps : float
        ``1 - alpha``.
    sigma_z2 : float
        Transition noise variance.
    sigma0 : float
        Prior standard deviation of :math:`\theta_0`.
    n_steps : int
        Steps ``k = 1..n_steps`` compared.

    Returns
    -------
    tuple of float
        Max relative error over k of the printed and of the corrected (32).
    """
    ks = np.arange(1, n_steps + 1)
    rec = np.empty(len(ks) + 1)
    rec[0] = sigma0**2
    for i in range(len(ks)):
        rec[i + 1] = (1 - eps) ** 2 * rec[i] + sigma_z2
    a = 1 - eps
    printed = np.array([a ** (2 * k) * sigma0**2 + sum(a ** (2 * (k - i)) for i in range(1, k)) * sigma_z2 for k in ks])
    corrected = theta_variance(ks, eps, sigma0, sigma_z2)
    return float(np.max(np.abs(printed / rec[1:] - 1))), float(np.max(np.abs(corrected / rec[1:] - 1)))
