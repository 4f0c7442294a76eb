"""The Fisher information of one hard-limited measurement and its expectation, eqs. (28)-(30).

``efq`` elsewhere in the package is the dimensionless expected 1-bit Fisher information
``sigma_eta^2 E[F_q]`` of (29).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.special import log_ndtr

from ...errors import InputError

__all__ = [
    "fisher_1bit",
    "expected_fisher_1bit",
    "expected_fisher_1bit_quad",
    "expected_fisher_interpolator",
    "rho_s_zero_crossing_limit",
    "expected_inverse_sqrt_fisher_1bit",
    "achievable_rho_s_limit_db",
    "achievable_rho_s_crossing_limit",
    "ACHIEVABLE_LIMIT_SNR_MAX_DB",
]

#: The stationary SNR (dB) from which E[F_q^(-1/2)] diverges: Var[theta]/sigma_eta^2 = 2.
ACHIEVABLE_LIMIT_SNR_MAX_DB = 10.0 * math.log10(2.0)

_LOG_SQRT_2PI = 0.5 * math.log(2.0 * math.pi)


def _log_h(x):
    """log of h(x) = phi(x) / (Phi(x) Phi(-x)), evaluated in the log domain."""
    return -0.5 * x * x - _LOG_SQRT_2PI - log_ndtr(x) - log_ndtr(-x)


def fisher_1bit(theta, sigma_eta: float = 1.0):
    r"""Fisher information of one hard-limited measurement, eq. (30).

    .. math::

        F_q(\theta) = \frac{1}{2\pi\sigma_\eta^2}
        \frac{e^{-\theta^2/\sigma_\eta^2}}{Q(\theta/\sigma_\eta)\,Q(-\theta/\sigma_\eta)}

    for :math:`r = \mathrm{sign}(\theta + \eta)`, eq. (28). Computed as
    ``exp(2 log phi - log Phi(x) - log Phi(-x)) / sigma_eta^2`` with
    :func:`scipy.special.log_ndtr`, so the ratio of two underflowing tails
    stays accurate (it decays like ``|x| phi(x)``).

    Parameters
    ----------
    theta : array_like
        Parameter values.
    sigma_eta : float
        Noise standard deviation.

    Returns
    -------
    ndarray
        :math:`F_q(\theta)`, same shape as ``theta``.
    """
    x = np.asarray(theta, dtype=float) / sigma_eta
    return np.exp(2.0 * (-0.5 * x * x - _LOG_SQRT_2PI) - log_ndtr(x) - log_ndtr(-x)) / sigma_eta**2


def expected_fisher_1bit(var_theta, sigma_eta: float = 1.0, mean_theta=0.0, half_width: float = 12.0,
                         step: float = 0.1):
    r"""Expected 1-bit Fisher information :math:`E_\theta[F_q(\theta)]`, eq. (29), vectorised.

    With :math:`\theta \sim N(\mu, v\sigma_\eta^2)` and :math:`x = \theta/\sigma_\eta`,
    write :math:`F_q = \sigma_\eta^{-2}\,\varphi(x)\,h(x)` with
    :math:`h = \varphi/(\Phi(x)\Phi(-x))` (smooth, growing like ``|x|``). The
    product of the two Gaussians is again Gaussian:

    .. math::

        \sigma_\eta^2 E[F_q] = N(m; 0, 1+v)\; E_{x \sim N(m/(1+v),\, v/(1+v))}[h(x)],
        \quad m = \mu/\sigma_\eta,

    an expectation under a normal law of variance < 1 of an analytic function,
    evaluated by the trapezoid rule on ``[-half_width, half_width]`` standard
    deviations (spectrally accurate; ~1e-14 relative for the defaults).
    Limits: ``2/pi`` as ``v -> 0`` (the -1.96 dB of [5]); ``c / sqrt(2 pi v)``
    with ``c = E_N(0,1)[h] = 1.806...`` as ``v -> inf``.

    Parameters
    ----------
    var_theta : array_like
        Variance of theta (any shape).
    sigma_eta : float
        Standard deviation of the measurement noise eta, (20) and (28) (units of theta).
    mean_theta : array_like
        Mean of theta, (31); broadcast against ``var_theta``.
    half_width, step : float
        Trapezoid range (in standard deviations) and spacing.

    Returns
    -------
    ndarray
        :math:`E[F_q]`, broadcast shape of ``var_theta`` and ``mean_theta``.

    Raises
    ------
    InputError
        If ``var_theta`` is negative.
    """
    v = np.asarray(var_theta, dtype=float) / sigma_eta**2
    m = np.asarray(mean_theta, dtype=float) / sigma_eta
    v, m = np.broadcast_arrays(v, m)
    if np.any(v < 0):
        raise InputError("expected_fisher_1bit: var_theta must be >= 0")
    u = np.arange(-half_width, half_width + step / 2, step)
    w = np.exp(-0.5 * u * u - _LOG_SQRT_2PI) * step
    tau = np.sqrt(v / (1.0 + v))[..., None]
    centre = (m / (1.0 + v))[..., None]
    inner = np.exp(_log_h(centre + tau * u)) @ w
    pref = np.exp(-0.5 * m * m / (1.0 + v)) / np.sqrt(2.0 * np.pi * (1.0 + v))
    return pref * inner / sigma_eta**2


def expected_fisher_1bit_quad(var_theta: float, sigma_eta: float = 1.0, mean_theta: float = 0.0,
                              epsrel: float = 1e-13) -> tuple[float, float]:
    """Eq. (29) by adaptive quadrature of (30) times the normal density (independent check).

    Returns ``(value, error_estimate)``; scalar arguments only.

    Parameters
    ----------
    var_theta : float
        Variance of theta.
    sigma_eta : float
        Noise standard deviation.
    mean_theta : float
        Mean of theta.
    epsrel : float
        Relative tolerance of the quadrature.

    Returns
    -------
    tuple of float
        ``(value, error_estimate)`` of (29).
    """
    from scipy import integrate

    s = math.sqrt(var_theta)
    lo = max(mean_theta - 40.0 * s, -60.0 * sigma_eta)
    hi = min(mean_theta + 40.0 * s, 60.0 * sigma_eta)

    def f(t):
        return fisher_1bit(t, sigma_eta) * math.exp(-0.5 * ((t - mean_theta) / s) ** 2) / (s * math.sqrt(2 * math.pi))

    points = [p for p in (mean_theta, 0.0) if lo < p < hi]
    val, err = integrate.quad(f, lo, hi, points=points or None, epsabs=0.0, epsrel=epsrel, limit=500)
    return float(val), float(err)


def expected_fisher_interpolator(log10_v_min: float = -12.0, log10_v_max: float = 8.0, n: int = 4001):
    """A cubic spline of ``log(sigma_eta^2 E[F_q])`` over ``log10(var_ratio)`` (mean zero).

    Used only to evaluate (29) at millions of time steps of a transient; the
    spline error is ~1e-12 relative for the defaults (tested).

    Parameters
    ----------
    log10_v_min, log10_v_max : float
        Range of ``log10(var_ratio)`` covered (clipped outside).
    n : int
        Number of spline nodes.

    Returns
    -------
    callable
        ``f(var_ratio) -> efq`` (dimensionless).
    """
    from scipy import interpolate

    grid = np.linspace(log10_v_min, log10_v_max, n)
    spline = interpolate.CubicSpline(grid, np.log(expected_fisher_1bit(10.0**grid)))

    def efq(var_ratio):
        lv = np.clip(np.log10(np.asarray(var_ratio, dtype=float)), log10_v_min, log10_v_max)
        return np.exp(spline(lv))

    return efq


def rho_s_zero_crossing_limit():
    r"""SNR (dB) where the alpha -> 1 rho_S crosses 0 dB: sigma_eta^2 E[F_q] = 1/4.

    Returns
    -------
    float
        The SNR in dB (stationary definition) where :math:`\sigma_\eta^2E[F_q] = 1/4`, i.e. where the alpha -> 1 limit of (49), :math:`2\sqrt{\sigma_\eta^2E[F_q]}`, equals one.
    """
    from scipy import optimize

    return float(optimize.brentq(lambda d: float(expected_fisher_1bit(10 ** (d / 10))) - 0.25, -10.0, 40.0, xtol=1e-10))



def expected_inverse_sqrt_fisher_1bit(var_ratio, half_width: float = 12.0, step: float = 0.1):
    r"""Expected inverse square root of the 1-bit Fisher information, :math:`E[(\sigma_\eta^2 F_q(\theta))^{-1/2}]`.

    Beyond the paper: with :math:`\theta \sim N(0, v\sigma_\eta^2)`, :math:`x = \theta/\sigma_\eta` and
    (30) written :math:`\sigma_\eta^2 F_q = \varphi(x) h(x)`, :math:`h = \varphi/(\Phi(x)\Phi(-x))`,

    .. math::

        E[(\sigma_\eta^2 F_q)^{-1/2}] = (2\pi)^{1/4} \sqrt{w/v}\; E_{x \sim N(0, w)}[h(x)^{-1/2}],
        \qquad w = \frac{2v}{2 - v},

    because :math:`N(x; 0, v)\,\varphi(x)^{-1/2} = (2\pi)^{1/4}\sqrt{w/v}\,N(x; 0, w)`; the last
    expectation is of a smooth function decaying like :math:`|x|^{-1/2}` and is taken by the
    trapezoid rule on ``[-half_width, half_width]`` standard deviations. For :math:`v \ge 2` the
    expectation diverges (:math:`F_q^{-1/2}` grows like :math:`e^{x^2/4}`) and ``inf`` is returned.
    Limit :math:`\sqrt{\pi/2}` as :math:`v \to 0` (:math:`\sigma_\eta^2 F_q(0) = 2/\pi`).

    Parameters
    ----------
    var_ratio : array_like
        :math:`v = \mathrm{Var}[\theta]/\sigma_\eta^2` (the stationary SNR as a ratio), >= 0.
    half_width, step : float
        Trapezoid range (standard deviations of :math:`N(0, w)`) and spacing.

    Returns
    -------
    ndarray
        :math:`E[(\sigma_\eta^2 F_q)^{-1/2}]`, shape of ``var_ratio`` (``inf`` where ``v >= 2``).

    Raises
    ------
    InputError
        If ``var_ratio`` is negative.
    """
    v = np.asarray(var_ratio, dtype=float)
    if np.any(v < 0):
        raise InputError("expected_inverse_sqrt_fisher_1bit: var_ratio must be >= 0")
    finite = v < 2.0
    vf = np.where(finite, v, 1.0)
    w = 2.0 * vf / (2.0 - vf)
    u = np.arange(-half_width, half_width + step / 2, step)
    weights = np.exp(-0.5 * u * u - _LOG_SQRT_2PI) * step
    inner = np.exp(-0.5 * _log_h(np.sqrt(w)[..., None] * u)) @ weights
    # sqrt(w / v) -> 1 as v -> 0 (w = 2v/(2 - v))
    ratio = np.sqrt(2.0 / (2.0 - vf))
    out = (2.0 * math.pi) ** 0.25 * ratio * inner
    return np.where(finite, out, np.inf)


def achievable_rho_s_limit_db(snr_db):
    r"""The alpha -> 1 limit of the achievable rho_S (dB): :math:`2/E[(\sigma_\eta^2 F_q)^{-1/2}]`.

    Beyond the paper. As :math:`\alpha \to 1` at fixed stationary SNR, :math:`\sigma_z \to 0` and the
    filter's time constant :math:`1/(\sigma_z\sqrt{F})` becomes short against the state's
    correlation time :math:`1/(1-\alpha)`: the state is locally constant, and the MMSE smoother
    around :math:`\theta` is the random-walk smoother with information :math:`F_q(\theta)` per
    step, of variance :math:`\sigma_z/(2\sqrt{F_q(\theta)})` (the :math:`\alpha \to 1` fixed
    points of (34)/(36)). Averaged over the stationary law, against the unquantized Kalman filter's
    :math:`\sigma_z\sigma_\eta` ((24), same limit),

    .. math::

        \rho_S^{\mathrm{ach}} \to \frac{2}{E[(\sigma_\eta^2 F_q(\theta))^{-1/2}]}
        \le 2\sqrt{\sigma_\eta^2 E[F_q]} \quad\text{(Jensen; the bound's limit of (49))}.

    It tends to :math:`2\sqrt{2/\pi}` (+2.03 dB) as SNR -> 0 and to 0 (-inf dB) as the SNR
    reaches :data:`ACHIEVABLE_LIMIT_SNR_MAX_DB` (3.01 dB).

    Parameters
    ----------
    snr_db : array_like
        Stationary SNR :math:`10\log_{10}(\mathrm{Var}[\theta]/\sigma_\eta^2)` in dB.

    Returns
    -------
    ndarray
        The limit in dB (``-inf`` from 3.01 dB on).
    """
    e = expected_inverse_sqrt_fisher_1bit(10.0 ** (np.asarray(snr_db, dtype=float) / 10.0))
    with np.errstate(divide="ignore"):
        return 10.0 * np.log10(2.0 / e)


def achievable_rho_s_crossing_limit(xtol: float = 1e-10) -> float:
    r"""SNR (dB) where the alpha -> 1 achievable rho_S crosses 0 dB: :math:`E[(\sigma_\eta^2 F_q)^{-1/2}] = 2`.

    Beyond the paper (:func:`achievable_rho_s_limit_db`); Brent's method between -10 dB and just
    below :data:`ACHIEVABLE_LIMIT_SNR_MAX_DB`.

    Parameters
    ----------
    xtol : float
        Absolute tolerance of the root in dB.

    Returns
    -------
    float
        The SNR in dB (stationary definition).
    """
    from scipy import optimize

    hi = ACHIEVABLE_LIMIT_SNR_MAX_DB - 1e-6
    return float(optimize.brentq(lambda d: float(achievable_rho_s_limit_db(d)), -10.0, hi, xtol=xtol))
