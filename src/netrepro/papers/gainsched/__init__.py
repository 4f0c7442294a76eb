"""Paper `gainsched`: G. Wei, Z. Wang, B. Shen, M. Li, *Probability-Dependent Gain-Scheduled
Filtering for Stochastic Systems with Missing Measurements*.

Modules
-------
``model``
    Plant (1)-(7), filter (8)-(9), augmented system (10)-(11), sector (3)-(5), Theorem 1 (12),
    second moments, simulation of Algorithm 1.
``kernels``
    Compiled inner loops of the simulation.
``design``
    Theorem 3 vertex LMIs (24)-(25), gain recovery (26), performance variant.
``moments``
    Exact second moments for linear f.
``feasibility``
    Certified feasible / infeasible / undecided decisions, plant LMI, brackets.
``analysis``
    Independent checks behind the evidence (stability indices, residuals of the errata).
``tuning``
    Gains of form (9) tuned by Monte Carlo or on the exact cost (yardsticks, not the paper's).
``steps``
    Pipeline steps (designs, stability, simulation, sensitivity, timing, vertex LMIs).
``evidence``
    Our side of the claims, errata, findings and reconstructions (``results/evidence/``).
``figures``
    Plotting only: Figs 1-2, S1, S2 from the tables; ``figures.yaml`` lists them.
``checks``
    Configuration checks the schema cannot express.
"""
