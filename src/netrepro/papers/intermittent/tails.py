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
    "weighted_quantiles",
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


def weighted_quantiles(values, weights, probs) -> np.ndarray:
    """Quantiles of a discrete law: the smallest support point v with P(X <= v) >= q, for each q.

    Parameters
    ----------
    values, weights : array_like (n,)
        Support and probabilities (summing to 1).
    probs : array_like (k,)
        Levels q in (0, 1].

    Returns
    -------
    ndarray (k,)
    """
    values, weights = np.asarray(values, dtype=float), np.asarray(weights, dtype=float)
    order = np.argsort(values, kind="stable")
    cdf = np.cumsum(weights[order])
    cdf /= cdf[-1]
    idx = np.searchsorted(cdf, np.asarray(probs, dtype=float) * (1 - 1e-15), side="left")
    return values[order][np.minimum(idx, len(values) - 1)]
