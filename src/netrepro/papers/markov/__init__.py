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
enumeration
    brute-force ``E||P_k||`` path by path (independent of ``exact``) and the finite-``k``
    monotonicity in ``p`` behind Proposition 2.
estimators
    plain and conditional Monte Carlo estimators of ``E||P_k||``.
certificates
    certified bounds that decide the stability map (Theorem 1 gains, two-reception upper bound,
    loss-run and parity lower bounds).
stability
    estimator verdicts of the stability map (a cross-check) and its single-transition check.
evidence
    assembly of the evidence table from the result tables and the claims' ``at:`` settings.
expectations
    ``E||P_k||`` beyond the exact range: validated conditional estimate, derived asymptote and its limit.
kernels
    compiled (numba) kernels of the conditional estimator.
steps
    pipeline steps (tables); ``figures`` plotting; ``checks`` configuration checks. The claims,
    errata, reconstructions and findings are the YAML files beside these modules.
"""

__all__ = ["model", "lmis", "certificates", "exact", "enumeration", "estimators", "expectations", "kernels", "stability",
           "steps", "evidence", "figures", "checks"]
