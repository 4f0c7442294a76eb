"""Paper `intermittent`: S. Teerikoski, *Kalman Filtering with Measurement Losses* (report, 2014).

After Sinopoli et al. (2004) and Liu & Goldsmith (2004). The report studies the scalar
system x_{k+1} = a x_k + v_k, y_k = x_k + w_k with i.i.d. packet losses (arrival
probability lambda) and the prediction-error variance recursion (6)

    p_{k+1} = a^2 p_k + R1 - gamma_k a^2 p_k^2 / (p_k + R2).

Modules
-------
``model``
    The scalar equations: critical probability, the Riccati step (6), the bounds s_k (10)
    and r_k (9), the report's rough estimate of E(p_k), Sinopoli's operator phi(K, p).
``exact``
    Exact E(p_k) by enumeration of the arrival sequences.
``estimators``
    The conditional Monte Carlo estimator of E(p_k) (averages bounded quantities only).
``exact``
    Exact E(p_k) at every k and the stationary mean, with rigorous error bounds
    (last-arrival decomposition, backward recursion on Chebyshev interpolants).
``tails``
    Sample paths and tails of p_k: the loss-run probability (log-scaled repeated squaring of the
    substochastic run-length block, with two independent checks), the tail index of p_inf and the
    moment thresholds 1 - 1/a^{2n}, quantiles of a discrete law.
``analysis``
    How the report's figures and words are read: settling and forgetting steps, the worst
    relative error, the one-step growth ratio.
``two_sensor``
    The two-sensor stability region (Liu & Goldsmith): closed-form lower bound and the
    certified LMI upper bound (eq. 16) by bisection.
``steps``
    Pipeline steps writing ``results/intermittent/*.csv``.
``evidence``
    Our side of the claims, errata, findings and reconstructions (``results/evidence/``).
``figures``
    Plotting only: Figs 1, 2, 4, 5 and S1 from the tables; ``figures.yaml`` lists them.
``checks``
    Configuration checks the schema cannot express.
"""
