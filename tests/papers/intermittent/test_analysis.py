import numpy as np
import pytest

from netrepro.papers.intermittent import analysis as readings

A, R1 = 1.5, 0.1
LAM = 1 - 1 / A**2 + 0.1
P0 = 10.0


def test_settle_step_matches_the_closed_form_of_a_geometric_approach():
    # s_k = s* + (s0 - s*) g^k: the curve is within `reading` of s* from k = ceil(log(reading/(s0 - s*))/log g)
    g = (1 - LAM) * A * A
    s_star = R1 / (1 - g)
    k = np.arange(200)
    s = s_star + (P0 - s_star) * g**k
    for reading in (0.025, 0.05, 0.1):
        expected = int(np.ceil(np.log(reading / (P0 - s_star)) / np.log(g)))
        assert readings.settle_step(s, s_star, reading) == expected
    assert readings.settle_step([3.0, 3.0], 3.0, 0.1) == 0
    # a curve that comes back out of the band is not settled until it stays
    assert readings.settle_step([1.0, 0.0, 1.0, 0.0, 0.0], 0.0, 0.5) == 3


def test_forget_step_of_two_geometric_curves():
    k = np.arange(100)
    x, y = 1.0 + 4.0 * 0.5**k, 1.0 + 0.0 * k
    # |x/y - 1| = 4 * 0.5^k <= 0.01  <=>  k >= log2(400) = 8.64
    assert readings.forget_step(x, y, 0.01) == 9


def test_worst_relative_error_keeps_the_sign():
    err, k = readings.worst_relative_error([1.0, 0.8, 1.1], [1.0, 1.0, 1.0])
    assert k == 1 and err == pytest.approx(-0.2)


def test_growth_ratio_of_the_two_sensor_mean_tends_to_the_loss_growth_factor():
    # independent: E(p_k) = g^k p0 + sum_{j<k} g^j b = g^k (p0 + c) - c with c = b/(g - 1), so
    # E(p_80)/E(p_79) = (g^80 (p0 + c) - c)/(g^79 (p0 + c) - c) -> g
    g, b, p0 = 1.1575, 0.7, 1.0
    c = b / (g - 1)
    k = np.arange(81)
    mean = g**k * p0 + b * (g**k - 1) / (g - 1)
    expected = (g**80 * (p0 + c) - c) / (g**79 * (p0 + c) - c)
    assert readings.growth_ratio(mean) == pytest.approx(expected, rel=1e-12)
    assert readings.growth_ratio(mean) == pytest.approx(g, rel=1e-5)
    assert readings.growth_ratio([2.0, 1.0]) == 0.5
