"""Paper `markov`: J. Wu, G. Shi, B. D. O. Anderson, K. H. Johansson, *Stability Conditions and
Phase Transition for Kalman Filtering over Markovian Channels*.

Modules
-------
``model``
    The equations: system, observability index (Definition 2), Proposition 1 (eq. 8), ``H(K)``
    (eq. 7), ``L_K`` (eq. 9), the Riccati maps (eqs. 4-5), closed forms of the examples.
``analysis``
    Exact E||P_k|| by enumerating the channel's paths (Proposition 2's finite-k check).
``lmis``
    The LMI (10)-(11) of Theorem 2 (iv), Theorem 5's bisection (eq. 12), the i.i.d. LMI bound.
``exact``
    Exact ``E||P_k||`` over all channel paths, as polynomials in ``(p, q)``.
``expectations``
    ``E||P_k||`` beyond the exact range (conditional estimates, parity brackets).
``estimators``
    Plain and conditional Monte Carlo estimators of ``E||P_k||``.
``kernels``
    Compiled inner loops of the estimators.
``certificates``
    Certified bounds that decide the stability map (Theorem 1 gains, two-reception upper bound,
    loss-run and parity lower bounds).
``stability``
    Estimator verdicts of the stability map (a cross-check).
``steps``
    Pipeline steps writing ``results/markov/*.csv``.
``evidence``
    Our side of the claims, errata, findings and reconstructions (``results/evidence/``).
``figures``
    Plotting only: Figs 2-6 and S1-S2 from the tables; ``figures.yaml`` lists them.
``checks``
    Configuration checks the schema cannot express.
"""
