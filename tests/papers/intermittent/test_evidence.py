import itertools

import numpy as np
import pytest

from netrepro.papers.intermittent import evidence
from netrepro.verdicts import load_paper_data

A, R1, R2, P0 = 1.5, 0.1, 0.5, 10.0
LAM = 1 - 1 / A**2 + 0.1


def test_paper_data_loads_and_every_dependent_claim_names_a_reconstruction():
    data = load_paper_data("intermittent")
    keys = {r["key"] for r in data.reconstructions}
    assert {"C15", "C16"} <= {c.claim_id for c in data.claims}
    assert {"E15", "E16", "E17"} <= {e["id"] for e in data.errata}
    kinds = {e["id"]: e["kind"] for e in data.errata}
    assert kinds["E12"] == kinds["E14"] == "notation"
    assert all(set(c.depends_on) <= keys for c in data.claims)


def test_settle_step_matches_the_closed_form_of_a_geometric_approach():
    # s_k = s* + (s0 - s*) g^k: the curve is within `reading` of s* from k = ceil(log(reading/(s0 - s*))/log g)
    g = (1 - LAM) * A * A
    s_star = R1 / (1 - g)
    k = np.arange(200)
    s = s_star + (P0 - s_star) * g**k
    for reading in (0.025, 0.05, 0.1):
        expected = int(np.ceil(np.log(reading / (P0 - s_star)) / np.log(g)))
        assert evidence.settle_step(s, s_star, reading) == expected
    assert evidence.settle_step([3.0, 3.0], 3.0, 0.1) == 0
    # a curve that comes back out of the band is not settled until it stays
    assert evidence.settle_step([1.0, 0.0, 1.0, 0.0, 0.0], 0.0, 0.5) == 3


def test_forget_step_of_two_geometric_curves():
    k = np.arange(100)
    x, y = 1.0 + 4.0 * 0.5**k, 1.0 + 0.0 * k
    # |x/y - 1| = 4 * 0.5^k <= 0.01  <=>  k >= log2(400) = 8.64
    assert evidence.forget_step(x, y, 0.01) == 9


def test_worst_relative_error_keeps_the_sign():
    err, k = evidence.worst_relative_error([1.0, 0.8, 1.1], [1.0, 1.0, 1.0])
    assert k == 1 and err == pytest.approx(-0.2)


def test_estimate_with_true_mean_is_exact_for_a_point_mass():
    # if p_k is deterministic (s = r = E(p) = m), the report's formula is exactly the lambda-mixture of eq. (6)
    m = np.array([10.0, 3.0, 0.7, 2.2])
    out = evidence.estimate_with_true_mean(m, m, m, A, R1, R2, LAM)
    with_arrival = A * A * m * R2 / (m + R2) + R1
    without = A * A * m + R1
    assert out[0] == m[0]
    np.testing.assert_allclose(out[1:], (LAM * with_arrival + (1 - LAM) * without)[:-1], rtol=1e-13)


@pytest.mark.parametrize("m,T", [(1, 6), (2, 8), (3, 10)])
def test_loss_run_probability_against_enumeration(m, T):
    lam = 0.4
    total = 0.0
    for seq in itertools.product((0, 1), repeat=T):
        run, hit = 0, False
        for g in seq:
            run = 0 if g else run + 1
            hit |= run >= m
        if hit:
            total += np.prod([lam if g else 1 - lam for g in seq])
    assert evidence.loss_run_probability(lam, m, T) == pytest.approx(total, rel=1e-12)


def test_loss_run_probability_of_a_single_loss():
    assert evidence.loss_run_probability(0.7, 1, 25) == pytest.approx(1 - 0.7**25, rel=1e-12)


def test_losses_to_exceed_iterating_eq6_without_arrivals():
    level = 1e6
    m = evidence.losses_to_exceed(level, A, R1)
    p = 0.0  # the worst start
    for _ in range(m - 1):
        p = A * A * p + R1
    assert p < level
    assert A * A * p + R1 >= level


def test_tail_grows():
    k = np.arange(81)
    assert evidence.tail_grows(1.1**k)
    assert not evidence.tail_grows(2.0 - 0.5**k)


def test_mean_is_concave_in_p0_so_the_two_point_laws_bracket_the_p0_range():
    # the range of reconstruction scalar.Ep0 rests on E(p_k | p0 = q) being concave in q (enumeration, k <= 8)
    from netrepro.papers.intermittent.model import exact_mean_enumeration

    m = {q: exact_mean_enumeration(q, A, R1, R2, LAM, 8) for q in (0.0, 5.0, 10.0, 15.0, 20.0)}
    assert np.all(m[10.0] >= 0.5 * (m[5.0] + m[15.0]) - 1e-12)
    assert np.all(0.5 * (m[5.0] + m[15.0]) >= 0.5 * (m[0.0] + m[20.0]) - 1e-12)
    assert np.any(m[10.0][1:] > 0.5 * (m[0.0] + m[20.0])[1:] + 1e-6)
