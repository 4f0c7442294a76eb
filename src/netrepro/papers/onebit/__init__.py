"""Paper `onebit`: L. Zhang, M. Stein, J. A. Nossek, *Asymptotic Performance Analysis for 1-Bit
Bayesian Smoothing*.

Recursive Bayesian information matrices (BIMs) for filtering (7), prediction (14) and smoothing
(16)-(19) in general vector form, their Gaussian random-walk specialisations (22)-(27), the 1-bit
(hard-limited) versions (29)-(38), and the steady-state information ratios (47)-(49) of Figs 1-2.

Modules
-------
``fisher``
    The 1-bit Fisher information (30) and its expectation (29).
``model``
    Moments of theta (31)-(33), the SNR convention, the general vector BIM recursions (7)-(19)
    (corrected and as printed) and the Kalman/RTS covariances they reproduce.
``randomwalk``
    The scalar random walk: recursions (24)-(27)/(34)-(38), fixed points, lag, ratios (47)-(49),
    transients.
``estimators``
    Beyond the paper: simulation, the grid 1-bit filter/smoother, the Kalman filter/RTS smoother.
``kernels``
    Compiled inner loops of the estimators.
``steps``
    Pipeline steps writing ``results/onebit/*.csv``.
``shards``
    Which estimator cases the sharded step runs, and how its shard files merge back (IO, no mathematics).
``evidence``
    Our side of the claims, errata, findings and reconstructions (``results/evidence/``).
``figures``
    Plotting only: Figs 1-2 and S1-S4 from the tables; ``figures.yaml`` lists them.
``checks``
    Configuration checks the schema cannot express.
"""
