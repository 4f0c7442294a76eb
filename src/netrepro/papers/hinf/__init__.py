"""Paper `hinf`: T. R. Nelson, R. A. Freeman, *Decentralized H-infinity Filtering in a Multi-Agent
System*.

Modules
-------
``algebra``
    Closed-form 2x2 matrix algebra (inverse, smallest eigenvalue, rotation of eq (3)).
``noise``
    Sensing geometry and the range-bearing noise model, eqs (2)-(4), (17)-(18).
``consensus``
    Communication graph (25) and the PI dynamic consensus estimator (5).
``filters``
    Centralized (6) and decentralized (9) H-infinity filters, Kalman limit, gamma_0.
``filter_kernels``
    Compiled inner loops of the filters.
``motion``
    Gradient motion control, eqs (10)-(16).
``evader``
    The evasive target, eqs (19)-(24).
``evader_kernels``
    Compiled inner loops of the evader's solver.
``simulation``
    The frozen scenario type and the named phases of one simulation step (target, measurements, consensus,
    filters, agents).
``model``
    The multi-agent system of Section VI: scenarios and their Monte Carlo simulation (the loop over the phases).
``steps``
    Pipeline steps writing ``results/hinf/*.csv``.
``analysis``
    What the evidence quotes beyond the tables: errata residuals, steady-state gain norms, the sweet spot.
``evidence``
    Our side of the claims, errata, findings and reconstructions (``results/evidence/``).
``figures``
    Plotting only: Figs 1-6 and S1-S4 from the tables; ``figures.yaml`` lists them.
``checks``
    Configuration checks the schema cannot express.
"""
