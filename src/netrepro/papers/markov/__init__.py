"""Paper `markov` (004): J. Wu, G. Shi, B. D. O. Anderson, K. H. Johansson, *Stability Conditions
and Phase Transition for Kalman Filtering over Markovian Channels*.

Modules
-------
model
    the equations: system, observability index (Definition 2), Proposition 1 (eq. 8), ``H(K)``
    (eq. 7), ``L_K`` (eq. 9), the Riccati maps (eqs. 4-5), closed forms of the examples.
lmis
    the LMI (10)-(11) of Theorem 2 (iv), Theorem 5's bisection (eq. 12), the i.i.d. LMI bound.
exact
    exact ``E||P_k||`` over all channel paths, as polynomials in ``(p, q)``.
estimators
    plain and conditional Monte Carlo estimators of ``E||P_k||``.
certificates
    certified bounds that decide the stability map (Theorem 1 gains, two-reception upper bound,
    loss-run and parity lower bounds).
stability
    estimator verdicts of the stability map (a cross-check).
steps
    pipeline steps (tables); ``claims`` the claims, errata, reconstructions; ``figures`` plotting;
    ``checks`` configuration checks.
"""

__all__ = ["model", "lmis", "certificates", "exact", "estimators", "stability", "steps", "claims", "figures", "checks"]
