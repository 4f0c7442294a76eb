import itertools

import numpy as np
import pytest

from netrepro.engines.riccati import Sensor, iterate_expected_riccati
from netrepro.errors import InputError
from netrepro.papers.intermittent import model as im

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
        p = P0
        path = [p]
        for g in seq:
            p = im.riccati_step(p, g, A, R1, R2)
            path.append(p)
        prob = np.prod([LAM_S if g else 1 - LAM_S for g in seq])
        # E(p_k) only depends on the first k arrivals: weight the full sequence
        total += prob * np.array(path)
    assert np.allclose(im.exact_mean_enumeration(P0, A, R1, R2, LAM_S, n), total)


def test_exact_enumeration_refuses_long_horizons():
    with pytest.raises(InputError, match="n_steps"):
        im.exact_mean_enumeration(P0, A, R1, R2, LAM_S, 25)


def test_report_estimate_fixed_point_formula():
    s = im.lower_bound_sequence(P0, A, R1, LAM_S, 3)
    r = im.upper_bound_sequence(P0, A, R1, R2, LAM_S, 3)
    m = im.report_estimate_sequence(P0, s, r, A, R1, R2, LAM_S)
    # with s = r the replacement is exact for a point mass: equals the Riccati step
    same = im.report_estimate_sequence(P0, r, r, A, R1, R2, LAM_S)
    assert same[1] == pytest.approx(im.riccati_step(P0, LAM_S, A, R1, R2))
    assert m.shape == (4,)


def test_sinopoli_operator_minimum_is_the_modified_riccati_map():
    ks = np.linspace(-3, 1, 400001)
    p = 2.0
    values = im.sinopoli_operator(ks, p, LAM_S, A, R1, R2)
    assert values.min() == pytest.approx(im.upper_bound_sequence(p, A, R1, R2, LAM_S, 1)[1], rel=1e-9)
    assert ks[values.argmin()] == pytest.approx(-A * p / (p + R2), abs=1e-4)


def test_estimate_with_true_mean_is_exact_for_a_point_mass():
    # if p_k is deterministic (s = r = E(p) = m), the report's formula is exactly the lambda-mixture of eq. (6)
    m = np.array([10.0, 3.0, 0.7, 2.2])
    out = im.estimate_with_true_mean(m, m, m, A, R1, R2, LAM_S)
    with_arrival = A * A * m * R2 / (m + R2) + R1
    without = A * A * m + R1
    assert out[0] == m[0]
    np.testing.assert_allclose(out[1:], (LAM_S * with_arrival + (1 - LAM_S) * without)[:-1], rtol=1e-13)


def test_printed_condition_11_is_the_printed_condition_divided_by_a2_p():
    # E2: (11) = [p > a^2 p + lambda a^2 p^2 (p + R2)^-2 (p - 2 + R2)] / (a^2 p), rearranged
    p = np.logspace(-2, 2, 50)
    lam = LAM_S
    direct = p - (A * A * p + lam * A * A * p * p / (p + R2) ** 2 * (p - 2 + R2))
    np.testing.assert_allclose(im.condition_11_printed(p, lam, A, R2) * A * A * p, direct, rtol=1e-12, atol=1e-14)


def test_corrected_condition_11_is_x_minus_phi_at_the_optimal_gain():
    p = np.logspace(-2, 2, 50)
    phi = im.sinopoli_operator(-A * p / (p + R2), p, LAM_S, A, R1, R2)
    np.testing.assert_allclose(im.condition_11_corrected(p, LAM_S, A, R1, R2) * A * A * p, p - phi, rtol=1e-10,
                               atol=1e-13)
    # the corrected condition holds for some p iff lambda > 1 - 1/a^2 (the MARE has a fixed point)
    grid = np.logspace(-3, 6, 2000)
    assert np.max(im.condition_11_corrected(grid, LAM_S, A, R1, R2)) > 0
    assert np.max(im.condition_11_corrected(grid, LAM_S - 0.2, A, R1, R2)) < 0


def test_lower_bound_limit_is_where_the_lower_bound_settles():
    from netrepro.papers.intermittent.model import lower_bound_limit, lower_bound_sequence

    a, R1, lam = 1.5, 0.1, 0.7  # (1 - lambda) a^2 = 0.675 < 1
    s = lower_bound_sequence(3.0, a, R1, lam, 400)
    assert abs(lower_bound_limit(a, R1, lam) - s[-1]) <= 1e-12 * s[-1]
