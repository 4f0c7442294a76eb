"""Paper `hinf` (003): T. R. Nelson, R. A. Freeman, *Decentralized H-infinity Filtering in a Multi-Agent System*.

Modules
-------
``algebra``    closed-form 2x2 matrix algebra (inverse, smallest eigenvalue, rotation of eq (3)).
``noise``      sensing geometry and the range-bearing noise model, eqs (2)-(4), (17)-(18).
``consensus``  communication graph (25) and the PI dynamic consensus estimator (5).
``filters``    centralized (6) and decentralized (9) H-infinity filters, Kalman limit, gamma_0.
``motion``     gradient motion control, eqs (10)-(16).
``evader``     the evasive target, eqs (19)-(24).
``model``      the multi-agent system of Section VI: scenarios and their Monte Carlo simulation.
``steps``      pipeline steps (tables under ``results/hinf/``).
``claims``     claims, errata and reconstructions steps.
``figures``    plotting only (reads tables); ``figures.yaml`` lists the figures.
``checks``     configuration checks the schema cannot express.
"""

__all__: list[str] = []
