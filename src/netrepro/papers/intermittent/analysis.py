"""How the report's figures and statements are read: settling, forgetting, relative errors, growth.

Small measurements on curves k = 0..n-1 (the bounds s_k, r_k, the report's estimate, the exact E(p_k)),
used to turn the report's words ('reached around k = 25', 'close to its real curve', 'diverges') into
numbers. They make no assumption about where the curves come from.
"""

from __future__ import annotations

import numpy as np

__all__ = ["settle_step", "forget_step", "worst_relative_error", "growth_ratio"]


def settle_step(x, limit, reading) -> int:
    """First k from which a curve stays within ``reading`` of its limit (how Fig. 1 is read: 'reached').

    Parameters
    ----------
    x : array_like (n,)
        The curve, k = 0..n-1.
    limit : float
        Its limit.
    reading : float
        Absolute reading precision: the curve has 'reached' its value once the rest of it is within this.

    Returns
    -------
    int
        The smallest k with |x_j - limit| <= reading for every j >= k.
    """
    idx = np.flatnonzero(np.abs(np.asarray(x, dtype=float) - limit) > reading)
    return int(idx[-1] + 1) if idx.size else 0


def forget_step(x, y, rel) -> int:
    """First k from which two curves agree within ``rel`` relative (the transient of the initial value).

    Parameters
    ----------
    x, y : array_like (n,)
        Two curves, k = 0..n-1 (e.g. started from two values of p_0).
    rel : float
        Relative agreement, |x_j / y_j - 1| <= rel.

    Returns
    -------
    int
        The smallest k with agreement at every j >= k.
    """
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    idx = np.flatnonzero(np.abs(x - y) > rel * np.abs(y))
    return int(idx[-1] + 1) if idx.size else 0


def worst_relative_error(est, ref):
    """The signed relative error est/ref - 1 of largest magnitude, and its index.

    Parameters
    ----------
    est, ref : array_like (n,)
        Estimate and reference (ref > 0).

    Returns
    -------
    (float, int)
    """
    err = np.asarray(est, dtype=float) / np.asarray(ref, dtype=float) - 1.0
    k = int(np.argmax(np.abs(err)))
    return float(err[k]), k


def growth_ratio(mean) -> float:
    """E(p_T) / E(p_{T-1}) at the last k of a curve: the one-step growth factor of a diverging mean.

    For the two-sensor recursion (14) below the boundary, E(p_k) = gamma^k p_0 + sum_j gamma^j b_{k-1-j}
    with gamma = (1 - lambda1)(1 - lambda2) a^2 > 1 and b bounded (after an arrival p is bounded when C_i
    is invertible), so the ratio tends to gamma.

    Parameters
    ----------
    mean : array_like (n,), n >= 2
        The curve.

    Returns
    -------
    float
    """
    mean = np.asarray(mean, dtype=float)
    return float(mean[-1] / mean[-2])
