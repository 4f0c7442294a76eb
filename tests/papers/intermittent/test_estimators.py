import itertools

import numpy as np
import pytest

from netrepro.engines.montecarlo import run_monte_carlo
from netrepro.engines.riccati import Sensor, covariance_paths
from netrepro.papers.intermittent import estimators as est
from netrepro.papers.intermittent import model as im
from netrepro.papers.intermittent.steps import _scalar_simulator

A, R1, R2, P0 = 1.5, 0.1, 0.5, 10.0
LAM_S = im.critical_probability(A) + 0.1
LAM_U = im.critical_probability(A) - 0.1


def test_loss_propagation_is_repeated_riccati_step_without_arrivals():
    x = 3.0
    for m in range(6):
        y = x
        for _ in range(m):
            y = im.riccati_step(y, 0.0, A, R1, R2)
        assert est.loss_propagation(x, m, A, R1) == pytest.approx(y, rel=1e-12)


@pytest.mark.parametrize("probs,variances", [([LAM_S], [R2]), ([LAM_U], [R2]), ([0.3, 0.5], [0.2, 0.5])])
def test_conditional_estimator_is_exactly_unbiased(probs, variances):
    """Average the per-path estimator over *all* arrival sequences with their probabilities."""
    T = 6
    m = len(probs)
    seqs = np.array(list(itertools.product([False, True], repeat=T * m)), dtype=bool).reshape(-1, T, m)
    weights = np.prod(np.where(seqs, probs, 1 - np.asarray(probs)), axis=(1, 2))
    sensors = [Sensor([[1.0]], [[v]]) for v in variances]
    paths = covariance_paths(P0, [[A]], [[R1]], sensors, seqs)
    y = est.conditional_mean_paths(paths, P0, A, R1, variances, probs)
    assert np.allclose(weights @ y, weights @ paths, rtol=1e-12)


def test_conditional_estimator_band_covers_exact():
    params = dict(a=A, R1=R1, R2=R2, Ep0=P0, horizon=18)
    exact = im.exact_mean_enumeration(P0, A, R1, R2, LAM_U, 18)
    mc = run_monte_carlo(_scalar_simulator(params, LAM_U), 40_000, 10_000, seed=3)
    _, lo, hi = mc.ci("cond")
    covered = (lo <= exact + 1e-9) & (exact <= hi + 1e-9)
    assert covered.mean() >= 0.85  # 95% pointwise bands, 19 correlated points
