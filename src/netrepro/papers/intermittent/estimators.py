"""The conditional Monte Carlo estimator of E(p_k) for eq. (6) (one sensor) and eq. (14) (two sensors).

The plain sample mean of p_k is heavy-tailed (infinite variance when pi_0 a^4 >= 1); this
estimator conditions on the time of the last arrival and averages bounded quantities only.
"""

from __future__ import annotations

import numpy as np

from ...engines.channels import arrival_patterns

__all__ = ["loss_propagation", "conditional_mean_weights", "conditional_mean_paths", "loss_path_terms"]


def loss_propagation(x, m, a, R1):
    """Loss propagation L^m(x) = a^{2m} x + R1 (a^{2m} - 1)/(a^2 - 1): m steps of eq. (6) with gamma = 0.

    Parameters
    ----------
    x : float or array_like
        Variance before the losses.
    m : int or array_like
        Number of consecutive losses.
    a, R1 : float
        System coefficient and process noise variance.

    Returns
    -------
    float or ndarray
        L^m(x).
    """
    a2m = (a * a) ** np.asarray(m, dtype=float)
    growth = m * 1.0 if np.isclose(a * a, 1.0) else (a2m - 1.0) / (a * a - 1.0)
    return a2m * x + R1 * growth


def conditional_mean_weights(horizon, a, pi_loss):
    """Weights W[j, k] = pi_loss^{k-1-j} a^{2(k-1-j)} for j < k (else 0).

    Used by :func:`conditional_mean_paths`: the contribution to E(p_k) of
    the last arrival happening at time j (the linear part of L^{k-1-j}, eq. (6) with gamma = 0).

    Parameters
    ----------
    horizon : int
        T, the last time.
    a : float
        System coefficient.
    pi_loss : float
        Probability that no packet arrives in one step.

    Returns
    -------
    ndarray (horizon, horizon + 1)
        W.
    """
    j = np.arange(horizon)[:, None]
    k = np.arange(horizon + 1)[None, :]
    m = k - 1 - j
    with np.errstate(over="ignore"):
        w = np.where(m >= 0, (pi_loss * a * a) ** np.maximum(m, 0), 0.0)
    return w


def conditional_mean_paths(p_paths, p0, a, R1, sensor_vars, probs):
    """Per-path unbiased estimator of E(p_k) that averages only bounded quantities.

    Condition on the time j of the last step before k at which at least one
    packet arrived. The sequence after j is pure loss, with known probability
    pi_0^{k-1-j} (pi_0 = P(no packet)), and p_k = L^{k-1-j}(p_{j+1}) with L the
    loss propagation. Since p_j is independent of the arrivals at and after j,

    .. math::

        E(p_k) = \\sum_{j<k} \\pi_0^{k-1-j} E\\big[\\sum_{S \\ne \\emptyset} \\pi_S
                 L^{k-1-j}(\\varphi_S(p_j))\\big] + \\pi_0^k L^k(p_0),

    where phi_S(p) = a^2 (p^{-1} + sum_{i in S} 1/sigma_i^2)^{-1} + R1 is bounded
    by a^2 max_i sigma_i^2 + R1 for every S (a single sensor i alone gives a^2 sigma_i^2 + R1 at most).
    The returned per-path quantity Y_k has
    E(Y_k) = E(p_k) and is bounded, so its sample mean obeys the CLT,
    unlike the sample mean of p_k (heavy-tailed; infinite variance when
    pi_0 a^4 >= 1).

    Parameters
    ----------
    p_paths : array (N, T+1)
        Sample paths p_0..p_T of the recursion (eq. (6) or (14)).
    sensor_vars : sequence of float
        Measurement noise variances of the (scalar, C = 1) sensors.
    probs : sequence of float
        Arrival probabilities of the sensors.
    p0 : float
        Deterministic p_0.
    a, R1 : float
        System coefficient and process noise variance.

    Returns
    -------
    ndarray (N, T+1)
        The per-path estimates Y_k.
    """
    p_paths = np.asarray(p_paths, dtype=float)
    N, T1 = p_paths.shape
    T = T1 - 1
    patterns, weights = arrival_patterns(probs)
    pi0 = float(weights[~patterns.any(axis=1)].sum())
    inv_vars = 1.0 / np.asarray(sensor_vars, dtype=float)
    p = p_paths[:, :T]
    mixed = np.zeros_like(p)  # sum over S != {} of pi_S phi_S(p_j)
    with np.errstate(divide="ignore"):
        for pattern, weight in zip(patterns, weights):
            if not pattern.any():
                continue
            post = 1.0 / (1.0 / p + inv_vars[pattern].sum())
            mixed += weight * (a * a * post + R1)
    W = conditional_mean_weights(T, a, pi0)  # (T, T+1)
    with np.errstate(over="ignore", invalid="ignore"):
        return mixed @ W + loss_path_terms(T, p0, a, R1, pi0)[None, :]


def loss_path_terms(horizon, p0, a, R1, pi_loss):
    """The part of E(p_k) that needs no expectation: R1 terms of the loss runs and the all-loss path.

    In the last-arrival decomposition (eqs. (6), (14))

    .. math::

        E(p_k) = \\sum_{j<k} \\pi_0^{m} \\big(a^{2m} \\mu_j + (1-\\pi_0) c_m\\big) + \\pi_0^k (a^{2k} p_0 + c_k),
        \\quad m = k-1-j,\\ c_m = R_1 (a^{2m}-1)/(a^2-1),

    with mu_j = E[sum_{S != {}} pi_S phi_S(p_j)], this returns everything but the mu_j terms.
    Written with (pi0 a^2)^m and pi0^m separately so that no 0 * inf can occur.

    Parameters
    ----------
    horizon : int
        T, the last time.
    p0 : float
        Deterministic p_0.
    a, R1 : float
        System coefficient and process noise variance.
    pi_loss : float
        pi_0, probability that no packet arrives in one step.

    Returns
    -------
    ndarray (horizon + 1,)
        The deterministic terms for k = 0..T.
    """
    pi0 = pi_loss
    ks = np.arange(horizon + 1)
    with np.errstate(over="ignore", invalid="ignore"):
        grow = (pi0 * a * a) ** ks.astype(float)  # (pi0 a^2)^k
        shrink = pi0 ** ks.astype(float)  # pi0^k
        if np.isclose(a * a, 1.0):
            r1_terms = R1 * ks * shrink
        else:
            r1_terms = R1 * (grow - shrink) / (a * a - 1.0)  # pi0^m R1 (a^{2m} - 1)/(a^2 - 1)
        cumulative = np.concatenate([[0.0], np.cumsum(r1_terms[:-1])])  # sum over m = 0..k-1
        return (1.0 - pi0) * cumulative + p0 * grow + r1_terms
