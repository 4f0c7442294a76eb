"""The two-sensor stability region of section 5 (after Liu & Goldsmith 2004).

Two scalar sensors with C1 = C2 = 1 and independent arrivals (probabilities lambda1,
lambda2); the error variance follows eq. (14). The region {(lambda1, lambda2): E(p_k)
bounded} is bounded below by a closed form and above by the LMI condition (16).
"""

from __future__ import annotations

from collections import Counter

import numpy as np

from ...engines.channels import arrival_patterns

__all__ = ["two_sensor_lower_bound", "two_sensor_modes", "two_sensor_upper_bound"]


def two_sensor_lower_bound(lambda1, a) -> np.ndarray:
    """Lower bound lambda2c_lower = max(1 - 1/(alpha^2 (1 - lambda1)), 0), alpha = |a| (section 5).

    Parameters
    ----------
    lambda1 : float or array_like
        Arrival probability of sensor 1.
    a : float
        System coefficient.

    Returns
    -------
    ndarray
        lambda2c_lower for each lambda1.
    """
    lambda1 = np.asarray(lambda1, dtype=float)
    with np.errstate(divide="ignore"):
        return np.maximum(1.0 - 1.0 / (a * a * (1.0 - lambda1)), 0.0)


def two_sensor_modes():
    """Output rows delivered in each arrival pattern of eq. (14).

    Returns
    -------
    list
        ``[None, [[1]], [[1]], [[1], [1]]]``, ordered as
        :func:`~netrepro.engines.channels.arrival_patterns` ([F,F],[F,T],[T,F],[T,T]).
    """
    return [None, np.array([[1.0]]), np.array([[1.0]]), np.array([[1.0], [1.0]])]


def two_sensor_upper_bound(lambda1_grid, a, tol=1e-5) -> list[dict]:
    """lambda2c_upper(lambda1) = inf{lambda2 : exists K, K1, K2, X > 0 with X > phi(K, K1, K2, X)} (eq. 16).

    Feasibility of eq. (16) is decided by the LMI of
    :class:`~netrepro.engines.lmi.MareStabilizabilityLMI` (one parametrised
    problem for the whole sweep) and certified by the spectral radius of the
    closed-loop second-moment operator; lambda2 is found by a bisection at each grid
    point bracketed from the closed-form lower bound of that point (so sharding the grid
    cannot change any answer, and a plain bisection would return the same lattice point).
    The noise terms of phi do not affect feasibility (the condition is
    homogeneous in X), so the bound depends on a and the C_i only.

    Parameters
    ----------
    lambda1_grid : array_like
        Values of lambda1.
    a : float
        System coefficient.
    tol : float
        Bisection tolerance on lambda2.

    Returns
    -------
    list of dict
        One row per lambda1 with ``lambda1, lambda2c_upper, bracket_lower, n_solves,
        status_at_threshold, certified_radius, statuses_seen`` (every solver status met in
        the bisection).
    """
    from ...engines.lmi import MareStabilizabilityLMI, bisect_bracketed  # cvxpy: only the steps that solve LMIs

    lmi = MareStabilizabilityLMI([[a]], two_sensor_modes())
    grid = np.asarray(lambda1_grid, dtype=float)
    outcomes = {float(lam1): {} for lam1 in grid}

    def make_predicate(lam1):
        def feasible(lam2):
            _, weights = arrival_patterns([lam1, lam2])
            out = lmi.solve(weights)
            outcomes[float(lam1)][lam2] = out
            return out.certified

        return feasible

    # each point's bisection starts from its own closed-form lower bound (a guess only: the LMI still
    # decides both ends of the final bracket, and for a monotone predicate the answer is the plain
    # bisection's, engines.lmi.bisect_bracketed); nothing depends on the neighbours, so no shard
    # split can change an answer
    guesses = two_sensor_lower_bound(grid, a)
    results = [bisect_bracketed(make_predicate(lam1), 0.0, 1.0, guess, 0.0, tol=tol)  # one lattice cell each side
               for lam1, guess in zip(grid, guesses)]
    rows = []
    for lam1, res in zip(grid, results):
        seen_outcomes = outcomes[float(lam1)]
        at = seen_outcomes.get(res.threshold)
        seen = Counter(o.status for o in seen_outcomes.values()).most_common()
        if at is None:  # nothing certified: say what the solver said at the feasible end of the bracket
            end = seen_outcomes.get(1.0)
            status = f"not certified at lambda2 = 1 ({end.status if end else 'not solved'})"
        else:
            status = at.status
        rows.append({
            "lambda1": lam1,
            "lambda2c_upper": res.threshold,
            "bracket_lower": res.lower,
            "n_solves": res.n_evals,
            "status_at_threshold": status,
            "certified_radius": at.certificate_value if at else np.nan,
            "statuses_seen": "; ".join(f"{k}: {v}" for k, v in seen),
        })
    return rows
