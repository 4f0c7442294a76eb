"""``E||P_k||`` over the whole figure horizon with a stated method per value: exact (all channel
paths, :mod:`.exact`), the conditional estimator where it is validated against the exact values, or
an asymptote whose growth rate is derived from the channel (eq. 3) and the parity lock of Example II.

Every value of ``results/markov/expectations.csv`` comes from one of these; where none applies the
value is left empty (``not_trustworthy``) rather than printed wrong.
"""

from __future__ import annotations

import numpy as np

from ...errors import InputError
from . import estimators as est
from .certificates import parity_structure
from .model import spectral_abs

__all__ = [
    "two_step_rate", "conditional_estimate", "conditional_validation", "asymptote_extrapolation",
    "asymptote_backtest", "asymptote_limit",
]


def two_step_rate(A, C, Q, p, q) -> float:
    """Derived asymptotic growth of ``E||P_k||`` over two steps, ``rho^2`` (``E||P_{k+2}|| / E||P_k|| -> rho^2``).

    Two mechanisms make ``||P_k||`` large (eqs. 3-5):

    * the trailing loss run: ``j`` losses after the last reception have probability
      ``p (1-q)^{j-1}`` and multiply ``P`` by up to ``|lambda_A|^{2j}`` (eq. 4), rate per step
      ``|lambda_A|^2 (1-q)``;
    * for a parity-locked system (``A^2 = lambda^2 I``, ``C v = 0``; Example II, eq. 13,
      :func:`.certificates.parity_structure`): receptions separated by even gaps all observe the same
      subspace, so the variance along ``v`` grows like ``lambda^{2k}`` until an odd gap. Gaps of
      ``2m`` steps have probability ``p q (1-q)^{2m-2}``, and the renewal equation
      ``sum_m p q (1-q)^{2m-2} (lambda^2 / rho)^{2m} = 1`` gives

    .. math:: \\rho^2 = \\lambda^4 \\big(p q + (1-q)^2\\big)

    (:func:`.certificates.parity_growth`; ``rho = 1`` is the parity critical curve,
    :func:`.model.parity_bound_example2`).

    The two-step rate is the larger of ``(|lambda_A|^2 (1-q))^2`` and, for a parity-locked system,
    ``rho^2``. It is the rate of the heavy-tail mechanisms only (the filter's own transients decay at
    rates set by the closed loop): whether it dominates at the exact horizon is checked, not assumed
    (:func:`asymptote_backtest`).

    Parameters
    ----------
    A, C, Q : array_like
        System, output and process noise matrices (eqs. 1-2).
    p, q : float
        Failure and recovery rates (eq. 3).

    Returns
    -------
    float
        The two-step growth factor ``rho^2``.
    """
    lam = spectral_abs(A)
    rate = (lam ** 2 * (1.0 - q)) ** 2
    structure = parity_structure(A, C, Q)
    if structure is not None:
        rate = max(rate, structure["lam"] ** 4 * (p * q + (1.0 - q) ** 2))
    return float(rate)


def conditional_estimate(system, Sigma0, p, q, n_paths: int, horizon: int, rng, z: float):
    """Conditional (Rao-Blackwellised) estimate of ``E||P_k||``, ``k = 1..horizon+1``, with a 95% interval.

    The per-path values of :func:`.estimators.rb_mean_norm` (trailing loss run integrated exactly)
    are independent across paths, so the interval is ``mean +- z s / sqrt(N)``.

    Parameters
    ----------
    system : LinearSystem
        The system (eqs. 1-2).
    Sigma0 : array_like
        ``P_1``.
    p, q : float
        Failure and recovery rates.
    n_paths, horizon : int
        Number of channel paths and of steps.
    rng : numpy.random.Generator
        Random source.
    z : float
        Normal quantile of the interval (``markov.estimator.interval_z``; 1.96: 95%).

    Returns
    -------
    (mean, half) : ndarray
        Estimate and 95% half-width, each of length ``horizon + 1`` (``k = 1..horizon+1``).
    """
    arrivals = est.gilbert_elliott_arrivals(rng, n_paths, horizon, p, q, initial=1)
    vals = est.rb_mean_norm(system, Sigma0, p, q, arrivals)
    mean = vals.mean(axis=0)
    half = z * vals.std(axis=0, ddof=1) / np.sqrt(n_paths)
    return mean, half


def conditional_validation(mean, half, exact, z_max: float, z: float, rtol: float):
    """Largest ``|z|`` of the conditional estimate against the exact values on the exact range.

    ``z_k = (mean_k - exact_k) / (half_k / z)`` for ``k = 2..K`` (``k = 1`` is deterministic);
    where the estimate is deterministic (``half_k <= rtol exact_k``, e.g. ``k = 2``: ``gamma_1 = 1``)
    the values must agree to ``rtol`` relative instead (``z = 0`` if they do, ``inf`` if not).

    Parameters
    ----------
    mean, half : ndarray
        From :func:`conditional_estimate`.
    exact : ndarray
        Exact ``E||P_k||``, ``k = 1..K`` (:meth:`.exact.ExactMoments.mean`).
    z_max : float
        Largest admissible ``|z|``.
    z : float
        The quantile that made ``half`` (``markov.estimator.interval_z``).
    rtol : float
        Relative tolerance of the deterministic case (``markov.estimator.deterministic_rtol``).

    Returns
    -------
    (max_abs_z, ok) : (float, bool)
    """
    K = len(exact)
    if len(mean) < K:
        raise InputError(f"the estimate has {len(mean)} values; need at least the {K} exact ones")
    se = half[1:K] / z
    diff = mean[1:K] - exact[1:]
    det = se <= rtol * np.abs(exact[1:])
    with np.errstate(divide="ignore", invalid="ignore"):
        z = np.where(det, np.where(np.abs(diff) <= rtol * np.abs(exact[1:]), 0.0, np.inf), diff / se)
    zmax = float(np.max(np.abs(z))) if len(z) else 0.0
    return zmax, bool(zmax <= z_max)


def asymptote_extrapolation(exact, k_max: int, rate2: float):
    """Extrapolate ``E||P_k||`` beyond the exact range with the derived two-step rate ``rho^2``.

    With ``E_k`` exact for ``k <= K`` and the two-step increments ``D_k = E_k - E_{k-2}``, the
    asymptote continues each parity class with increments in geometric ratio ``R``:

    .. math:: E_{K' + 2m} = E_{K'} + D_{K'} \\sum_{i=1}^{m} R^i,\\quad K' \\in \\{K-1, K\\}

    (for a growing mean this is ``E_{K'} R^m`` in the limit). ``mean`` takes ``R = rho^2``
    (:func:`two_step_rate`); the bracket takes ``R`` between ``rho^2`` and the last observed
    increment ratio ``r = D_K / D_{K-2}`` (resp. ``D_{K-1} / D_{K-3}``): if the observed ratios
    converge monotonically to ``rho^2`` (checked by :func:`asymptote_backtest`), every later ratio
    lies in that interval, and so does ``E_k``.

    Parameters
    ----------
    exact : ndarray
        Exact ``E||P_k||``, ``k = 1..K`` (``K >= 6``).
    k_max : int
        Last ``k`` to extrapolate to.
    rate2 : float
        ``rho^2`` from :func:`two_step_rate`.

    Returns
    -------
    (mean, lo, hi) : ndarray
        For ``k = K+1..k_max``.
    """
    exact = np.asarray(exact, float)
    K = len(exact)
    if K < 6:
        raise InputError(f"asymptote_extrapolation needs at least 6 exact values, got {K}")
    ks = np.arange(K + 1, k_max + 1)
    mean, lo, hi = (np.empty(len(ks)) for _ in range(3))
    for i, k in enumerate(ks):
        base = K if (k - K) % 2 == 0 else K - 1  # same parity as k
        m = (k - base) // 2
        D = exact[base - 1] - exact[base - 3]
        r_obs = D / (exact[base - 3] - exact[base - 5])
        vals = [exact[base - 1] + D * sum(R ** j for j in range(1, m + 1)) for R in (rate2, r_obs)]
        mean[i] = vals[0]
        lo[i], hi[i] = min(vals), max(vals)
    return mean, lo, hi


def asymptote_limit(exact, rate2: float):
    """``lim_k E||P_k||`` of :func:`asymptote_extrapolation` (``m -> infinity``), with its bracket.

    For ``R < 1`` the sum in :func:`asymptote_extrapolation` converges:

    .. math:: E_\\infty = E_{K'} + D_{K'} \\frac{R}{1 - R},\\quad K' \\in \\{K-1, K\\}

    ``limit`` takes ``R = rho^2`` and averages the two parity classes; ``lo, hi`` span both classes
    and ``R`` between ``rho^2`` and the observed ratio (the bracket of :func:`asymptote_extrapolation`
    carried to the limit). ``inf`` when either ratio is ``>= 1`` (the mean diverges).

    Parameters
    ----------
    exact : ndarray
        Exact ``E||P_k||``, ``k = 1..K`` (``K >= 6``).
    rate2 : float
        ``rho^2`` from :func:`two_step_rate`.

    Returns
    -------
    (limit, lo, hi) : float
    """
    exact = np.asarray(exact, float)
    K = len(exact)
    if K < 6:
        raise InputError(f"asymptote_limit needs at least 6 exact values, got {K}")
    means, vals = [], []
    for base in (K, K - 1):
        D = exact[base - 1] - exact[base - 3]
        r_obs = D / (exact[base - 3] - exact[base - 5])
        at_rate, at_obs = (exact[base - 1] + D * R / (1.0 - R) if R < 1.0 else np.inf for R in (rate2, r_obs))
        means.append(at_rate)
        vals += [at_rate, at_obs]
    return float(np.mean(means)), float(min(vals)), float(max(vals))


def asymptote_backtest(exact, rate2: float, k0: int):
    """Validate :func:`asymptote_extrapolation` on the exact range: extrapolate from ``k <= k0`` and
    compare with the exact ``E||P_k||`` at ``k = k0+1..K``.

    Parameters
    ----------
    exact : ndarray
        Exact ``E||P_k||``, ``k = 1..K``.
    rate2 : float
        ``rho^2`` from :func:`two_step_rate`.
    k0 : int
        Last exact value used by the extrapolation (``6 <= k0 < K``).

    Returns
    -------
    (inside, max_rel_err, monotone) : (bool, float, bool)
        ``inside``: every exact value lies in the extrapolated bracket; ``max_rel_err``: largest
        ``|mean - exact| / exact``; ``monotone``: the observed two-step increment ratios approach
        ``rho^2`` monotonically over ``k0 - 2..K`` (the premise of the bracket).
    """
    exact = np.asarray(exact, float)
    K = len(exact)
    if not 6 <= k0 < K:
        raise InputError(f"k0 must be in [6, {K - 1}], got {k0}")
    mean, lo, hi = asymptote_extrapolation(exact[:k0], K, rate2)
    truth = exact[k0:]
    tol = 1e-12 * np.abs(truth)
    inside = bool(np.all((truth >= lo - tol) & (truth <= hi + tol)))
    rel = float(np.max(np.abs(mean - truth) / truth))
    D = exact[2:] - exact[:-2]  # D[k-3] = E_k - E_{k-2}
    r = D[2:] / D[:-2]  # ratio at k = 5..K
    dev = np.abs(r - rate2)
    monotone = True
    for par in (0, 1):
        d = dev[max(k0 - 7, 0):][par::2]
        monotone &= bool(np.all(np.diff(d) <= 1e-12))
    return inside, rel, monotone
