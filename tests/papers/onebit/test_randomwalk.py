"""Tests of netrepro.papers.onebit.randomwalk: each equation against an independent computation."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy import integrate, linalg, stats

from netrepro.engines.kernels import scalar_information_steps
from netrepro.papers.onebit import fisher
from netrepro.papers.onebit import model
from netrepro.papers.onebit import randomwalk
from netrepro.papers.onebit.model import axis_shift_db
from netrepro.papers.onebit.randomwalk import ratios_at, snr_shift_deviation

ROOT = Path(__file__).resolve().parents[3]


def test_stable_forms_equal_printed_scalar_equations():
    eps, s, F = 0.05, 0.2, 0.8
    a = 1 - eps
    J = np.linspace(0.5, 20, 9)
    printed24 = 1 / s + F - (a / s) ** 2 / (J + a * a / s)
    np.testing.assert_allclose(randomwalk.rw_filtering_step(J, F, eps, s), printed24, rtol=1e-13)
    printed25 = 1 / s - (a / s) ** 2 / (a * a / s + J)
    np.testing.assert_allclose(randomwalk.rw_prediction_step(J, eps, s), printed25, rtol=1e-13)
    kap = np.linspace(0, 10, 9)
    printed27 = a * a / s - (a / s) ** 2 / (1 / s + F + kap)
    np.testing.assert_allclose(randomwalk.rw_smoothing_gain_step(kap, F, eps, s), printed27, rtol=1e-12)
    # the scalar step equals the general step with the blocks (22)
    D11, D12, D22 = model.linear_gaussian_blocks([[a]], [[s]])
    assert D11[0, 0] == pytest.approx(a * a / s) and D12[0, 0] == pytest.approx(-a / s)
    assert float(model.filtering_bim_step([[3.0]], D11, D12, D22, [[F]])[0, 0]) == pytest.approx(
        float(randomwalk.rw_filtering_step(3.0, F, eps, s)), rel=1e-13)


@pytest.mark.parametrize("eps,s,F", [(1e-3, 1e-4, 0.6), (1e-2, 0.5, 0.07), (0.3, 2.0, 1.0), (1e-5, 2e-8, 0.63)])
def test_fixed_points_match_dare_and_long_iteration(eps, s, F):
    a = 1 - eps
    Jstar = float(randomwalk.rw_filtering_fixed_point(F, eps, s))
    M = linalg.solve_discrete_are(np.array([[a]]), np.array([[1.0]]), np.array([[s]]), np.array([[1 / F]]))[0, 0]
    assert 1 / M + F == pytest.approx(Jstar, rel=1e-9)  # DARE: predicted variance M
    J, kap = 1.0, 0.0
    kstar = float(randomwalk.rw_smoothing_gain_fixed_point(F, eps, s))
    for _ in range(400_000 if eps < 1e-4 else 60_000):
        J = randomwalk.rw_filtering_step(J, F, eps, s)
        kap = randomwalk.rw_smoothing_gain_step(kap, F, eps, s)
    assert J == pytest.approx(Jstar, rel=1e-10)
    assert kap == pytest.approx(kstar, rel=1e-10)
    # and the smoothing variance equals the steady-state RTS variance
    Pf = 1 / Jstar
    Pp = a * a * Pf + s
    G = Pf * a / Pp
    Ps = Pf * (1 - G * G * Pp / Pf) / (1 - G * G)   # P_s = P_f + G^2 (P_s - P_p)
    assert 1 / (Jstar + kstar) == pytest.approx(Ps, rel=1e-8)


def test_lag_closed_form_equals_iteration():
    eps = 1e-3
    snr_db = np.arange(-30, 21, 2.5)
    s = model.sigma_z2_from_snr(snr_db, eps)
    F = fisher.expected_fisher_1bit(model.stationary_variance(eps, s))
    for tol in (0.01, 0.001):
        np.testing.assert_array_equal(randomwalk.rw_lag_needed(F, eps, s, tol), randomwalk.rw_lag_iterated(F, eps, s, tol))
    assert np.all(randomwalk.rw_lag_needed(F, eps, s, 0.01) > 0)


def test_ratios_tend_to_limit_and_limit_values():
    snr_db = np.array([-20.0, 0.0, 10.0])
    lim = randomwalk.information_ratios_limit(snr_db)
    near = randomwalk.information_ratios(snr_db, 1e-10)
    for key in ("rho_sl_db", "rho_f_db", "rho_s_db"):
        np.testing.assert_allclose(near[key], lim[key], atol=2e-3)
    low = randomwalk.information_ratios_limit(np.array([-80.0]))
    assert low["rho_f_db"][0] == pytest.approx(5 * math.log10(2 / math.pi), abs=1e-6)
    assert low["rho_s_db"][0] == pytest.approx(10 * math.log10(2 * math.sqrt(2 / math.pi)), abs=1e-6)
    r = randomwalk.information_ratios(np.linspace(-30, 20, 11), 1e-3)
    assert np.all(r["rho_s_db"] > r["rho_f_db"])
    assert np.all(r["j_s_q"] <= r["j_s_inf"]) and np.all(r["j_f_q"] <= r["j_f_inf"])


def test_transient_iteration_reaches_fixed_point():
    out = randomwalk.iterate_transient([-10.0, 10.0], 1e-2, 1.0, 0.0, 1.0, 6000, 1e-9, record=[0, 10, 100])
    np.testing.assert_allclose(out["j_f_q"], out["j_f_q_star"], rtol=1e-9)
    np.testing.assert_allclose(out["j_f_inf"], out["j_f_inf_star"], rtol=1e-12)
    assert np.all(out["k_conv_q"] < 6000)
    assert out["trace"]["j_f_q_ratio"].shape == (3, 2)
    with pytest.raises(ValueError, match="mu0"):
        randomwalk.iterate_transient([0.0], 1e-2, 1.0, 1.0, 1.0, 10, 1e-9)


def test_compiled_bim_steps_equal_numpy_loop_and_general_recursion_7():
    """(24)/(34) as compiled: bit-identical to the numpy loop it replaced, and equal to the general (7)
    with the random walk's D11 = a^2/s, D12 = -a/s, D22 = 1/s (an independent form)."""
    rng = np.random.default_rng(3)
    a2, s2 = 0.98**2, rng.uniform(0.01, 2.0, 6)
    F = rng.uniform(0.0, 3.0, (50, 6))
    j0 = rng.uniform(0.1, 5.0, 6)
    j, J = j0.copy(), np.empty_like(F)
    scalar_information_steps(j, a2, s2, F, J)
    ref, tmp, out = j0.copy(), np.empty(6), []
    for i in range(len(F)):  # the numpy form
        np.divide(a2, ref, out=tmp)
        tmp += s2
        np.divide(1.0, tmp, out=ref)
        ref += F[i]
        out.append(ref.copy())
    assert np.array_equal(J, np.array(out)) and np.array_equal(j, J[-1])
    a = np.sqrt(a2)
    for lane in range(6):
        s = s2[lane]
        general = model.filtering_bims(j0[lane], a2 / s, -a / s, 1.0 / s, F[:, lane].reshape(-1, 1, 1), len(F))
        assert np.allclose(general[1:, 0, 0], J[:, lane], rtol=1e-12)


def _break_even_by_hand(F, eps, s, max_steps=100_000):
    """J_{k|k,q} + kappa_Delta > J_{k|k,inf}: long iterations of the printed (24) and (27), no module helper."""
    a = 1 - eps
    jq = ji = 1.0
    for _ in range(200_000):
        jq = 1 / s + F - (a / s) ** 2 / (jq + a * a / s)
        ji = 1 / s + 1.0 - (a / s) ** 2 / (ji + a * a / s)
    kap = 0.0
    for n in range(1, max_steps + 1):
        kap = a * a / s - (a / s) ** 2 / (1 / s + F + kap)
        if jq + kap > ji:
            return n
    return -1


@pytest.mark.parametrize("eps", [1e-2, 1e-3])
def test_break_even_lag_against_direct_iteration(eps):
    snr_db = np.array([-30.0, -20.0, -10.0, -3.0, 0.0, 4.0, 10.0, 20.0])
    s = model.sigma_z2_from_snr(snr_db, eps)
    Fq = fisher.expected_fisher_1bit(model.stationary_variance(eps, s))
    closed = randomwalk.rw_break_even_lag(Fq, 1.0, eps, s)
    np.testing.assert_array_equal(closed, randomwalk.rw_break_even_iterated(Fq, 1.0, eps, s))
    for i in range(len(s)):
        assert closed[i] == _break_even_by_hand(float(Fq[i]), eps, float(s[i])), snr_db[i]
    # it exists exactly where rho_S > 0 dB (49)
    rho_s = randomwalk.information_ratios(snr_db, eps)["rho_s_db"]
    np.testing.assert_array_equal(closed < 0, rho_s <= 0)


def test_filter_time_constant_from_dare_gain():
    eps, s, F = 1e-3, 2e-4, 0.6
    a = 1 - eps
    M = linalg.solve_discrete_are(np.array([[a]]), np.array([[1.0]]), np.array([[s]]), np.array([[1 / F]]))[0, 0]
    G = M * F / (1 + M * F)                         # steady-state Kalman gain with noise variance 1/F
    assert float(randomwalk.rw_filter_time_constant(F, eps, s)) == pytest.approx(-1 / math.log(a * (1 - G)), rel=1e-8)


def test_bound_paths_and_design_are_in_steady_state_inside_the_window():
    eps, s = 1e-3, float(model.sigma_z2_from_snr(0.0, 1e-3))
    Fq = float(fisher.expected_fisher_1bit(model.stationary_variance(eps, s)))
    d = randomwalk.estimator_design((Fq, 1.0), eps, s, 5.0, 3.0, 5.0, 4.0)
    assert d["start"] >= 5 * d["tau"] and d["horizon"] - d["stop"] >= 5 * d["tau"]
    assert np.all((d["eval_idx"] >= d["start"]) & (d["eval_idx"] < d["stop"]))
    v = float(model.stationary_variance(eps, s))
    for F in (Fq, 1.0):
        Jf, Js = randomwalk.bound_paths(F, eps, s, v, d["horizon"])
        jf = float(randomwalk.rw_filtering_fixed_point(F, eps, s))
        js = jf + float(randomwalk.rw_smoothing_gain_fixed_point(F, eps, s))
        ev = d["eval_idx"]
        assert np.max(np.abs(Jf[ev] / jf - 1)) < 1e-3 and np.max(np.abs(Js[ev] / js - 1)) < 1e-3
        assert abs(Jf[1] / jf - 1) > 1e-2          # while the start of the record is not
    # J_s over the record = RTS smoothing variances (covariance form, another algorithm)
    _, _, Ps = model.kalman_covariances(np.array([[1 - eps]]), np.array([[s]]), np.array([[1.0]]), np.array([[1.0]]),
                                        np.array([[v]]), 200)
    _, Js = randomwalk.bound_paths(1.0, eps, s, v, 200)
    np.testing.assert_allclose(1 / Js, Ps[:, 0, 0], rtol=1e-10)


def test_rho_s_crossings_and_alpha_threshold():
    near_limit = randomwalk.rho_s_zero_crossing(1e-9)
    assert near_limit == pytest.approx(fisher.rho_s_zero_crossing_limit(), abs=0.05)   # alpha -> 1: E[F_q] = 1/4
    x = randomwalk.rho_s_zero_crossing(1e-3)
    r = randomwalk.information_ratios(np.array([x - 1e-3, x + 1e-3]), 1e-3)["rho_s_db"]
    assert r[0] > 0 >= r[1]
    e = randomwalk.rho_s_threshold_eps(-20.0)
    r = [float(randomwalk.information_ratios(np.array([-20.0]), v)["rho_s_db"][0]) for v in (e * 0.999, e * 1.001)]
    assert r[0] > 0 >= r[1]


# ratios_at, axis_shift_db, snr_shift_deviation (moved from evidence.py, issue 29): against plain loops

def _efq_by_quad(var):
    """(29) with (30), sigma_eta = 1, by adaptive quadrature of the plain formula (no product-Gaussian trick)."""
    def f(t):
        q = stats.norm.sf(t) * stats.norm.cdf(t)
        return math.exp(-t * t) / (2 * math.pi * q) * stats.norm.pdf(t, scale=math.sqrt(var))
    sd = math.sqrt(var)
    return integrate.quad(f, -12 * sd, 12 * sd, points=[0.0], limit=400, epsabs=0, epsrel=1e-12)[0]


def _ratios_by_iteration(eps, sigma_z2, F_q, n=200_000):
    """(24)/(34) and (27)/(37)-(38) iterated to their fixed points (plain loops), then (47)-(49) in dB."""
    a = 1.0 - eps

    def fixed(F):
        J = 1.0
        for _ in range(n):
            J_new = 1 / sigma_z2 + F - (a / sigma_z2) ** 2 / (J + a * a / sigma_z2)
            if abs(J_new - J) <= 1e-15 * J_new:
                break
            J = J_new
        k = 0.0
        for _ in range(n):
            k_new = a * a / sigma_z2 - (a / sigma_z2) ** 2 / (1 / sigma_z2 + F + k)
            if abs(k_new - k) <= 1e-15 * abs(k_new):
                break
            k = k_new
        return J, J + k

    jf_i, js_i = fixed(1.0)
    jf_q, js_q = fixed(F_q)
    db = lambda x: 10 * math.log10(x)  # noqa: E731
    return dict(rho_sl_db=db(js_q / js_i), rho_f_db=db(jf_q / jf_i), rho_s_db=db(js_q / jf_i))


@pytest.mark.parametrize("eps,snr_db,definition", [(1e-2, 0.0, "stationary"), (1e-1, -10.0, "stationary"),
                                                   (1e-2, -20.0, "innovation")])
def test_ratios_at_against_plain_iteration(eps, snr_db, definition):
    snr = 10 ** (snr_db / 10)
    s = snr * eps * (2 - eps) if definition == "stationary" else snr
    var = s / (eps * (2 - eps))
    ref = _ratios_by_iteration(eps, s, _efq_by_quad(var))
    ours = ratios_at([snr_db], eps, 1.0, definition)
    for k, v in ref.items():
        assert ours[k][0] == pytest.approx(v, abs=1e-6), k


def test_limit_low_snr_closed_form():
    """alpha -> 1 and SNR -> 0: rho_F = rho_SL = sqrt(2/pi), rho_S = 2 sqrt(2/pi) (Sec. 1, Sec. 5)."""
    r = ratios_at([-80.0], 0.0)
    assert r["rho_f_db"][0] == pytest.approx(5 * math.log10(2 / math.pi), abs=1e-6)
    assert r["rho_sl_db"][0] == pytest.approx(5 * math.log10(2 / math.pi), abs=1e-6)
    assert r["rho_s_db"][0] == pytest.approx(10 * math.log10(2 * math.sqrt(2 / math.pi)), abs=1e-6)
    assert np.isnan(ratios_at([-10.0], 0.0, definition="innovation")["rho_s_db"][0])


def test_limit_is_approached_by_finite_alpha():
    """The closed-form limit against the plain iteration at a tiny 1 - alpha (fixed stationary SNR 0 dB)."""
    eps = 1e-7
    s = eps * (2 - eps)
    ref = _ratios_by_iteration(eps, s, _efq_by_quad(1.0), n=2_000_000)
    lim = ratios_at([0.0], 0.0)
    for k, v in ref.items():
        assert lim[k][0] == pytest.approx(v, abs=2e-3), k


@pytest.mark.parametrize("eps", [1e-3, 1e-5, 0.3])
def test_axis_shift(eps):
    """The innovation SNR is the stationary SNR times 1 - alpha^2, (33); the curves coincide after the shift."""
    a = 1 - eps
    assert axis_shift_db(eps) == pytest.approx(10 * math.log10(1 - a * a), rel=1e-12)
    snr_stat = -12.0
    s = 10 ** (snr_stat / 10) * (1 - a * a)          # the same sigma_z^2 ...
    snr_inno = 10 * math.log10(s)                     # ... labelled by the innovation reading
    ours = ratios_at([snr_inno], eps, 1.0, "innovation")
    ref = _ratios_by_iteration(eps, s, _efq_by_quad(10 ** (snr_stat / 10)))
    for k, v in ref.items():
        assert ours[k][0] == pytest.approx(v, abs=1e-6), k
    assert snr_shift_deviation(np.array([-30.0, 0.0, 10.0]), eps) < 1e-9


def test_ratio_window_of_fig1_by_plain_iteration():
    """The window where rho_SL(alpha = 1 - 1e-5) is within 0.005 dB of -0.98 dB, checked at its ends by iteration."""
    grid = np.arange(-40.0, -15.0 + 0.25, 0.5)
    lo, hi = randomwalk.ratio_window(grid, 1e-5, "rho_sl_db", -0.98, 0.005)
    assert -40.0 < lo < hi < -15.0
    eps = 1e-5
    for snr_db, inside in ((lo, True), (lo - 0.5, False), (hi, True), (hi + 0.5, False)):
        s = 10 ** (snr_db / 10) * eps * (2 - eps)
        ref = _ratios_by_iteration(eps, s, _efq_by_quad(10 ** (snr_db / 10)), n=3_000_000)["rho_sl_db"]
        assert (abs(ref + 0.98) <= 0.005) is inside, snr_db
    assert all(math.isnan(v) for v in randomwalk.ratio_window(grid, 1e-5, "rho_sl_db", 5.0, 0.005))


def test_ratios_without_mean_reversion_by_plain_iteration():
    """alpha = 1 in the recursions with the sigma_z^2 and E[F_q] of alpha = 1 - 1e-5: the plain loops at eps = 0."""
    eps, snr_db = 1e-5, -50.0
    s = 10 ** (snr_db / 10) * eps * (2 - eps)
    ref = _ratios_by_iteration(0.0, s, _efq_by_quad(10 ** (snr_db / 10)), n=3_000_000)
    ours = randomwalk.ratios_without_mean_reversion([snr_db], eps)
    for k, v in ref.items():
        assert ours[k][0] == pytest.approx(v, abs=1e-6), k
    # with the mean reversion the prior information lifts rho_SL towards 0 dB; without it, it stays near -0.98 dB
    assert ratios_at([snr_db], eps)["rho_sl_db"][0] > ours["rho_sl_db"][0] + 0.3
