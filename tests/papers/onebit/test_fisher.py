"""Tests of netrepro.papers.onebit.fisher: each equation against an independent computation."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy import integrate, stats

from netrepro.papers.onebit import fisher

ROOT = Path(__file__).resolve().parents[3]


def test_fisher_1bit_matches_direct_formula_in_the_bulk():
    theta = np.linspace(-4, 4, 81)
    for se in (0.5, 1.0, 3.0):
        x = theta / se
        direct = stats.norm.pdf(x) ** 2 / (stats.norm.cdf(x) * stats.norm.sf(x)) / se**2
        np.testing.assert_allclose(fisher.fisher_1bit(theta, se), direct, rtol=1e-12)
    assert fisher.fisher_1bit(0.0) == pytest.approx(2 / math.pi, rel=1e-15)  # eq. (30) at theta = 0: 2/pi


def test_fisher_1bit_tails_do_not_underflow_to_nan():
    x = np.array([10.0, 20.0, 30.0, -30.0])
    f = fisher.fisher_1bit(x)
    assert np.all(np.isfinite(f)) and np.all(f > 0)
    # Q(x) ~ phi(x)/x (1 - 1/x^2 + 3/x^4 - 15/x^6): F_q ~ |x| phi(x) / (1 - 1/x^2 + 3/x^4 - 15/x^6)
    ax = np.abs(x)
    asym = ax * stats.norm.pdf(ax) / (1 - ax**-2 + 3 * ax**-4 - 15 * ax**-6)
    np.testing.assert_allclose(f[1:], asym[1:], rtol=1e-6)


@pytest.mark.parametrize("mean", [0.0, 0.7, -2.5])
def test_expected_fisher_matches_adaptive_quadrature(mean):
    v = np.logspace(-3, 3, 13)
    ours = fisher.expected_fisher_1bit(v, 1.0, mean)
    for vi, oi in zip(v, ours):
        s = math.sqrt(vi)
        f = lambda t: fisher.fisher_1bit(t) * stats.norm.pdf(t, mean, s)  # noqa: E731
        lo, hi = max(mean - 40 * s, -60), min(mean + 40 * s, 60)
        pts = [p for p in (mean, 0.0) if lo < p < hi]
        q, err = integrate.quad(f, lo, hi, points=pts, epsabs=0, epsrel=1e-13, limit=500)
        assert err < 1e-12 * q
        assert oi == pytest.approx(q, rel=1e-10)


def test_expected_fisher_scaling_limits_and_vectorisation():
    # sigma_eta scaling: E[F_q](var, se) = E[F_q](var/se^2, 1)/se^2
    assert fisher.expected_fisher_1bit(8.0, 2.0) == pytest.approx(fisher.expected_fisher_1bit(2.0) / 4, rel=1e-14)
    assert fisher.expected_fisher_1bit(1e-12) == pytest.approx(2 / math.pi, rel=1e-11)
    c = fisher.expected_fisher_1bit(1e14) * math.sqrt(2 * math.pi * 1e14)
    c_quad = integrate.quad(lambda t: fisher.fisher_1bit(t), -40, 40, epsrel=1e-13, limit=200)[0]
    assert c == pytest.approx(c_quad, rel=1e-6)
    grid = np.logspace(-2, 2, 12).reshape(3, 4)
    assert fisher.expected_fisher_1bit(grid).shape == (3, 4)
    assert np.all(np.diff(fisher.expected_fisher_1bit(np.logspace(-6, 6, 50))) < 0)


def test_expected_fisher_quad_helper_agrees():
    for v in (1e-2, 1.0, 1e2):
        assert fisher.expected_fisher_1bit_quad(v)[0] == pytest.approx(float(fisher.expected_fisher_1bit(v)), rel=1e-10)


def test_interpolator_is_accurate():
    f = fisher.expected_fisher_interpolator()
    v = np.logspace(-9, 7, 333)
    np.testing.assert_allclose(f(v), fisher.expected_fisher_1bit(v), rtol=1e-9)
