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
from .model import axis_shift_db, kalman_covariances, sigma_z2_from_snr, stationary_variance, theta_variance

__all__ = [
    "rw_filtering_step",
    "rw_prediction_step",
    "rw_smoothing_gain_step",
    "rw_smoothing_gain_iterated",
    "rw_filtering_fixed_point",
    "rw_smoothing_gain_fixed_point",
    "rw_lag_needed",
    "rw_lag_iterated",
    "information_ratios",
    "information_ratios_limit",
    "iterate_transient",
    "rw_scalar_check",
    "variance_sum_check",
    "rw_filter_time_constant",
    "bound_paths",
    "estimator_design",
    "rw_break_even_lag",
    "rw_break_even_iterated",
    "rho_s_threshold_eps",
    "rho_s_zero_crossing",
    "ratios_at",
    "snr_shift_deviation",
    "ratio_window",
    "ratios_without_mean_reversion",
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


def rw_smoothing_gain_iterated(F, eps: float, sigma_z2, kappa_star, n_steps: int, rtol: float):
    r"""``n_steps`` steps of the smoothing gain (27)/(37)-(38) from :math:`\kappa = 0`, with the convergence step.

    Iterates :func:`rw_smoothing_gain_step` with constant ``F`` (one lane per element) and records the
    last step ``d`` at which :math:`|\kappa_d/\kappa^* - 1| >` ``rtol``. Compiled (a numpy loop over
    ~1e5 steps of a few lanes is all interpreter overhead); bit-identical to
    :func:`_rw_smoothing_gain_iterated_numpy` (same operations in the same order).

    Parameters
    ----------
    F, sigma_z2, kappa_star : ndarray (lanes,)
        Information per measurement, transition noise variance and the fixed point
        (:func:`rw_smoothing_gain_fixed_point`).
    eps : float
        ``1 - alpha``.
    n_steps : int
        Steps iterated.
    rtol : float
        Relative distance to the fixed point counted as converged.

    Returns
    -------
    kappa : ndarray (lanes,)
        :math:`\kappa` after ``n_steps`` steps.
    last : ndarray of int64 (lanes,)
        Last step outside ``rtol`` (0: none).
    """
    from .kernels import smoothing_gain_iterations  # numba: only the step that iterates

    F, s, ks = (np.ascontiguousarray(np.broadcast_to(np.asarray(a, dtype=float), np.shape(F))) for a in
                (F, sigma_z2, kappa_star))
    kappa = np.zeros_like(F)
    last = np.zeros(len(F), dtype=np.int64)
    smoothing_gain_iterations(F, s, (1.0 - eps) ** 2, ks, float(rtol), int(n_steps), kappa, last)
    return kappa, last


def _rw_smoothing_gain_iterated_numpy(F, eps: float, sigma_z2, kappa_star, n_steps: int, rtol: float):
    """:func:`rw_smoothing_gain_iterated` as a numpy loop over the steps (the reference)."""
    kappa = np.zeros_like(np.asarray(F, dtype=float))
    last = np.zeros(len(kappa), dtype=np.int64)
    for d in range(1, n_steps + 1):
        kappa = rw_smoothing_gain_step(kappa, F, eps, sigma_z2)
        last[np.abs(kappa / kappa_star - 1) > rtol] = d
    return kappa, last


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


# ============================================================================ beyond the paper (issue 17)
def rw_filter_time_constant(F, eps: float, sigma_z2):
    r"""Time constant of the steady-state filter: :math:`\tau = -1/\ln\lambda`, :math:`\lambda = \alpha/(1 + MF)`.

    With the steady-state predicted variance :math:`M = 1/(\tilde J_{k|k} - F)` of (41)/(42), the
    filter's error obeys :math:`e_k = \lambda e_{k-1} + \dots` with the pole
    :math:`\lambda = \alpha(1 - G)`, :math:`G = MF/(1 + MF)`; the RTS smoother's backward gain
    :math:`\tilde P_{k|k}\alpha/M` is the same number, so :math:`\tau` also sets how far from the
    end of the record the smoother is in steady state. For 1-bit data ``F`` is :math:`E[F_q]`
    (the linearised information filter).

    Parameters
    ----------
    F : float or ndarray
        Information per measurement.
    eps : float
        ``1 - alpha``.
    sigma_z2 : float or ndarray
        Transition noise variance.

    Returns
    -------
    ndarray
        :math:`\tau` in steps.
    """
    F = np.asarray(F, dtype=float)
    J = rw_filtering_fixed_point(F, eps, sigma_z2)
    M = 1.0 / (J - F)
    return -1.0 / (math.log1p(-eps) - np.log1p(M * F))


def bound_paths(F, eps: float, sigma_z2: float, sigma0_2: float, horizon: int):
    r"""Filtering and smoothing BIMs over a finite record, (24)/(34) forward and (26)-(27)/(36)-(38) backward.

    Parameters
    ----------
    F : float
        Information per measurement (constant: stationary start).
    eps : float
        ``1 - alpha``.
    sigma_z2 : float
        Transition noise variance.
    sigma0_2 : float
        Prior variance, :math:`J_{0|0} = 1/\sigma_0^2`, (12).
    horizon : int
        Last step K.

    Returns
    -------
    J_f, J_s : ndarray (K+1,)
        :math:`J_{k|k}` and :math:`J_{k|K}`, k = 0..K.
    """
    J = np.empty(horizon + 1)
    J[0] = 1.0 / sigma0_2
    for k in range(1, horizon + 1):
        J[k] = rw_filtering_step(J[k - 1], F, eps, sigma_z2)
    kap = np.zeros(horizon + 1)
    for l in range(horizon - 1, -1, -1):
        kap[l] = rw_smoothing_gain_step(kap[l + 1], F, eps, sigma_z2)
    return J, J + kap


def estimator_design(F_list, eps: float, sigma_z2: float, burn_in_taus: float, window_taus: float,
                     tail_taus: float, evals_per_tau: float) -> dict:
    r"""Record length and evaluation window of a Monte Carlo run in steady state.

    :math:`\tau` is the largest :func:`rw_filter_time_constant` over ``F_list`` (the slowest of the
    compared filters). The window starts after ``burn_in_taus`` time constants (the filter has
    forgotten its prior to :math:`e^{-\text{burn\_in}}`), lasts ``window_taus`` of them, and the
    record continues ``tail_taus`` of them after the window (the smoother has forgotten the end of
    the record). Estimates are evaluated every ``stride`` steps inside the window.

    Parameters
    ----------
    F_list : sequence of float
        Information per measurement of each filter compared.
    eps : float
        ``1 - alpha``.
    sigma_z2 : float
        Transition noise variance.
    burn_in_taus, window_taus, tail_taus : float
        Lengths in time constants.
    evals_per_tau : float
        Evaluation steps per time constant.

    Returns
    -------
    dict
        ``tau`` (float), ``start``, ``stop`` (window ``start <= k < stop``), ``horizon`` (K),
        ``stride`` (ints) and ``eval_idx`` (ndarray).
    """
    tau = float(max(float(rw_filter_time_constant(F, eps, sigma_z2)) for F in F_list))
    start = int(math.ceil(burn_in_taus * tau))
    stop = start + int(math.ceil(window_taus * tau))
    horizon = stop + int(math.ceil(tail_taus * tau))
    stride = max(1, int(math.floor(tau / evals_per_tau)))
    return dict(tau=tau, start=start, stop=stop, horizon=horizon, stride=stride,
                eval_idx=np.arange(start, stop, stride))


def rw_break_even_lag(Fq, Finf, eps: float, sigma_z2):
    r"""Smallest lag Delta with :math:`J_{k|k+\Delta,q} > \tilde J_{k|k,\infty}` in steady state (-1: never).

    :math:`J_{k|k+\Delta,q} = \tilde J_{k|k,q} + \kappa_\Delta` with :math:`\kappa_\Delta` the
    Delta-th iterate of (37)-(38) from :math:`\kappa_0 = 0`, increasing to :math:`\kappa_\infty`
    (:func:`rw_smoothing_gain_fixed_point`). The lag exists iff
    :math:`\tilde J_{k|k,q} + \kappa_\infty > \tilde J_{k|k,\infty}`, i.e. iff :math:`\rho_S > 1`, (49).
    The iteration is the Moebius map of :func:`rw_lag_needed`, so
    :math:`w_n = (\kappa_n - x_+)/(\kappa_n - x_-) = w_0 K^n`; with the target
    :math:`t = \tilde J_{k|k,\infty} - \tilde J_{k|k,q}`, the answer is the smallest ``n`` with
    :math:`w_0K^n < w(t)` (``w`` decreasing in ``|.|``), checked and corrected by one step of the map
    on each side against rounding.

    Parameters
    ----------
    Fq : float or ndarray
        :math:`E[F_q]` (1-bit information per measurement).
    Finf : float or ndarray
        ``1/sigma_eta^2`` (unquantized information per measurement).
    eps : float
        ``1 - alpha``.
    sigma_z2 : float or ndarray
        Transition noise variance.

    Returns
    -------
    ndarray of int64
        Delta, or -1 where the 1-bit smoother never reaches the unquantized filter.
    """
    Fq, Finf, s = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in (Fq, Finf, sigma_z2)))
    Jq = rw_filtering_fixed_point(Fq, eps, s)
    Ji = rw_filtering_fixed_point(Finf, eps, s)
    xp = rw_smoothing_gain_fixed_point(Fq, eps, s)
    a2 = (1.0 - eps) ** 2
    xm = -a2 * Fq / (s * xp)
    target = Ji - Jq
    ok = Jq + xp > Ji
    with np.errstate(divide="ignore", invalid="ignore"):
        w0 = xp / xm
        wt = (target - xp) / (target - xm)
        logK = np.log1p(-eps * (2.0 - eps) - s * xp) - np.log1p(s * (Fq + xp))
        n = np.where(ok, np.floor(np.log(wt / w0) / logK) + 1, -1)
    n = np.where(ok, np.maximum(n, 1), -1).astype(np.int64)
    # guard against rounding: kappa_n > target and kappa_{n-1} <= target, by the recursion itself
    for i in np.flatnonzero(ok.ravel()):
        idx = np.unravel_index(i, n.shape)
        n[idx] = _break_even_fix(int(n[idx]), float(Fq[idx]), eps, float(s[idx]), float(target[idx]))
    return n


def _break_even_fix(n: int, F: float, eps: float, s: float, target: float) -> int:
    """Move ``n`` by at most a few steps so that kappa_n > target >= kappa_{n-1} (exact by iteration near n)."""
    def kappa(m):  # closed form of the m-th iterate would round the same way; iterate from a nearby start
        k = 0.0
        for _ in range(m):
            k = rw_smoothing_gain_step(k, F, eps, s)
        return k

    if n > 200_000:  # too long to iterate: trust the closed form
        return n
    while n > 1 and kappa(n - 1) > target:
        n -= 1
    while kappa(n) <= target:
        n += 1
    return n


def rw_break_even_iterated(Fq, Finf, eps: float, sigma_z2, max_steps: int = 10_000_000):
    r"""The lag of :func:`rw_break_even_lag` by iterating (37)-(38) directly (vectorised; -1: never).

    Parameters
    ----------
    Fq, Finf : float or ndarray
        1-bit and unquantized information per measurement.
    eps : float
        ``1 - alpha``.
    sigma_z2 : float or ndarray
        Transition noise variance.
    max_steps : int
        Iteration limit.

    Returns
    -------
    ndarray of int64
        Delta, or -1 where :math:`\tilde J_{k|k,q} + \kappa_\infty \le \tilde J_{k|k,\infty}`.

    Raises
    ------
    ModelError
        If a reachable lag is not reached within ``max_steps``.
    """
    Fq, Finf, s = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in (Fq, Finf, sigma_z2)))
    Jq = rw_filtering_fixed_point(Fq, eps, s)
    Ji = rw_filtering_fixed_point(Finf, eps, s)
    reach = Jq + rw_smoothing_gain_fixed_point(Fq, eps, s) > Ji
    lag = np.where(reach, 0, -1).astype(np.int64)
    kappa = np.zeros_like(Fq)
    todo = reach.copy()
    n = 0
    while np.any(todo):
        n += 1
        if n > max_steps:
            raise ModelError(f"rw_break_even_iterated: no break-even within {max_steps} steps")
        kappa = rw_smoothing_gain_step(kappa, Fq, eps, s)
        hit = todo & (Jq + kappa > Ji)
        lag[hit] = n
        todo &= ~hit
    return lag


def rho_s_threshold_eps(snr_db: float, sigma_eta: float = 1.0, eps_lo: float = 1e-9, eps_hi: float = 0.5,
                        definition: str = "stationary") -> float:
    r"""Largest ``eps = 1 - alpha`` at which :math:`\rho_S`, (49), still exceeds 0 dB at a given SNR.

    Bisection in :math:`\log\varepsilon` on the sign of :math:`\rho_S` from
    :func:`information_ratios`; the bracket must hold one sign change (checked).

    Parameters
    ----------
    snr_db : float
        SNR in dB.
    sigma_eta : float
        Noise standard deviation.
    eps_lo, eps_hi : float
        Bracket; :math:`\rho_S(\varepsilon_{lo}) > 0 \ge \rho_S(\varepsilon_{hi})` is required.
    definition : str
        SNR convention.

    Returns
    -------
    float
        The threshold, NaN if :math:`\rho_S > 0` on the whole bracket, 0.0 if nowhere.
    """
    from scipy import optimize

    def f(le):
        return float(information_ratios(np.array([snr_db]), 10.0**le, sigma_eta, definition)["rho_s_db"][0])

    a, b = math.log10(eps_lo), math.log10(eps_hi)
    fa, fb = f(a), f(b)
    if fa <= 0:
        return 0.0
    if fb > 0:
        return float("nan")
    return float(10.0 ** optimize.brentq(f, a, b, xtol=1e-12))


def rho_s_zero_crossing(eps: float, sigma_eta: float = 1.0, definition: str = "stationary", lo_db: float = -40.0,
                        hi_db: float = 40.0) -> float:
    r"""SNR (dB) at which the steady-state :math:`\rho_S`, (49), first falls to 0 dB.

    A grid of 0.5 dB brackets the first sign change, then Brent's method solves
    :math:`\rho_S(\mathrm{SNR}) = 0` to 1e-10 dB.

    Parameters
    ----------
    eps : float
        ``1 - alpha`` (> 0).
    sigma_eta : float
        Noise standard deviation.
    definition : str
        SNR convention.
    lo_db, hi_db : float
        Search range.

    Returns
    -------
    float
        The crossing, NaN if :math:`\rho_S` does not change sign on the range.
    """
    from scipy import optimize

    grid = np.arange(lo_db, hi_db + 0.25, 0.5)
    r = information_ratios(grid, eps, sigma_eta, definition)["rho_s_db"]
    idx = np.flatnonzero((r[:-1] > 0) & (r[1:] <= 0))
    if len(idx) == 0:
        return float("nan")
    i = int(idx[0])

    def f(d):
        return float(information_ratios(np.array([d]), eps, sigma_eta, definition)["rho_s_db"][0])

    return float(optimize.brentq(f, grid[i], grid[i + 1], xtol=1e-10))


def ratios_at(snr_db, eps: float, sigma_eta: float = 1.0, definition: str = "stationary",
              quadrature: dict | None = None) -> dict:
    r"""The steady-state ratios (47)-(49) in dB at the given SNRs; ``eps = 0`` is the alpha -> 1 limit.

    The expected 1-bit information is (29) by the trapezoid rule (:func:`.fisher.expected_fisher_1bit`),
    the fixed points those of (24)/(34) and (27)/(37)-(38) (:func:`information_ratios`).

    The limit exists only at fixed stationary SNR (:func:`information_ratios_limit`); with
    ``definition='innovation'`` it is NaN (the stationary variance (33) diverges as alpha -> 1).

    Parameters
    ----------
    snr_db : array_like
        SNRs in dB.
    eps : float
        ``1 - alpha``; 0 for the limit.
    sigma_eta : float
        Noise standard deviation.
    definition : {'stationary', 'innovation'}
        SNR reading.
    quadrature : dict, optional
        ``half_width, step`` of the trapezoid rule for (29).

    Returns
    -------
    dict of ndarray
        ``rho_sl_db, rho_f_db, rho_s_db``.
    """
    snr_db = np.atleast_1d(np.asarray(snr_db, dtype=float))
    if eps == 0:
        if definition != "stationary":
            nan = np.full(snr_db.shape, np.nan)
            return dict(rho_sl_db=nan, rho_f_db=nan.copy(), rho_s_db=nan.copy())
        lim = information_ratios_limit(snr_db)
        return {k: lim[k] for k in ("rho_sl_db", "rho_f_db", "rho_s_db")}
    q = quadrature or {}
    s = sigma_z2_from_snr(snr_db, eps, sigma_eta, definition)
    e = expected_fisher_1bit(stationary_variance(eps, s) / sigma_eta**2, **q)
    res = information_ratios(snr_db, eps, sigma_eta, definition, efq=e)
    return {k: res[k] for k in ("rho_sl_db", "rho_f_db", "rho_s_db")}


def snr_shift_deviation(snr_db, eps: float, sigma_eta: float = 1.0) -> float:
    r"""Largest difference (dB) between the ratios (47)-(49) under the two SNR readings after the axis shift.

    Evaluates :func:`ratios_at` at the stationary SNRs ``snr_db`` and under the innovation reading
    at ``snr_db + axis_shift_db(eps)`` (the same :math:`\sigma_z^2`); both describe the same
    model, so the difference is rounding only.

    Parameters
    ----------
    snr_db : array_like
        Stationary SNRs in dB.
    eps : float
        ``1 - alpha`` (> 0).
    sigma_eta : float
        Noise standard deviation.

    Returns
    -------
    float
        ``max |ratio(innovation, SNR + shift) - ratio(stationary, SNR)|`` over the grid and the three ratios.
    """
    snr_db = np.asarray(snr_db, dtype=float)
    stat = ratios_at(snr_db, eps, sigma_eta, "stationary")
    inno = ratios_at(snr_db + axis_shift_db(eps), eps, sigma_eta, "innovation")
    return float(max(np.max(np.abs(stat[k] - inno[k])) for k in stat))


def ratio_window(snr_db, eps: float, ratio: str, target_db: float, tol_db: float, sigma_eta: float = 1.0) -> tuple:
    r"""The range of SNRs on a grid at which a steady-state ratio (47)-(49) is within ``tol_db`` of ``target_db``.

    At finite alpha, :math:`\rho_{SL}` (47) passes through its alpha -> 1 asymptote
    :math:`\sqrt{2/\pi}` (-0.98 dB) only inside a window of SNRs: below it the prior information
    :math:`(1-\alpha^2)/\sigma_z^2` lifts it towards 0 dB, above it the SNR loss sets in.

    Parameters
    ----------
    snr_db : array_like
        Increasing SNR grid (dB, stationary reading).
    eps : float
        ``1 - alpha``.
    ratio : {'rho_sl_db', 'rho_f_db', 'rho_s_db'}
        Which ratio of :func:`ratios_at`.
    target_db, tol_db : float
        Target value and tolerance (dB).
    sigma_eta : float
        Noise standard deviation.

    Returns
    -------
    tuple of float
        ``(lo, hi)``: the smallest and largest grid SNR within the tolerance; NaNs if none is.
    """
    snr_db = np.asarray(snr_db, dtype=float)
    r = ratios_at(snr_db, eps, sigma_eta)[ratio]
    ok = np.abs(r - target_db) <= tol_db
    if not ok.any():
        return float("nan"), float("nan")
    return float(snr_db[ok].min()), float(snr_db[ok].max())


def ratios_without_mean_reversion(snr_db, eps: float, sigma_eta: float = 1.0) -> dict:
    r"""The ratios (47)-(49) in dB with the mean reversion of (21) removed: a counterfactual for the prior's role.

    For each stationary SNR, :math:`\sigma_z^2` and :math:`E[F_q]` are those of ``eps`` (by (33) and
    (29)), but the fixed points of (24)/(34) and (27)/(37)-(38) are taken at :math:`\alpha = 1`: the
    stationary prior information :math:`(1-\alpha^2)/\sigma_z^2`, which the mean reversion supplies,
    is gone while the information per measurement and per transition stays. Comparing with
    :func:`ratios_at` at the same SNR isolates the effect of that prior information.

    Parameters
    ----------
    snr_db : array_like
        Stationary SNRs in dB.
    eps : float
        ``1 - alpha`` that sets :math:`\sigma_z^2` and :math:`E[F_q]` (> 0).
    sigma_eta : float
        Noise standard deviation.

    Returns
    -------
    dict of ndarray
        ``rho_sl_db, rho_f_db, rho_s_db``.
    """
    snr_db = np.atleast_1d(np.asarray(snr_db, dtype=float))
    s = sigma_z2_from_snr(snr_db, eps, sigma_eta, "stationary")
    Fq = expected_fisher_1bit(stationary_variance(eps, s) / sigma_eta**2) / sigma_eta**2
    Fi = np.full_like(s, 1.0 / sigma_eta**2)
    jf_q, jf_i = rw_filtering_fixed_point(Fq, 0.0, s), rw_filtering_fixed_point(Fi, 0.0, s)
    js_q = jf_q + rw_smoothing_gain_fixed_point(Fq, 0.0, s)
    js_i = jf_i + rw_smoothing_gain_fixed_point(Fi, 0.0, s)
    return dict(rho_sl_db=_db(js_q / js_i), rho_f_db=_db(jf_q / jf_i), rho_s_db=_db(js_q / jf_i))
