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

    Feasibility of eq. (16) is decided by the shared solve-and-certify path
    (:meth:`~netrepro.engines.lmi.MareStabilizabilityLMI.certify`, one parametrised problem for the
    whole sweep): ``feasible`` only when our own eigenvalue check of the returned point passes
    (whatever the solver status), ``infeasible`` only with a certificate (a checked dual
    certificate, or the necessary condition (1 - lambda1)(1 - lambda2) a^2 >= 1 computed without
    the LMI), else ``undecided`` (never counted either way). lambda2 is found by
    :func:`~netrepro.engines.certify.bisect_certified` at each grid point, started from the
    closed-form lower bound of that point (a guess only: it changes the number of solves, never
    the answer, so sharding the grid cannot change any answer). Both ends of each bracket are
    certified; where lambda2 = 0 is already certified feasible (one sensor suffices), the
    threshold is 0 and there is no infeasible end. The noise terms of phi do not affect
    feasibility, though the condition is not homogeneous in X: for fixed gains it reads
    X > L(X) + N with L linear and N >= 0, and a strict solution of the noise-free X > L(X) scaled
    by a large t also solves X > L(X) + N (conversely any solution with noise solves the noise-free
    one). So the LMI solved here is the noise-free one and the bound depends on a and the C_i only.
    With C_1 = C_2 = 1 invertible it is moreover the closed form of :func:`two_sensor_lower_bound`
    (gains -a/C_i cancel the error in every mode with an arrival).

    Parameters
    ----------
    lambda1_grid : array_like
        Values of lambda1.
    a : float
        System coefficient.
    tol : float
        Bisection lattice spacing on lambda2.

    Returns
    -------
    list of dict
        One row per lambda1: ``lambda1, lambda2c_upper`` (the certified-feasible end),
        ``bracket_lower`` (the certified-infeasible end, nan if lambda2 = 0 is feasible),
        ``certified`` (the threshold is bracketed by certified ends, or is 0 with lambda2 = 0
        certified feasible), ``upper_certified_by``, ``lower_certified_by`` (the evidence of each
        end), ``upper_slack`` (smallest eigenvalue margin of the point at the feasible end),
        ``n_solves``, ``n_undecided``, ``status_at_threshold`` (the solver's status at the feasible
        end, information only) and ``statuses_seen`` (every solver status met).
    """
    from ...engines.certify import bisect_certified  # cvxpy: only the steps that solve LMIs
    from ...engines.lmi import MareStabilizabilityLMI

    lmi = MareStabilizabilityLMI([[a]], two_sensor_modes())
    grid = np.asarray(lambda1_grid, dtype=float)

    def make_decide(lam1):
        def decide(lam2):
            _, weights = arrival_patterns([lam1, lam2])
            return lmi.certify(weights)  # necessary condition: w_loss a^2 >= 1 (+1e-9) -> infeasible

        return decide

    guesses = two_sensor_lower_bound(grid, a)
    rows = []
    for lam1, guess in zip(grid, guesses):
        br = bisect_certified(make_decide(lam1), 0.0, 1.0, tol=tol, feasible_above=True, guess=guess)
        up = br.verdicts.get(br.feasible_end) if np.isfinite(br.feasible_end) else None
        low = br.verdicts.get(br.infeasible_end) if np.isfinite(br.infeasible_end) else None
        seen = Counter(v.solver_status for v in br.verdicts.values()).most_common()
        at_zero = up is not None and br.feasible_end == 0.0
        if up is None:  # nothing certified feasible: say what the solver said at the feasible end of the range
            end = br.verdicts.get(1.0)
            status = f"not certified at lambda2 = 1 ({end.solver_status if end else 'not solved'})"
        else:
            status = up.solver_status
        rows.append({
            "lambda1": lam1,
            "lambda2c_upper": br.feasible_end,
            "bracket_lower": br.infeasible_end,
            "certified": bool(br.certified or at_zero),
            "upper_certified_by": up.evidence if up else "none",
            "lower_certified_by": (low.evidence if low else
                                   "none needed: lambda2 = 0 is certified feasible" if at_zero else "none"),
            "upper_slack": up.point.slack if up is not None and up.point is not None else np.nan,
            "n_solves": br.n_evals,
            "n_undecided": len(br.undecided),
            "status_at_threshold": status,
            "statuses_seen": "; ".join(f"{k}: {v}" for k, v in seen),
        })
    return rows
