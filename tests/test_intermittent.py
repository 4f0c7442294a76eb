import itertools

import numpy as np
import pandas as pd
import pytest

from netrepro.engines.montecarlo import run_monte_carlo
from netrepro.engines.riccati import Sensor, covariance_paths, iterate_expected_riccati
from netrepro.papers import intermittent as im

A, R1, R2, P0 = 1.5, 0.1, 0.5, 10.0
LAM_S = im.critical_probability(A) + 0.1
LAM_U = im.critical_probability(A) - 0.1


def test_critical_probability_closed_form():
    assert im.critical_probability(1.5) == pytest.approx(1 - 1 / 2.25)
    assert im.critical_probability([[0.5, 0], [0, -2.0]]) == pytest.approx(0.75)


@pytest.mark.parametrize("lam", [LAM_S, LAM_U])
def test_lower_bound_closed_form(lam):
    c = (1 - lam) * A * A
    k = np.arange(41)
    closed = c**k * P0 + R1 * (1 - c**k) / (1 - c)
    assert np.allclose(im.lower_bound_sequence(P0, A, R1, lam, 40), closed)


@pytest.mark.parametrize("lam", [LAM_S, LAM_U])
def test_upper_bound_is_modified_riccati_iteration(lam):
    engine = iterate_expected_riccati([[P0]], [[A]], [[R1]], [Sensor([[1.0]], [[R2]])], [lam], 30)[:, 0, 0]
    assert np.allclose(im.upper_bound_sequence(P0, A, R1, R2, lam, 30), engine)


def test_exact_enumeration_matches_brute_force():
    n = 7
    total = np.zeros(n + 1)
    for seq in itertools.product([0, 1], repeat=n):
        prob, p = 1.0, P0
        total[0] += 0  # filled below
        path = [p]
        for g in seq:
            p = im.riccati_step(p, g, A, R1, R2)
            path.append(p)
        prob = np.prod([LAM_S if g else 1 - LAM_S for g in seq])
        # E(p_k) only depends on the first k arrivals: weight the full sequence
        total += prob * np.array(path)
    assert np.allclose(im.exact_mean_enumeration(P0, A, R1, R2, LAM_S, n), total)


@pytest.mark.parametrize("probs,variances", [([LAM_S], [R2]), ([LAM_U], [R2]), ([0.3, 0.5], [0.2, 0.5])])
def test_conditional_estimator_is_exactly_unbiased(probs, variances):
    """Average the per-path estimator over *all* arrival sequences with their probabilities."""
    T = 6
    m = len(probs)
    seqs = np.array(list(itertools.product([False, True], repeat=T * m)), dtype=bool).reshape(-1, T, m)
    weights = np.prod(np.where(seqs, probs, 1 - np.asarray(probs)), axis=(1, 2))
    sensors = [Sensor([[1.0]], [[v]]) for v in variances]
    paths = covariance_paths(P0, [[A]], [[R1]], sensors, seqs)
    y = im.conditional_mean_paths(paths, P0, A, R1, variances, probs)
    assert np.allclose(weights @ y, weights @ paths, rtol=1e-12)


def test_conditional_estimator_band_covers_exact():
    params = dict(a=A, R1=R1, R2=R2, Ep0=P0, horizon=18)
    exact = im.exact_mean_enumeration(P0, A, R1, R2, LAM_U, 18)
    mc = run_monte_carlo(im._scalar_simulator(params, LAM_U), 40_000, 10_000, seed=3)
    _, lo, hi = mc.ci("cond")
    covered = (lo <= exact + 1e-9) & (exact <= hi + 1e-9)
    assert covered.mean() >= 0.85  # 95% pointwise bands, 19 correlated points


def test_report_estimate_fixed_point_formula():
    s = im.lower_bound_sequence(P0, A, R1, LAM_S, 3)
    r = im.upper_bound_sequence(P0, A, R1, R2, LAM_S, 3)
    m = im.report_estimate_sequence(P0, s, r, A, R1, R2, LAM_S)
    # with s = r the replacement is exact for a point mass: equals the Riccati step
    same = im.report_estimate_sequence(P0, r, r, A, R1, R2, LAM_S)
    assert same[1] == pytest.approx(im.riccati_step(P0, LAM_S, A, R1, R2))
    assert m.shape == (4,)


def test_two_sensor_lmi_equals_lower_bound():
    grid = np.array([0.0, 0.3, 0.5, 0.8])
    upper = im.two_sensor_upper_bound(grid, A, tol=1e-5)
    assert np.allclose(upper["lambda2c_upper"], im.two_sensor_lower_bound(grid, A), atol=1e-4)
    assert (upper["certified_radius"] < 1).all()


def test_lower_bound_is_zero_when_one_sensor_suffices():
    assert im.two_sensor_lower_bound(0.6, A) == 0.0
    assert im.two_sensor_lower_bound(0.0, A) == pytest.approx(1 - 1 / A**2)


def test_errata_corrections_are_right_and_printed_forms_wrong():
    cfg = {"scalar": dict(a=A, R1=R1, R2=R2, Ep0=P0), "two_sensor": {"sigma2": [0.2, 0.5]}}
    rows = pd.DataFrame(im.errata_rows(cfg))
    numeric = rows.dropna(subset=["residual_printed"])
    assert len(rows) >= 10 and len(numeric) >= 8
    assert (numeric["residual_corrected"] < 1e-5).all()
    assert (numeric["residual_printed"] > 1e-3).all()


def test_check_config_names_key():
    from netrepro.config import ConfigError
    with pytest.raises(ConfigError, match="exact_horizon"):
        im.check_config({"scalar": dict(a=1.5, exact_horizon=30, horizon=10, lambda_offsets=[0.1])})
    with pytest.raises(ConfigError, match="lambda_offsets"):
        im.check_config({"scalar": dict(a=1.5, exact_horizon=3, horizon=10, lambda_offsets=[0.6])})


def test_region_shards_give_identical_tables_whatever_the_split():
    base = {"a": A, "lambda1_grid": 9, "bisection_tol": 1e-4}
    tables = []
    for n_shards in (1, 2, 4):
        parts = [im.two_sensor_region_shard_step({**base, "n_shards": n_shards, "shard": s}, {}, {})["table"]
                 for s in range(n_shards)]
        tables.append(pd.concat(parts).sort_values("lambda1", kind="stable").reset_index(drop=True))
    for other in tables[1:]:
        pd.testing.assert_frame_equal(tables[0], other)
