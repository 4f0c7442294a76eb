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


def _inverse_sqrt_quad(v):
    """E[F_q^(-1/2)] under N(0, v) by adaptive quadrature of the log-domain integrand (independent of the
    product-Gaussian form of the module)."""
    def f(x):
        log_f = 2.0 * stats.norm.logpdf(x) - stats.norm.logcdf(x) - stats.norm.logsf(x)
        return math.exp(-0.5 * log_f + stats.norm.logpdf(x, scale=math.sqrt(v)))
    return 2.0 * integrate.quad(f, 0.0, np.inf, limit=500, epsabs=0.0, epsrel=1e-11)[0]


@pytest.mark.parametrize("snr_db", [-30.0, -10.0, 0.0, 1.5, 2.5])
def test_expected_inverse_sqrt_fisher_matches_adaptive_quadrature(snr_db):
    v = 10.0 ** (snr_db / 10.0)
    assert fisher.expected_inverse_sqrt_fisher_1bit(v) == pytest.approx(_inverse_sqrt_quad(v), rel=1e-8)


def test_expected_inverse_sqrt_fisher_limits_and_divergence():
    # v -> 0: a point mass at 0, F_q(0) = 2/pi
    assert fisher.expected_inverse_sqrt_fisher_1bit(1e-12) == pytest.approx(math.sqrt(math.pi / 2), rel=1e-9)
    # F_q^(-1/2) grows like exp(x^2/4): the expectation under N(0, v) is infinite from v = 2 on
    e = fisher.expected_inverse_sqrt_fisher_1bit([1.9, 1.99, 2.0, 3.0])
    assert np.isfinite(e[:2]).all() and e[1] > e[0] and np.isinf(e[2:]).all()
    with pytest.raises(Exception):
        fisher.expected_inverse_sqrt_fisher_1bit(-1.0)


def test_achievable_limit_below_the_bounds_limit_by_jensen():
    snr = np.array([-20.0, -5.0, 0.0, 2.0, 2.9])
    bound_lim = 10.0 * np.log10(2.0 * np.sqrt(fisher.expected_fisher_1bit(10.0 ** (snr / 10.0))))
    ach = fisher.achievable_rho_s_limit_db(snr)
    assert np.all(ach < bound_lim)
    assert fisher.achievable_rho_s_limit_db(-60.0) == pytest.approx(10 * math.log10(2 * math.sqrt(2 / math.pi)),
                                                                     abs=1e-5)


def test_achievable_crossing_limit_is_a_root_of_the_quadrature():
    x = fisher.achievable_rho_s_crossing_limit()
    assert 0.0 < x < fisher.ACHIEVABLE_LIMIT_SNR_MAX_DB
    assert _inverse_sqrt_quad(10.0 ** (x / 10.0)) == pytest.approx(2.0, rel=1e-8)


def test_locally_constant_smoother_variance_is_sigma_z_over_2_sqrt_f():
    """The ingredient of the alpha -> 1 achievable limit: for constant information F per step, the
    steady-state smoothing BIM (24)+(27) tends to 2 sqrt(F)/sigma_z as sigma_z -> 0 and alpha -> 1."""
    from netrepro.papers.onebit.randomwalk import rw_filtering_fixed_point, rw_smoothing_gain_fixed_point

    F = 0.37
    for sz2 in (1e-6, 1e-8):
        eps = sz2 / 2.0 * 1e-4          # the mean reversion's prior information is negligible
        js = rw_filtering_fixed_point(F, eps, sz2) + rw_smoothing_gain_fixed_point(F, eps, sz2)
        assert float(js) * math.sqrt(sz2) / (2.0 * math.sqrt(F)) == pytest.approx(1.0, rel=2e-3)
