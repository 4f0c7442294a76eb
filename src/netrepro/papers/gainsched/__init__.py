"""Paper `gainsched`: probability-dependent gain-scheduled filtering (Wei, Wang, Shen, Li).

G. Wei, Z. Wang, B. Shen, M. Li, *Probability-Dependent Gain-Scheduled Filtering for
Stochastic Systems with Missing Measurements*.

Modules:

* :mod:`.model`: plant (1)-(7), filter (8)-(9), augmented system (10)-(11), sector (3)-(5),
  Theorem 1 (12), second moments, simulation of Algorithm 1;
* :mod:`.design`: Theorem 3 vertex LMIs (24)-(25), gain recovery (26), performance variant;
* :mod:`.moments`: exact second moments for linear f (issue 16);
* :mod:`.feasibility`: certified feasible / infeasible / undecided decisions, plant LMIs for the paper's
  class (3) (scalar multiplier) and componentwise sectors (diagonal), worst linear gain in the sector, brackets;
* :mod:`.verification`: independent checks behind the evidence (stability indices, residuals of the errata);
* :mod:`.tuning`: gains of form (9) tuned by Monte Carlo or on the exact cost (yardsticks, not the paper's);
* :mod:`.steps`: pipeline steps (designs, stability, simulation, sensitivity, timing, vertex LMIs);
* :mod:`.evidence`: the evidence step (our side of ``claims.yaml``, ``errata.yaml``,
  ``reconstructions.yaml``, ``findings.yaml``; issue 15);
* :mod:`.figures`: Figs 1-2, S1, S2 from the tables;
* :mod:`.checks`: configuration checks; ``figures.yaml``: the figure list.
"""

__all__ = ["model", "moments", "design", "feasibility", "verification", "tuning", "steps", "evidence", "figures", "checks"]
