"""The scalar equations of the report (section 4): eq. (6) and the bounds (9)-(10) on E(p_k).

The system is x_{k+1} = a x_k + v_k, y_k = x_k + w_k (eq. 5) with Var v = R1, Var w = R2
and i.i.d. arrivals gamma_k ~ Bernoulli(lambda); p_k is the prediction-error variance.
"""

from __future__ import annotations

import numpy as np

from ...errors import InputError

__all__ = [
    "critical_probability",
    "riccati_step",
    "lower_bound_sequence",
    "lower_bound_limit",
    "upper_bound_sequence",
    "report_estimate_sequence",
    "estimate_with_true_mean",
    "condition_11_printed",
    "condition_11_corrected",
    "exact_mean_enumeration",
    "sinopoli_operator",
    "mare_fixed_point",
]


def critical_probability(a) -> float:
    """Critical arrival probability lambda_c = 1 - 1/|a|^2 (section 4).

    Parameters
    ----------
    a : float or array_like (n, n)
        System coefficient; for a matrix, |a| is its spectral radius.

    Returns
    -------
    float
        lambda_c.
    """
    rho = np.max(np.abs(np.linalg.eigvals(np.atleast_2d(np.asarray(a, dtype=float)))))
    return float(1.0 - 1.0 / rho**2)


def riccati_step(p, gamma, a, R1, R2):
    """One step of eq. (6): p_{k+1} = a^2 p + R1 - gamma a^2 p^2 / (p + R2), elementwise.

    Parameters
    ----------
    p : array_like
        Current variances p_k.
    gamma : float or array_like
        Arrival indicator(s) (0 = lost, 1 = arrived), broadcast against ``p``.
    a, R1, R2 : float
        System coefficient, process and measurement noise variances.

    Returns
    -------
    ndarray
        p_{k+1}.
    """
    p = np.asarray(p, dtype=float)
    return a * a * p + R1 - gamma * a * a * p * p / (p + R2)


def lower_bound_sequence(s0, a, R1, lam, n_steps) -> np.ndarray:
    """Lower bound of eq. (10): s_{k+1} = (1 - lambda) a^2 s_k + R1, for k = 0..n_steps.

    Parameters
    ----------
    s0 : float
        s_0 (= E(p_0)).
    a, R1 : float
        System coefficient and process noise variance.
    lam : float
        Arrival probability lambda.
    n_steps : int
        Number of steps.

    Returns
    -------
    ndarray (n_steps + 1,)
        s_0..s_{n_steps} (inf once it overflows).
    """
    s = np.empty(n_steps + 1)
    s[0] = s0
    with np.errstate(over="ignore"):
        for k in range(n_steps):
            s[k + 1] = (1.0 - lam) * a * a * s[k] + R1
    return s


def lower_bound_limit(a, R1, lam) -> float:
    """Limit of the lower bound (10): the fixed point s* = R1 / (1 - (1 - lambda) a^2) of s -> (1 - lambda) a^2 s + R1.

    Parameters
    ----------
    a, R1 : float
        System coefficient and process noise variance.
    lam : float
        Arrival probability lambda, with (1 - lambda) a^2 < 1 (otherwise s_k diverges).

    Returns
    -------
    float
        s*.
    """
    growth = (1.0 - lam) * a * a
    return R1 / (1.0 - growth)


def upper_bound_sequence(r0, a, R1, R2, lam, n_steps) -> np.ndarray:
    """Upper bound of eq. (9): r_{k+1} = a^2 r_k + R1 - lambda a^2 r_k^2 / (r_k + R2).

    This is the modified Riccati iteration of Sinopoli et al.

    Parameters
    ----------
    r0 : float
        r_0 (= E(p_0)).
    a, R1, R2 : float
        System coefficient, process and measurement noise variances.
    lam : float
        Arrival probability lambda.
    n_steps : int
        Number of steps.

    Returns
    -------
    ndarray (n_steps + 1,)
        r_0..r_{n_steps}; a diverged bound stays inf.
    """
    r = np.empty(n_steps + 1)
    r[0] = r0
    with np.errstate(over="ignore"):
        for k in range(n_steps):
            # a diverged bound stays inf (inf/inf would give NaN)
            r[k + 1] = np.inf if np.isinf(r[k]) else a * a * r[k] + R1 - lam * a * a * r[k] ** 2 / (r[k] + R2)
    return r


def report_estimate_sequence(m0, s, r, a, R1, R2, lam, printed=False) -> np.ndarray:
    """The report's rough estimate of E(p_k) (section 4, after Fig. 1), built on eq. (8).

    With p^2/(p+R2) = p - R2 + R2^2/(p+R2), eq. (8) is exactly

        E(p_{k+1}) = a^2 E(p_k) + R1 - a^2 lambda (E(p_k) - R2 + R2^2 E[(p_k+R2)^{-1}]),

    and the report replaces E[(p_k+R2)^{-1}] by the average of (s_k+R2)^{-1}
    and (r_k+R2)^{-1}, with its own previous estimate for E(p_k).

    Parameters
    ----------
    m0 : float
        Initial value E(p_0).
    s, r : array_like (n,)
        The bounds s_k (10) and r_k (9).
    a, R1, R2 : float
        System coefficient, process and measurement noise variances.
    lam : float
        Arrival probability lambda.
    printed : bool
        If True use the formula as printed,
        ``+ a^2 lambda (E(p_k) - R2 - R2 E[(p_k+R2)^{-1}])`` (an erratum).

    Returns
    -------
    ndarray (n,)
        The estimate for k = 0..n-1.
    """
    m = np.empty(len(s))
    m[0] = m0
    for k in range(len(s) - 1):
        inv = 0.5 * (1.0 / (s[k] + R2) + 1.0 / (r[k] + R2))
        if printed:
            m[k + 1] = a * a * m[k] + R1 + a * a * lam * (m[k] - R2 - R2 * inv)
        else:
            m[k + 1] = a * a * m[k] + R1 - a * a * lam * (m[k] - R2 + R2 * R2 * inv)
    return m


def estimate_with_true_mean(mean, s, r, a, R1, R2, lam) -> np.ndarray:
    """The report's estimate of E(p_{k+1}) (section 4, the rewritten eq. (8)) with the exact E(p_k) plugged in.

    E(p_{k+1}) ~ a^2 E(p_k) + R1 - a^2 lambda (E(p_k) - R2 + R2^2 (1/(s_k + R2) + 1/(r_k + R2)) / 2),
    i.e. the other reading of the report's recipe (it does not say which E(p_k) goes on the right).

    Parameters
    ----------
    mean, s, r : array_like (n,)
        Exact E(p_k) and the bounds (10), (9).
    a, R1, R2, lam : float
        The scalar system and the arrival probability.

    Returns
    -------
    ndarray (n,)
        The estimate, with the estimate at k = 0 equal to E(p_0).
    """
    mean, s, r = (np.asarray(v, dtype=float) for v in (mean, s, r))
    inv = 0.5 * (1.0 / (s + R2) + 1.0 / (r + R2))
    out = np.empty_like(mean)
    out[0] = mean[0]
    out[1:] = a * a * mean[:-1] + R1 - a * a * lam * (mean[:-1] - R2 + R2 * R2 * inv[:-1])
    return out
def condition_11_printed(p, lam, a, R2):
    """Right-hand side minus left-hand side of eq. (11) as printed: lambda p (2 - R2 - p)/(p + R2)^2 - (1 - 1/a^2).

    Positive where the printed condition holds. It is eq. (11) of the report, i.e. the printed condition
    before (11) (p > a^2 p + lambda a^2 p^2 (p + R2)^-2 (p - 2 + R2)) divided by a^2 p and rearranged, so
    the two printed forms are one error (erratum E2).

    Parameters
    ----------
    p : float or array_like
        The scalar p~ > 0.
    lam : float
        Arrival probability.
    a, R2 : float
        System coefficient and measurement noise variance.

    Returns
    -------
    float or ndarray
    """
    p = np.asarray(p, dtype=float)
    return lam * p * (2.0 - R2 - p) / (p + R2) ** 2 - (1.0 - 1.0 / (a * a))


def condition_11_corrected(p, lam, a, R1, R2):
    """Margin of the corrected eq. (11): lambda p/(p + R2) - R1/(a^2 p) - (1 - 1/a^2).

    From p > phi(K~, p) = a^2 p + R1 - lambda a^2 p^2/(p + R2) (Sinopoli's operator at the optimal gain,
    K~ = -a p/(p + R2)) divided by a^2 p. Positive where the condition holds; the MARE has a positive
    fixed point iff the margin is positive for some p > 0.

    Parameters
    ----------
    p : float or array_like
        The scalar p~ > 0.
    lam : float
        Arrival probability.
    a, R1, R2 : float
        System coefficient, process and measurement noise variances.

    Returns
    -------
    float or ndarray
    """
    p = np.asarray(p, dtype=float)
    return lam * p / (p + R2) - R1 / (a * a * p) - (1.0 - 1.0 / (a * a))


def exact_mean_enumeration(p0, a, R1, R2, lam, n_steps, return_distribution=False):
    """E(p_k) for k = 0..n_steps by enumerating all 2^k arrival sequences of eq. (6).

    The support doubles each step (2^n_steps points at the end), so this is for
    short horizons only; it is the ground truth that validates the other methods.

    Parameters
    ----------
    p0 : float
        Deterministic p_0.
    a, R1, R2 : float
        System coefficient, process and measurement noise variances.
    lam : float
        Arrival probability lambda.
    n_steps : int
        Horizon (at most 24).
    return_distribution : bool
        Also return the support and weights of p_{n_steps}.

    Returns
    -------
    means : ndarray (n_steps + 1,)
        E(p_0)..E(p_{n_steps}).
    values, weights : ndarray (2^n_steps,)
        Only with ``return_distribution``: the support of p_{n_steps} and its probabilities.

    Raises
    ------
    InputError
        If ``n_steps > 24``.
    """
    if n_steps > 24:
        raise InputError(f"exact enumeration over 2^{n_steps} sequences is too large; use n_steps <= 24")
    values = np.array([float(p0)])
    weights = np.array([1.0])
    means = [float(p0)]
    for _ in range(n_steps):
        values = np.concatenate([riccati_step(values, 0.0, a, R1, R2), riccati_step(values, 1.0, a, R1, R2)])
        weights = np.concatenate([(1.0 - lam) * weights, lam * weights])
        means.append(float(weights @ values))
    means = np.array(means)
    return (means, values, weights) if return_distribution else means


def sinopoli_operator(K, p, lam, a, R1, R2):
    """Sinopoli's operator phi(K, p) for the scalar system (section 4, Lemma 1).

    phi(K, p) = (1 - lambda)(a^2 p + R1) + lambda ((a + K)^2 p + R1 + K R2 K); its minimum
    over K is the modified Riccati map (9), attained at K~ = -a p / (p + R2).

    Parameters
    ----------
    K : float or array_like
        Gain.
    p : float or array_like
        Variance.
    lam : float
        Arrival probability.
    a, R1, R2 : float
        System coefficient, process and measurement noise variances.

    Returns
    -------
    float or ndarray
        phi(K, p).
    """
    return (1 - lam) * (a * a * p + R1) + lam * ((a + K) ** 2 * p + R1 + K * R2 * K)


def mare_fixed_point(a, R1, R2, lam) -> float:
    """The fixed point r* of the modified Riccati iteration (9), i.e. the positive root of the MARE.

    r = a^2 r + R1 - lambda a^2 r^2/(r + R2) is, times (r + R2),
    (1 - (1 - lambda) a^2) r^2 + (R2 - a^2 R2 - R1) r - R1 R2 = 0.

    Parameters
    ----------
    a, R1, R2 : float
        System coefficient, process and measurement noise variances.
    lam : float
        Arrival probability lambda.

    Returns
    -------
    float
        r*, or inf when (1 - lambda) a^2 >= 1 (lambda <= lambda_c: the iteration diverges).
    """
    c = 1.0 - (1.0 - lam) * a * a
    if c <= 0.0:
        return float(np.inf)
    b = R2 - a * a * R2 - R1
    return float((-b + np.sqrt(b * b + 4.0 * c * R1 * R2)) / (2.0 * c))
