"""`hinf.analysis` (issue 29: the evidence's mathematics) against independent computations: the noise
covariance and its derivatives written out entry by entry, the information form of eq (6), the scalar
fixed point of the steady-state Riccati equation, scipy's Pearson correlation, hand-made series."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats

from netrepro.papers.hinf import analysis as an
from netrepro.papers.hinf.filters import FilterDoesNotExist
from netrepro.papers.hinf.motion import control_law, printed_control_law, printed_sigma_gradient, sigma_gradient
from netrepro.papers.hinf.noise import NoiseModel, printed_dinfo_dtheta

MODEL = NoiseModel(a0=0.3528, a1=15.625, a2=0.0008, alpha=5.0)


# ----------------------------------------------------------------------------- closed forms of eqs (3)-(4)
def cov_hand(r, th, m=MODEL):
    """M = T diag(f_r, f_b) T^T written out entry by entry."""
    fr = m.a2 * (r - m.a1) ** 2 + m.a0
    fb = m.alpha * fr
    c, s = math.cos(th), math.sin(th)
    return np.array([[fr * c * c + fb * s * s, (fr - fb) * c * s], [(fr - fb) * c * s, fr * s * s + fb * c * c]])


def dcov_dr_hand(r, th, m=MODEL):
    c, s = math.cos(th), math.sin(th)
    d = 2 * m.a2 * (r - m.a1)
    return d * np.array([[c * c + m.alpha * s * s, (1 - m.alpha) * c * s], [(1 - m.alpha) * c * s, s * s + m.alpha * c * c]])


def dcov_dth_hand(r, th, m=MODEL):
    fr = m.a2 * (r - m.a1) ** 2 + m.a0
    fb = m.alpha * fr
    s2, c2 = math.sin(2 * th), math.cos(2 * th)
    return np.array([[(fb - fr) * s2, (fr - fb) * c2], [(fr - fb) * c2, (fr - fb) * s2]])


def dinfo(dM, M):
    """d(M^-1) = -M^-1 dM M^-1."""
    Mi = np.linalg.inv(M)
    return -Mi @ dM @ Mi


def info_sum_hand(target, agents):
    S = np.zeros((2, 2))
    for p in agents:
        dx, dy = target[0] - p[0], target[1] - p[1]
        S += np.linalg.inv(cov_hand(math.hypot(dx, dy), math.atan2(dy, dx)))
    return S


def sigma_info_form(Delta, S, g2, Lbar):
    """Sigma of eq (6) in information form: (Delta^-1 + S - gamma^-2 Lbar)^-1."""
    return np.linalg.inv(np.linalg.inv(Delta) + S - g2 * Lbar)


@pytest.fixture(scope="module")
def geo():
    return an.errata_geometry(np.random.default_rng(3), 3.0)


# ----------------------------------------------------------------------------- tests
def test_relative_distance_by_hand():
    assert an.relative_distance([3.0, 9.0], [3.0, 4.0]) == pytest.approx(1.0)
    assert an.relative_distance(np.eye(2) * 2, np.eye(2)) == pytest.approx(1.0)


def test_information_at_positions_is_the_inverse_covariance_written_out():
    rng = np.random.default_rng(0)
    target, agents = rng.normal(size=(3, 2)) * 10, rng.normal(size=(3, 4, 2)) * 20
    info = an.information_at_positions(target, agents, MODEL)
    for i in range(3):
        for j in range(4):
            dx, dy = target[i] - agents[i, j]
            np.testing.assert_allclose(info[i, j], np.linalg.inv(cov_hand(math.hypot(dx, dy), math.atan2(dy, dx))),
                                       rtol=1e-12)


def test_covariance_form_residuals_against_the_covariance_written_out():
    r, th = 27.0, 0.9
    printed, corrected = an.covariance_form_residuals(np.random.default_rng(1), MODEL, r, th, 200_000)
    M = cov_hand(r, th)
    c, s = math.cos(th), math.sin(th)
    fr = MODEL.a2 * (r - MODEL.a1) ** 2 + MODEL.a0
    root = np.array([[c, -s], [s, c]]) @ np.diag([math.sqrt(fr), math.sqrt(MODEL.alpha * fr)])
    # sampling error of a covariance from 2e5 draws: about sqrt(2 / n) ~ 0.003 relative
    assert corrected < 0.01
    assert printed == pytest.approx(np.linalg.norm(root - M) / np.linalg.norm(M), abs=0.01)


def test_sigma_of_the_geometry_is_the_information_form(geo):
    S = info_sum_hand(geo.target, geo.agents)
    np.testing.assert_allclose(geo.sigma(MODEL), sigma_info_form(geo.Delta, S, geo.gamma_inv2, geo.Lbar), rtol=1e-10)
    printed, corrected = an.sigma_form_residuals(geo, MODEL)
    eye = np.eye(2)
    sig_printed = geo.Delta @ np.linalg.inv(eye - geo.gamma_inv2 * geo.Lbar @ geo.Delta - S @ geo.Delta)
    true = sigma_info_form(geo.Delta, S, geo.gamma_inv2, geo.Lbar)
    assert corrected < 1e-10
    assert printed == pytest.approx(np.linalg.norm(sig_printed - true) / np.linalg.norm(true), rel=1e-8)


def test_sigma_gradient_residuals_against_the_closed_form_derivative(geo):
    # dSigma/dr_1 with Delta fixed: -Sigma (dM_1^-1/dr) Sigma, dM^-1/dr from the covariance written out
    S = info_sum_hand(geo.target, geo.agents)
    sig = sigma_info_form(geo.Delta, S, geo.gamma_inv2, geo.Lbar)
    dS = dinfo(dcov_dr_hand(geo.r[0], geo.theta[0]), cov_hand(geo.r[0], geo.theta[0]))
    exact = -sig @ dS @ sig
    printed, corrected, spread = an.sigma_gradient_residuals(geo, MODEL)
    prin = printed_sigma_gradient(geo.Delta, np.zeros((2, 2)), S, dS, geo.gamma_inv2, geo.Lbar)
    assert corrected < 1e-6
    # the spread over step sizes brackets the corrected residual: it is the finite difference's own error
    assert 0 < spread and corrected <= 3 * spread
    assert printed == pytest.approx(np.linalg.norm(prin - exact) / np.linalg.norm(exact), rel=1e-4)
    assert printed > 0.1


def test_bearing_and_range_derivative_residuals_against_closed_forms():
    radii, th = (5.0, 27.0, 45.0), 0.9
    printed, corrected = an.bearing_derivative_residuals(MODEL, radii, th)
    ref = [np.linalg.norm(printed_dinfo_dtheta(r, th, MODEL) - dinfo(dcov_dth_hand(r, th), cov_hand(r, th)))
           / np.linalg.norm(dinfo(dcov_dth_hand(r, th), cov_hand(r, th))) for r in radii]
    assert corrected < 1e-6
    assert printed == pytest.approx(max(ref), rel=1e-4)
    # E9: the 'variances' reading is the derivative; the square-root reading is off by the ratio of the two
    printed9, corrected9 = an.range_derivative_reading_residuals(MODEL, radii, th)
    assert corrected9 < 1e-6 and printed9 > 0.1


def test_control_direction_residuals_against_an_independent_gradient(geo):
    # grad_p J of J = tr Sigma(p) in information form, by a 4th-order stencil over the hand-written covariance
    def J(p):
        ag = geo.agents.copy()
        ag[0] = p
        return np.trace(sigma_info_form(geo.Delta, info_sum_hand(geo.target, ag), geo.gamma_inv2, geo.Lbar))

    h = 1e-3
    grad = np.array([(-J(geo.agents[0] + 2 * h * e) + 8 * J(geo.agents[0] + h * e) - 8 * J(geo.agents[0] - h * e)
                      + J(geo.agents[0] - 2 * h * e)) / (12 * h) for e in np.eye(2)])
    desc = -grad / np.linalg.norm(grad)
    printed, corrected = an.control_direction_residuals(geo, MODEL)
    S = info_sum_hand(geo.target, geo.agents)
    r, th = geo.r[0], geo.theta[0]
    zero = np.zeros((2, 2))
    _, sr = sigma_gradient(geo.Delta, zero, S, dinfo(dcov_dr_hand(r, th), cov_hand(r, th)), geo.gamma_inv2, geo.Lbar)
    _, st = sigma_gradient(geo.Delta, zero, S, dinfo(dcov_dth_hand(r, th), cov_hand(r, th)), geo.gamma_inv2, geo.Lbar)
    u_c = control_law(np.trace(sr), np.trace(st), r, th, 1.0)
    u_p = printed_control_law(np.trace(sr), np.trace(st), r, th, 1.0)
    assert corrected == pytest.approx(1 - u_c @ desc / np.linalg.norm(u_c), abs=1e-7)
    assert corrected < 1e-6
    assert printed == pytest.approx(1 - u_p @ desc / np.linalg.norm(u_p), abs=1e-6)


def test_average_information_residuals(geo):
    printed, corrected, offset = an.average_information_residuals(geo, MODEL)
    S = info_sum_hand(geo.target, geo.agents)
    true = sigma_info_form(geo.Delta, S, geo.gamma_inv2, geo.Lbar)
    avg = sigma_info_form(geo.Delta, S / 4, geo.gamma_inv2, geo.Lbar)
    assert corrected < 1e-12 and printed > 0.1
    assert offset == pytest.approx(np.linalg.norm(avg - true) / np.linalg.norm(true), rel=1e-8)


def test_errata_residuals_corrected_forms_beat_the_printed_ones():
    res = an.errata_residuals(MODEL, 3.0, seed=5, n_samples=50_000)
    assert res["E4_radii"] == (5.0, MODEL.a1, 27.0, 45.0)
    for eid in ("E1", "E2", "E3", "E4", "E5", "E6", "E9"):
        printed, corrected = res[eid][:2]
        assert corrected < 0.05 and printed > 10 * corrected, eid


def test_order_violation_and_settles_first_by_hand():
    assert an.order_violation(2.0, 1.5) == 0.0 and an.order_violation(1.5, 2.0) == pytest.approx(0.5)
    a = [5, 3, 1, 0.5, 0.2]      # below 1 from k = 3
    b = [5, 4, 3, 2, 0.9]        # below 1 from k = 4
    never = [5, 4, 3, 2, 1.5]
    assert an.settles_first(a, b, 1.0) == (True, 3, 4)
    assert an.settles_first(b, a, 1.0) == (False, 4, 3)
    assert an.settles_first(a, never, 1.0) == (True, 3, -1)
    assert an.settles_first(never, a, 1.0) == (False, -1, 3)


def test_difference_correlation_is_scipy_pearson_and_nan_when_constant():
    rng = np.random.default_rng(2)
    a, b, c = rng.normal(size=30), rng.normal(size=30), rng.normal(size=30)
    assert an.difference_correlation(a, b, c) == pytest.approx(stats.pearsonr(a - b, c).statistic, rel=1e-12)
    assert math.isnan(an.difference_correlation(np.arange(30.0), np.arange(30.0) - 1.0, c))  # d = 1 exactly
    assert math.isnan(an.difference_correlation(a, b, np.ones(30)))


def test_disturbance_weight_by_hand():
    L, Q = np.array([[1.0, 2.0]]), np.array([[3.0]])
    np.testing.assert_allclose(an.disturbance_weight(L, Q), [[3.0, 6.0], [6.0, 12.0]])


def test_mean_gain_norms_kalman_scalar_fixed_point():
    # isotropic information c I at every sensor: Delta = d I with d = d / (1 + c d) + W, i.e.
    # c d^2 - c W d - W = 0; K = c d / (1 + c d), K~ = d / (1 + c d); centralized with N c in place of c
    c, W, N = 2.0, 0.01, 3
    info = np.broadcast_to(c * np.eye(2), (2, N, 2, 2)).copy()

    def d_of(cc):
        return (cc * W + math.sqrt((cc * W) ** 2 + 4 * cc * W)) / (2 * cc)

    d, dc = d_of(c), d_of(N * c)
    K, Kt, Kc, Ktc = an.mean_gain_norms(info, W, math.inf, np.eye(2))
    assert K == pytest.approx(c * d / (1 + c * d), rel=1e-9)
    assert Kt == pytest.approx(d / (1 + c * d), rel=1e-9)
    assert Kc == pytest.approx(c * dc / (1 + N * c * dc), rel=1e-9)
    assert Ktc == pytest.approx(dc / (1 + N * c * dc), rel=1e-9)


def test_mean_gain_norms_refuses_a_gamma_below_gamma0():
    info = np.broadcast_to(0.5 * np.eye(2), (1, 2, 2, 2)).copy()
    with pytest.raises(FilterDoesNotExist, match="does not exist at gamma = 0.1"):
        an.mean_gain_norms(info, 0.01, 0.1, np.eye(2))


@pytest.mark.parametrize("a1, step, expected", [(15.625, 0.5, 15.5), (15.625, 0.25, 15.5), (20.4, 1.0, 20.0)])
def test_sweet_spot_grid_is_the_grid_point_nearest_a1(a1, step, expected):
    # f_r is a parabola with vertex a1 and tr M = (1 + alpha) f_r, det M = alpha f_r^2: both minimised nearest a1
    # (15.625 with step 0.25 is a tie between 15.5 and 15.75: the first is taken)
    model = NoiseModel(a0=0.3, a1=a1, a2=0.001, alpha=4.0)
    r_tr, r_det, got_step = an.sweet_spot_grid(model, 60.0, step)
    assert (r_tr, r_det, got_step) == (expected, expected, step)


def test_covariance_sampling_scale_against_replicated_sample_covariances():
    # the RMS relative distance of sample covariances (n = 40 draws, 4000 replicates) to the true covariance
    M = np.array([[2.0, 0.6], [0.6, 0.5]])
    rng = np.random.default_rng(11)
    x = rng.multivariate_normal(np.zeros(2), M, size=(4000, 40))
    xc = x - x.mean(1, keepdims=True)
    S = np.einsum("rni,rnj->rij", xc, xc) / 39
    rms = np.sqrt(np.mean(np.linalg.norm(S - M, axis=(1, 2)) ** 2)) / np.linalg.norm(M)
    assert an.covariance_sampling_scale(M, 40) == pytest.approx(rms, rel=0.05)
