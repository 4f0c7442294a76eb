"""Sample paths and tails of p_k (eq. (6)): runs of losses, the loss-run probability, the tail index.

Everything here follows from one fact about eq. (6): a loss (gamma_k = 0) multiplies p by a^2 and adds R1,
an arrival maps every p >= 0 into [R1, a^2 R2 + R1). So p_k is large exactly when the last arrival lies
far back: a run of m losses lifts p above R1 (a^{2m} - 1)/(a^2 - 1) from any state, and a stationary
run of losses is geometric, P(run >= m) = (1 - lambda)^m. Hence the power tail P(p_inf > x) ~ x^{-alpha}
with alpha = log(1/(1 - lambda)) / log(a^2), and E(p_inf^n) < inf iff (1 - lambda) a^{2n} < 1
(n = 1: lambda > lambda_c; n = 2: lambda > 1 - 1/a^4).
"""

from __future__ import annotations

import numpy as np

from ...errors import InputError

__all__ = [
    "losses_to_exceed",
    "loss_run_survival_log",
    "loss_run_probability",
    "loss_run_probability_dominant_root",
    "loss_run_probability_recursion",
    "tail_index",
    "moment_finite_threshold",
    "sum_rounding_bound",
    "quantile_interval",
    "exceedance_probability",
]


def losses_to_exceed(level, a, R1) -> int:
    """Consecutive losses after which p_k >= ``level`` from any p >= 0 (eq. (6) with gamma = 0).

    After m losses p >= R1 (a^{2m} - 1)/(a^2 - 1) whatever p was before.

    Parameters
    ----------
    level : float
        Level to reach, > 0.
    a, R1 : float
        System coefficient (|a| > 1) and process noise variance (> 0).

    Returns
    -------
    int
        The smallest m with R1 (a^{2m} - 1)/(a^2 - 1) >= level.
    """
    a2 = a * a
    m = int(np.ceil(np.log1p(level * (a2 - 1.0) / R1) / np.log(a2)))
    # guard the rounding of the logarithms at an exact power
    while m > 0 and R1 * np.expm1((m - 1) * np.log(a2)) / (a2 - 1.0) >= level:
        m -= 1
    return m


def _check_run(lam, m, T):
    if not 0.0 < lam <= 1.0:
        raise InputError(f"arrival probability lambda = {lam} must lie in (0, 1]")
    if int(m) != m or m < 1:
        raise InputError(f"run length m = {m} must be an integer >= 1")
    if int(T) != T or T < 0:
        raise InputError(f"number of steps T = {T} must be an integer >= 0")


def loss_run_survival_log(lam, m, T) -> float:
    """log P(no run of m consecutive losses among T i.i.d. arrivals of probability lambda).

    The transient block Q of the run-length chain (states 0..m-1: the current run of losses; a loss in
    state m-1 leaves the block, i.e. completes a run of m) is substochastic; the survival is
    e_0^T Q^T 1. Q^T is formed by repeated squaring with a separate logarithmic scale: after every
    product the matrix is divided by its largest entry and the logarithm of that entry is accumulated,
    so nothing under- or overflows and the absorbing column (whose entry would be 1 - survival, the
    difference of two numbers near 1) is never formed. Accuracy: each squaring doubles the relative
    rounding error already in the power, so log survival carries an absolute error of order T m eps
    (measured: 1.4e-12 at T = 1e5, 1.4e-8 at T = 1e9 for m = 21 against
    :func:`loss_run_probability_dominant_root`); P = 1 - survival then has a relative error of that
    order divided by P.

    Parameters
    ----------
    lam : float
        Arrival probability lambda in (0, 1].
    m : int
        Run length, >= 1.
    T : int
        Number of steps, >= 0 (may be huge: O(m^3 log T) work).

    Returns
    -------
    float
        log of the survival probability, <= 0.

    Raises
    ------
    InputError
        For lambda outside (0, 1], m < 1 or T < 0.
    """
    _check_run(lam, m, T)
    T = int(T)
    Q = np.zeros((m, m))
    Q[:, 0] = lam
    Q[np.arange(m - 1), np.arange(1, m)] = 1.0 - lam
    # result = exp(log_r) * R, base = exp(log_b) * B
    R, log_r = np.eye(m), 0.0
    B, log_b = Q, 0.0
    while T:
        if T & 1:
            R = R @ B
            log_r += log_b
            top = R.max()
            R, log_r = R / top, log_r + np.log(top)
        T >>= 1
        if T:
            B = B @ B
            log_b *= 2.0
            top = B.max()
            B, log_b = B / top, log_b + np.log(top)
    return float(min(0.0, log_r + np.log(R[0].sum())))


def loss_run_probability(lam, m, T) -> float:
    """P(a run of at least m consecutive losses occurs among T i.i.d. arrivals of probability lambda).

    P = -expm1(log survival) with the survival of :func:`loss_run_survival_log`, so that small
    probabilities keep their relative precision and P never leaves [0, 1] (a power of the full stochastic
    matrix, with its absorbing state, accumulates rounding of order T eps and can exceed 1).

    Parameters
    ----------
    lam : float
        Arrival probability lambda in (0, 1].
    m : int
        Run length, >= 1.
    T : int
        Number of steps, >= 0.

    Returns
    -------
    float
        The probability, in [0, 1].
    """
    p = float(-np.expm1(loss_run_survival_log(lam, m, T)))
    if not 0.0 <= p <= 1.0:
        raise AssertionError(f"loss-run probability {p!r} outside [0, 1]")
    return p


def loss_run_probability_dominant_root(lam, m, T) -> float:
    """The same probability from the dominant root of the run generating function (Feller, vol. I, XIII.7).

    With u = 1 - lambda the loss probability, the probability of no run of m losses in T trials is
    (1 - u x) / ((m + 1 - m x) lambda) x^{-(T+1)} up to terms that decay like (x / |x_2|)^T, where
    x = 1 + delta is the root near 1 of 1 - x + lambda u^m x^{m+1} = 0 and x_2 the next root. delta
    solves delta = lambda u^m (1 + delta)^{m+1} (fixed-point iteration, converging fast when
    lambda u^m (m + 1) << 1), and is computed directly, so log x = log1p(delta) keeps full relative
    precision. Accurate for T much larger than m; used as an independent check of
    :func:`loss_run_probability`.

    Parameters
    ----------
    lam : float
        Arrival probability lambda in (0, 1).
    m : int
        Run length, >= 1, with lambda (1 - lambda)^m (m + 1) < 0.5 (the fixed point is then a contraction).
    T : int
        Number of steps, >= 0.

    Returns
    -------
    float

    Raises
    ------
    InputError
        Outside the range where the fixed-point iteration is a contraction.
    """
    _check_run(lam, m, T)
    u = 1.0 - lam
    c = lam * u**m
    if not 0.0 < c * (m + 1) < 0.5:
        raise InputError(f"lambda (1 - lambda)^m (m + 1) = {c * (m + 1):.3g} must lie in (0, 0.5) for this method")
    delta = c
    for _ in range(200):
        nxt = c * np.exp((m + 1) * np.log1p(delta))
        if abs(nxt - delta) <= 1e-17 * nxt:
            delta = nxt
            break
        delta = nxt
    x = 1.0 + delta
    log_surv = np.log((1.0 - u * x) / ((m + 1 - m * x) * lam)) - (int(T) + 1) * np.log1p(delta)
    return float(-np.expm1(min(0.0, log_surv)))


def loss_run_probability_recursion(lam, m, T) -> float:
    """The same probability by the renewal recursion on the first arrival (exact, O(T m)).

    With v_n = P(no run of m losses in n trials): v_n = 1 for n < m and
    v_n = sum_{i=0}^{m-1} (1 - lambda)^i lambda v_{n-i-1} for n >= m (the first arrival comes after i < m
    losses). Summed in the complementary form w_n = 1 - v_n, so small probabilities are not lost.

    Parameters
    ----------
    lam : float
        Arrival probability lambda in (0, 1].
    m : int
        Run length, >= 1.
    T : int
        Number of steps, >= 0 (modest: a Python loop over T).

    Returns
    -------
    float
    """
    _check_run(lam, m, T)
    T = int(T)
    u = 1.0 - lam
    weights = lam * u ** np.arange(m)  # P(first arrival after exactly i losses), i < m
    tail = u**m  # P(m losses first): a run
    w = np.zeros(T + 1)
    for n in range(m, T + 1):
        # w_n = u^m + sum_i weights_i w_{n-i-1}
        w[n] = tail + float(weights @ w[n - 1 - np.arange(m)])
    return float(w[T])


def tail_index(lam, a) -> float:
    """Tail index alpha of the stationary p_inf: P(p_inf > x) ~ x^{-alpha}, alpha = log(1/(1 - lambda))/log(a^2).

    A stationary run of losses is geometric with ratio 1 - lambda and multiplies p by a^2 per loss, while
    an arrival puts p back into [R1, a^2 R2 + R1); hence the moment E(p_inf^n) is finite iff n < alpha.

    Parameters
    ----------
    lam : float or array_like
        Arrival probability in (0, 1]; lambda = 1 gives alpha = inf (p bounded).
    a : float
        System coefficient, |a| > 1.

    Returns
    -------
    float or ndarray
    """
    lam = np.asarray(lam, dtype=float)
    with np.errstate(divide="ignore"):
        out = -np.log1p(-lam) / np.log(a * a)
    return float(out) if out.ndim == 0 else out


def moment_finite_threshold(n, a) -> float:
    """Smallest arrival probability above which E(p_inf^n) is finite: lambda > 1 - 1/a^{2n}.

    n = 1 is lambda_c (section 4); n = 2 is where the variance of p_inf becomes finite.

    Parameters
    ----------
    n : float
        Order of the moment, > 0.
    a : float
        System coefficient, |a| > 1.

    Returns
    -------
    float
    """
    return float(1.0 - abs(a) ** (-2.0 * n))


def sum_rounding_bound(n_terms: int, weight_rtol: float = 0.0) -> float:
    """Relative error bound of a prefix sum of ``n_terms`` nonnegative weights formed in extended precision.

    Recursive summation of ``n`` nonnegative terms carries ``|s_hat - s| <= gamma_n sum w`` with
    ``gamma_n = n u / (1 - n u)`` (Higham, *Accuracy and Stability of Numerical Algorithms*, 2nd ed., eq. (4.4)),
    ``u`` the unit roundoff of ``numpy.longdouble`` (the precision the sums are formed in). If each weight
    itself carries a relative error ``rho = weight_rtol`` (a product of ``k`` rounded factors: ``rho = gamma_k``
    of float64), the computed prefix sum ``F_hat`` and the true one ``F`` satisfy
    ``|F_hat - F| <= (rho + gamma_n (1 + rho)) F``, and ``F <= F_hat / (1 - rho - gamma_n (1 + rho))``.

    Parameters
    ----------
    n_terms : int
        Number of summed terms, >= 0.
    weight_rtol : float
        Relative error bound of each weight, >= 0.

    Returns
    -------
    float
        ``c`` with ``|F_hat - F| <= c F_hat`` for every prefix sum.

    Raises
    ------
    InputError
        For a negative ``n_terms`` or ``weight_rtol``, or a bound that is not below 1.
    """
    if n_terms < 0 or weight_rtol < 0:
        raise InputError(f"n_terms = {n_terms} and weight_rtol = {weight_rtol} must be >= 0")
    u = float(np.finfo(np.longdouble).eps) / 2.0
    gamma = n_terms * u / (1.0 - n_terms * u)
    total = weight_rtol + gamma * (1.0 + weight_rtol)
    if not total < 0.5:
        raise InputError(f"rounding bound {total:g} of {n_terms} terms is not small")
    return total / (1.0 - total)


def _sorted_cdf(values, weights):
    values, weights = np.asarray(values, dtype=float), np.asarray(weights, dtype=float)
    if values.shape != weights.shape or values.ndim != 1 or values.size == 0:
        raise InputError(f"values {values.shape} and weights {weights.shape} must be 1-d arrays of one length")
    if np.any(weights < 0) or not np.all(np.isfinite(weights)):
        raise InputError("weights must be finite and >= 0")
    order = np.argsort(values, kind="stable")
    return values[order], np.cumsum(weights[order].astype(np.longdouble))


def quantile_interval(values, weights, probs, weight_rtol: float = 0.0):
    """The q-quantiles of a discrete law as an interval ``[Q^-(q), Q^+(q)]``, enclosing the rounding of the CDF.

    Convention: ``Q^-(q) = min{v : F(v) >= q}`` (the lower quantile, numpy's ``inverted_cdf``) and
    ``Q^+(q) = inf{v : F(v) > q}`` (the upper quantile); every ``v`` in between has ``P(X < v) <= q <= P(X <= v)``,
    i.e. is a q-quantile. They differ exactly where the distribution function is flat at the level,
    ``F = q`` on ``[Q^-, Q^+)``: then the quantile is an interval, not a number. (The law of p_k at lambda = 0.9 has
    ``F = 0.9`` exactly on a stretch: the event {arrival at step k} has probability 0.9 and puts p_k below every
    value reached after a final loss.) ``F`` is summed in extended precision with the rounding bound ``eps_i`` of
    :func:`sum_rounding_bound`; the returned ``lo = min{v_i : F_hat_i >= q - eps_i} <= Q^-`` and
    ``hi = min{v_i : F_hat_i - eps_i > q} >= Q^+`` enclose the exact interval, and ``lo == hi`` proves
    ``Q^- = Q^+``. A level within the rounding of a flat stretch reads as flat (both ends reported).

    Parameters
    ----------
    values, weights : array_like (n,)
        Support points and their probabilities (summing to 1 up to their rounding; not renormalised).
    probs : array_like (k,)
        Levels q in (0, 1).
    weight_rtol : float
        Relative error bound of each weight (see :func:`sum_rounding_bound`).

    Returns
    -------
    (lo, hi) : tuple of ndarray (k,)
        Lower and upper ends; ``hi`` is the largest support point if no prefix sum exceeds q with certainty.

    Raises
    ------
    InputError
        For a level outside (0, 1), or malformed values or weights.
    """
    probs = np.atleast_1d(np.asarray(probs, dtype=float))
    if np.any((probs <= 0) | (probs >= 1)):
        raise InputError(f"quantile levels {probs.tolist()} must lie in (0, 1)")
    v, F = _sorted_cdf(values, weights)
    eps = F * np.longdouble(sum_rounding_bound(len(v), weight_rtol))
    q = probs.astype(np.longdouble)[:, None]
    reach = F[None, :] >= q - eps[None, :]
    above = F[None, :] - eps[None, :] > q
    lo = v[np.where(reach.any(axis=1), reach.argmax(axis=1), len(v) - 1)]
    hi = v[np.where(above.any(axis=1), above.argmax(axis=1), len(v) - 1)]
    return lo, hi


def exceedance_probability(values, weights, level: float, level_rtol: float = 0.0, weight_rtol: float = 0.0):
    """``P(X > level)`` of a discrete law, with a bound on its error.

    Summed in extended precision (:func:`sum_rounding_bound`); a support point within ``level_rtol |level|`` of
    the level (known to that relative accuracy) could lie on either side, so its weight is added to the bound.

    Parameters
    ----------
    values, weights : array_like (n,)
        Support points and probabilities.
    level : float
        The level (e.g. the mean E X).
    level_rtol : float
        Relative error bound of ``level``.
    weight_rtol : float
        Relative error bound of each weight.

    Returns
    -------
    (p, err) : (float, float)
        The probability of the points above the level, and a bound on ``|p - P(X > level)|``.
    """
    values, weights = np.asarray(values, dtype=float), np.asarray(weights, dtype=float)
    if values.shape != weights.shape or values.ndim != 1:
        raise InputError(f"values {values.shape} and weights {weights.shape} must be 1-d arrays of one length")
    above = values > level
    near = np.abs(values - level) <= level_rtol * abs(level)
    p = np.sum(weights[above].astype(np.longdouble))
    ambiguous = float(np.sum(weights[near].astype(np.longdouble)))
    return float(p), float(p) * sum_rounding_bound(len(values), weight_rtol) + ambiguous
