"""Packet-loss channels: i.i.d. Bernoulli and Gilbert-Elliott (two-state Markov).

All samplers are vectorised over sample paths: they return boolean arrays of
shape ``(n_paths, horizon)`` (or ``(n_paths, horizon, n_sensors)``) where
``True`` means the packet arrived (gamma_k = 1).

Gilbert-Elliott convention (Wu, Shi, Anderson, Johansson): the channel state is
gamma_k itself; ``p = P(gamma_{k+1} = 0 | gamma_k = 1)`` is the failure rate and
``q = P(gamma_{k+1} = 1 | gamma_k = 0)`` the recovery rate.
"""

from __future__ import annotations

import itertools

import numpy as np

__all__ = [
    "iid_arrivals",
    "gilbert_elliott_arrivals",
    "gilbert_elliott_stationary",
    "arrival_patterns",
]


def _check_prob(name, value):
    arr = np.asarray(value, dtype=float)
    if np.any(~np.isfinite(arr)) or np.any(arr < 0) or np.any(arr > 1):
        raise ValueError(f"{name} must be a probability in [0, 1], got {value!r}")
    return arr


def iid_arrivals(rng: np.random.Generator, n_paths: int, horizon: int, prob) -> np.ndarray:
    """I.i.d. Bernoulli arrivals.

    Parameters
    ----------
    rng : numpy.random.Generator
        Source of the uniforms.
    n_paths, horizon : int
        Number of sample paths and of time steps.
    prob : float or sequence of float
        Arrival probability lambda; a sequence gives one independent channel per sensor.

    Returns
    -------
    ndarray of bool
        Shape ``(n_paths, horizon)`` for a scalar ``prob`` or ``(n_paths, horizon, n_sensors)``
        for a sequence; True where the packet arrived.

    Raises
    ------
    ValueError
        If a probability is not in [0, 1].
    """
    prob = _check_prob("prob", prob)
    if prob.ndim == 0:
        return rng.random((n_paths, horizon)) < prob
    return rng.random((n_paths, horizon, prob.size)) < prob.reshape(1, 1, -1)


def gilbert_elliott_stationary(p: float, q: float) -> tuple[float, float]:
    """Stationary probabilities ``(P(gamma=1), P(gamma=0)) = (q/(p+q), p/(p+q))``.

    Parameters
    ----------
    p, q : float
        Failure rate ``P(gamma_{k+1} = 0 | gamma_k = 1)`` and recovery rate
        ``P(gamma_{k+1} = 1 | gamma_k = 0)``.

    Returns
    -------
    tuple of float
        ``(P(gamma = 1), P(gamma = 0))``.

    Raises
    ------
    ValueError
        If a rate is not in [0, 1], or ``p + q = 0`` (no unique stationary law).
    """
    p, q = float(_check_prob("p", p)), float(_check_prob("q", q))
    if p + q == 0:
        raise ValueError("p + q = 0: the Gilbert-Elliott chain has no unique stationary law")
    return q / (p + q), p / (p + q)


def gilbert_elliott_arrivals(
    rng: np.random.Generator, n_paths: int, horizon: int, p: float, q: float, initial="stationary"
) -> np.ndarray:
    """Gilbert-Elliott arrivals, shape ``(n_paths, horizon)``.

    The loop runs over time only; every step is batched over paths.

    Parameters
    ----------
    rng : numpy.random.Generator
        Source of the uniforms (one per path and step).
    n_paths, horizon : int
        Number of sample paths and of time steps.
    p, q : float
        Failure and recovery rates (module docstring).
    initial : {"stationary", 0, 1}
        ``gamma_0`` drawn from the stationary law, or fixed.

    Returns
    -------
    ndarray of bool, shape ``(n_paths, horizon)``
        True where the packet arrived.

    Raises
    ------
    ValueError
        If a rate is not in [0, 1] or ``initial`` is not one of the above.
    """
    p, q = float(_check_prob("p", p)), float(_check_prob("q", q))
    uniforms = rng.random((n_paths, horizon))
    out = np.empty((n_paths, horizon), dtype=bool)
    if initial == "stationary":
        state = uniforms[:, 0] < gilbert_elliott_stationary(p, q)[0]
    elif initial in (0, 1):
        state = np.full(n_paths, bool(initial))
    else:
        raise ValueError(f"initial must be 'stationary', 0 or 1, got {initial!r}")
    out[:, 0] = state
    for k in range(1, horizon):
        # stay received with prob 1-p, recover with prob q
        state = np.where(state, uniforms[:, k] >= p, uniforms[:, k] < q)
        out[:, k] = state
    return out


def arrival_patterns(probs) -> tuple[np.ndarray, np.ndarray]:
    """All arrival patterns of independent sensors and their probabilities.

    Parameters
    ----------
    probs : sequence of float
        Arrival probability of each of the ``m`` sensors.

    Returns
    -------
    patterns : ndarray of bool, shape ``(2**m, m)``
        Every pattern ``s`` (True: sensor ``j`` delivered).
    weights : ndarray, shape ``(2**m,)``
        ``weights[i] = prod_j probs_j**s_j (1-probs_j)**(1-s_j)``.

    Raises
    ------
    ValueError
        If a probability is not in [0, 1].
    """
    probs = _check_prob("probs", probs).ravel()
    patterns = np.array(list(itertools.product([False, True], repeat=probs.size)), dtype=bool)
    weights = np.prod(np.where(patterns, probs, 1.0 - probs), axis=1)
    return patterns, weights
