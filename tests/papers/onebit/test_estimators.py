"""Tests of netrepro.papers.onebit.estimators: each equation against an independent computation."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from netrepro.errors import InputError
from netrepro.papers.onebit import estimators
from netrepro.papers.onebit import model

ROOT = Path(__file__).resolve().parents[3]


def test_grid_filter_without_data_information_keeps_prior_mean():
    r = np.ones((3, 5))
    filt, smooth = estimators.grid_filter_smoother(r, 0.1, 0.2, 1e6)  # huge noise: 1-bit data carry ~no information
    np.testing.assert_allclose(filt, 0.0, atol=1e-5)
    np.testing.assert_allclose(smooth, 0.0, atol=1e-5)


def test_grid_filter_reproduces_kalman_on_unquantized_data():
    eps, s = 1e-2, float(model.sigma_z2_from_snr(0.0, 1e-2))
    rng = np.random.default_rng(11)
    theta, y, r = estimators.simulate_block(rng, 20, 60, eps, s, 1.0)
    filt, smooth = estimators.grid_filter_smoother(y, eps, s, 1.0, 8.0, 2.0, quantized=False)
    kf, rts = estimators.kalman_rts(y, eps, s, 1.0)
    sd = math.sqrt(float(model.stationary_variance(eps, s)))
    assert np.max(np.abs(filt - kf)) < 1e-6 * sd
    assert np.max(np.abs(smooth - rts)) < 1e-6 * sd


def _kalman_rts_means(y, a, s, r_var, P0):
    """Textbook scalar Kalman filter and RTS smoother (independent of the module)."""
    n, K = y.shape
    mf, Pf = np.zeros((n, K + 1)), np.zeros(K + 1)
    mp, Pp = np.zeros((n, K + 1)), np.zeros(K + 1)
    Pf[0] = P0
    for k in range(1, K + 1):
        mp[:, k], Pp[k] = a * mf[:, k - 1], a * a * Pf[k - 1] + s
        G = Pp[k] / (Pp[k] + r_var)
        mf[:, k], Pf[k] = mp[:, k] + G * (y[:, k - 1] - mp[:, k]), (1 - G) * Pp[k]
    ms = mf.copy()
    for k in range(K - 1, -1, -1):
        C = Pf[k] * a / Pp[k + 1]
        ms[:, k] = mf[:, k] + C * (ms[:, k + 1] - mp[:, k + 1])
    return mf, ms


@pytest.mark.parametrize("snr_db", [-20.0, 0.0, 10.0])
def test_banded_grid_smoother_equals_kalman_rts_on_unquantized_data(snr_db):
    """The estimator of issue 17 (banded transition, evaluation steps only) in the unquantized case = Kalman/RTS."""
    eps = 1e-3
    s = float(model.sigma_z2_from_snr(snr_db, eps))
    theta, y, r = estimators.simulate_block(np.random.default_rng(2), 30, 300, eps, s, 1.0)
    ev = np.arange(40, 300, 7)
    filt, smooth = estimators.grid_smoother_at(y, eps, s, 1.0, ev, quantized=False)
    kf, rts = _kalman_rts_means(y, 1 - eps, s, 1.0, s / (eps * (2 - eps)))
    sd = math.sqrt(s / (eps * (2 - eps)))
    assert np.max(np.abs(filt - kf[:, ev])) < 1e-6 * sd
    assert np.max(np.abs(smooth - rts[:, ev])) < 1e-6 * sd


def test_banded_transition_equals_dense_on_one_bit_data():
    eps = 1e-3
    s = float(model.sigma_z2_from_snr(5.0, eps))
    _, _, r = estimators.simulate_block(np.random.default_rng(4), 10, 200, eps, s, 1.0)
    ev = np.arange(0, 201, 10)
    fb, sb = estimators.grid_smoother_at(r, eps, s, 1.0, ev)
    fd, sd_ = estimators.grid_smoother_at(r, eps, s, 1.0, ev, band_sigmas=None)
    assert np.max(np.abs(fb - fd)) < 1e-10 and np.max(np.abs(sb - sd_)) < 1e-10
    # a finer and wider grid changes the estimates by far less than their errors (the grid has converged)
    ff, sf = estimators.grid_smoother_at(r, eps, s, 1.0, ev, grid_half_width=7.0, points_per_sigma_z=2.0)
    assert np.max(np.abs(sf - sb)) < 1e-5 and np.max(np.abs(ff - fb)) < 1e-5


def test_banded_transition_rows_are_gaussian_moments():
    eps, s = 1e-3, 2e-3
    x = estimators.state_grid(eps, s, 6.0, 1.0)
    T = estimators.transition_matrix(x, 1 - eps, math.sqrt(s), 8.0)
    assert T.nnz < 20 * len(x)                                        # banded: ~2 * 8 * 1 + 1 entries per row
    T = T.toarray()
    np.testing.assert_allclose(T.sum(axis=1), 1.0, rtol=1e-14)
    inner = np.abs(x) < 5.0 * math.sqrt(s / (eps * (2 - eps)))
    mean = T @ x
    var = T @ x**2 - mean**2
    np.testing.assert_allclose(mean[inner], (1 - eps) * x[inner], atol=1e-9 * math.sqrt(s))   # (21): E = alpha x
    # Var = sigma_z^2 up to the aliasing of sampling a Gaussian at spacing h = sigma_z / p (Poisson summation:
    # leading relative term 4 pi^2 p^2 exp(-2 pi^2 p^2) times 2 cos(.); we allow twice that)
    p = 1.0
    np.testing.assert_allclose(var[inner], s, rtol=8 * math.pi**2 * p**2 * math.exp(-2 * math.pi**2 * p**2))
    with pytest.raises(ValueError, match="uniform"):
        estimators.transition_matrix(np.array([0.0, 1.0, 3.0]), 0.9, 1.0, 8.0)


def test_paired_bootstrap_collapses_for_proportional_runs_and_is_narrower_than_unpaired():
    rng = np.random.default_rng(0)
    common = rng.exponential(1.0, 500)
    a = 2.0 * common
    est, lo, hi = estimators.paired_ratio_interval(a, common, 500, 1)
    assert est == pytest.approx(10 * math.log10(2.0), abs=1e-12)
    assert lo == pytest.approx(est, abs=1e-9) and hi == pytest.approx(est, abs=1e-9)   # same runs resampled together
    b = common * rng.uniform(0.9, 1.1, 500)
    est, lo, hi = estimators.paired_ratio_interval(b, common, 2000, 2)
    # independent resampling of the two arms (what an unpaired design would give) is much wider
    i1, i2 = rng.integers(0, 500, (2, 2000, 500))
    unpaired = 10 * np.log10(b[i1].mean(axis=1) / common[i2].mean(axis=1))
    assert (hi - lo) < 0.3 * np.subtract(*np.percentile(unpaired, [97.5, 2.5]))
    # against the delta method for the log of a ratio of paired means
    d = b / b.mean() - common / common.mean()
    half = 1.959964 * (10 / math.log(10)) * d.std(ddof=1) / math.sqrt(500)
    assert (hi - lo) / 2 == pytest.approx(half, rel=0.15)


def test_db_zero_crossing_linear():
    assert estimators.db_zero_crossing([0.0, 1.0, 2.0], [2.0, 1.0, -1.0]) == pytest.approx(1.5)
    assert math.isnan(estimators.db_zero_crossing([0.0, 1.0], [1.0, 2.0]))


def test_downward_root_of_a_known_parabola():
    # y = -(x - 1)(x - 3): up through 1, down through 3
    coefs = np.polyfit([0.0, 1.0, 2.0, 3.0], [-3.0, 0.0, 1.0, 0.0], 2)
    assert estimators.downward_root(coefs, 0.0, 4.0) == pytest.approx(3.0, abs=1e-9)
    assert math.isnan(estimators.downward_root(coefs, 0.0, 2.5))


def test_local_crossing_fit_recovers_a_known_crossing_and_covers_it():
    """A concave curve with noise of known size: the fit's root against the exact root, and its bootstrap interval."""
    x = np.array([1.0, 1.5, 2.0, 2.5, 3.0])
    truth = lambda t: 0.9 - 0.1 * t - 0.15 * t**2  # noqa: E731  root at t = 2.1 (0.9 = 0.1 t + 0.15 t^2)
    root = (-0.1 + math.sqrt(0.01 + 4 * 0.15 * 0.9)) / (2 * 0.15)
    rng = np.random.default_rng(1)
    sd = 0.05
    y = truth(x) + rng.normal(0, sd, size=x.shape)
    yb = y + rng.normal(0, sd, size=(2000, len(x)))     # replicates with the noise's spread
    fit = estimators.local_crossing_fit(x, y, yb)
    assert fit["lo"] < root < fit["hi"]
    assert abs(fit["estimate"] - root) < 0.15
    exact = estimators.local_crossing_fit(x, truth(x), np.tile(truth(x), (10, 1)))
    assert exact["estimate"] == pytest.approx(root, abs=1e-9) and exact["fail_frac"] == 0.0
    with pytest.raises(InputError, match="need m > degree points"):
        estimators.local_crossing_fit(x[:2], y[:2], yb[:, :2])


def test_bootstrap_ratio_db_matches_a_plain_loop():
    rng = np.random.default_rng(3)
    a, b = rng.exponential(2.0, 50), rng.exponential(1.0, 50)
    reps = estimators.bootstrap_ratio_db(a, b, 30, seed=7, chunk=7)
    g = np.random.default_rng(7)
    plain = []
    for r0 in range(0, 30, 7):
        idx = g.integers(0, 50, size=(min(7, 30 - r0), 50))
        plain += [10 * math.log10(a[i].mean() / b[i].mean()) for i in idx]
    np.testing.assert_allclose(reps, plain, rtol=0, atol=1e-12)
    with pytest.raises(InputError, match="same length"):
        estimators.bootstrap_ratio_db(a, b[:-1], 10, seed=1)


@pytest.mark.parametrize("n_runs, chunk", [(50, 7), (2000, 250), (333, 64)])
def test_paired_ratio_intervals_replicates_are_bootstrap_ratio_db(n_runs, chunk):
    # the estimator step takes rho_S's crossing replicates from the intervals' resampling (same seed) instead
    # of redrawing them with bootstrap_ratio_db: the same numbers, bit for bit (tolerance 0)
    rng = np.random.default_rng(n_runs)
    vals = {k: rng.exponential(s, n_runs) for k, s in (("a", 2.0), ("b", 1.0), ("c", 1.5))}
    pairs = [("a", "b"), ("c", "b"), ("a", "c")]
    out, reps = estimators.paired_ratio_intervals(vals, pairs, 300, 11, replicates=True)
    assert out == estimators.paired_ratio_intervals(vals, pairs, 300, 11)
    for (num, den), rep in zip(pairs, reps):
        assert rep.tobytes() == estimators.bootstrap_ratio_db(vals[num], vals[den], 300, 11, chunk=chunk).tobytes()


@pytest.mark.parametrize("degree", [1, 2, 3])
def test_downward_roots_is_downward_root_row_by_row(degree):
    # the batched form (one eigvals call on the stacked companion matrices) against the per-row function,
    # tolerance 0; rows with a zero leading or trailing coefficient take the per-row path
    rng = np.random.default_rng(degree)
    c = rng.normal(size=(400, degree + 1))
    c[:50, -1] = 0.0
    c[50:60, 0] = 0.0
    c[61:80] = np.round(c[61:80], 1)
    got = estimators.downward_roots(c, -1.5, 1.5)
    want = np.array([estimators.downward_root(row, -1.5, 1.5) for row in c])
    assert got.tobytes() == want.tobytes()
    assert np.isfinite(got).sum() > 50 and np.isnan(got).sum() > 50  # both outcomes exercised


def test_run_tail_statistics_against_direct_formulas():
    rng = np.random.default_rng(5)
    v = rng.lognormal(0.0, 1.0, 400)
    blocks = np.repeat(np.arange(8), 50)
    out = estimators.run_tail_statistics(v, blocks)
    d = v - v.mean()
    assert out["kurtosis"] == pytest.approx(np.mean(d**4) / np.mean(d**2) ** 2, rel=1e-12)
    from scipy import stats
    assert out["kurtosis"] == pytest.approx(stats.kurtosis(v, fisher=False), rel=1e-10)
    means = v.reshape(8, 50).mean(axis=1)
    assert out["se_ratio"] == pytest.approx(means.std(ddof=1) / (v.std(ddof=1) / math.sqrt(50)), rel=1e-12)
    assert out["n_blocks"] == 8 and out["max_over_mean"] == pytest.approx(v.max() / v.mean())
    # iid runs: the ratio is about 1 on average over many independent experiments
    ratios = [estimators.run_tail_statistics(rng.normal(size=400), blocks)["se_ratio"] for _ in range(300)]
    assert abs(np.sqrt(np.mean(np.square(ratios))) - 1.0) < 0.05


def test_pooled_se_ratio_against_chi_square_by_simulation():
    from scipy import stats

    pooled, dof, lo, hi = estimators.pooled_se_ratio([1.0, 1.0], [8, 16])
    assert (pooled, dof) == (1.0, 22)
    assert lo == pytest.approx(math.sqrt(stats.chi2.ppf(0.025, 22) / 22)) and hi > 1.0
    # normal runs with correct standard errors: the pooled ratio falls inside its band about 95 % of the time
    rng = np.random.default_rng(11)
    blocks = np.repeat(np.arange(8), 25)
    inside = 0
    for _ in range(200):
        rs = [estimators.run_tail_statistics(rng.normal(size=200), blocks)["se_ratio"] for _ in range(5)]
        p, _, a, b = estimators.pooled_se_ratio(rs, [8] * 5)
        inside += a <= p <= b
    assert 175 <= inside <= 200
    with pytest.raises(InputError, match="n_blocks >= 2"):
        estimators.pooled_se_ratio([1.0], [1])


def test_paired_db_contrasts_equal_a_direct_gather():
    rng = np.random.default_rng(3)
    n = 300
    v = {k: rng.gamma(2.0, size=n) + 0.1 for k in ("a", "b", "c", "d")}
    contrasts = [[("a", "b", 1.0), ("c", "d", -1.0)], [("a", "c", 1.0)]]
    got = estimators.paired_db_contrasts(v, contrasts, 500, 11)
    idx = np.random.default_rng(11).integers(0, n, size=(500, n))
    m = {k: x[idx].mean(axis=1) for k, x in v.items()}
    rep = 10 * np.log10(m["a"] / m["b"]) - 10 * np.log10(m["c"] / m["d"])
    est = 10 * np.log10(v["a"].mean() / v["b"].mean()) - 10 * np.log10(v["c"].mean() / v["d"].mean())
    assert got[0][0] == pytest.approx(est, rel=1e-12)
    np.testing.assert_allclose(got[0][1:], np.percentile(rep, [2.5, 97.5]), rtol=1e-12)
    assert got[1][0] == pytest.approx(10 * np.log10(v["a"].mean() / v["c"].mean()), rel=1e-12)
    with pytest.raises(InputError):
        estimators.paired_db_contrasts({"a": np.ones(3), "b": np.ones(4)}, [[("a", "b", 1.0)]], 10, 0)


def test_replicate_coverage_matches_a_loop_and_the_nominal_rate():
    rng = np.random.default_rng(5)
    v = rng.normal(2.0, 1.0, size=103)
    got = estimators.replicate_coverage(v, 5)
    parts = np.array_split(v, 5)
    for r, p in enumerate(parts):
        o = np.concatenate([q for j, q in enumerate(parts) if j != r])
        z = (p.mean() - o.mean()) / np.hypot(p.std(ddof=1) / np.sqrt(len(p)), o.std(ddof=1) / np.sqrt(len(o)))
        assert got["z"][r] == pytest.approx(z, rel=1e-10)
        assert got["covered"][r] == (abs(z) <= 1.959963984540054)
    # normal runs against the exact mean: about 95 % of 4000 replicates cover (fixed seed)
    w = rng.normal(2.0, 1.0, size=4000 * 50)
    cov = estimators.replicate_coverage(w, 4000, reference=2.0)["covered"].mean()
    assert 0.935 < cov < 0.965
    # heavy tails (lognormal, sigma 2.5: kurtosis ~ 1e10), small replicates: the normal interval under-covers
    h = rng.lognormal(0.0, 2.5, size=2000 * 50)
    cov_h = estimators.replicate_coverage(h, 2000, reference=float(np.exp(2.5**2 / 2)))["covered"].mean()
    assert cov_h < 0.85
    with pytest.raises(InputError):
        estimators.replicate_coverage(np.ones(5), 3)


def test_binomial_coverage_against_scipy_binomtest():
    from scipy import stats

    for k, n in ((190, 200), (180, 200), (200, 200), (0, 5)):
        got = estimators.binomial_coverage(k, n)
        ref = stats.binomtest(k, n, 0.95, alternative="less")
        ci = stats.binomtest(k, n).proportion_ci(confidence_level=0.95, method="exact")
        assert got["p_under"] == pytest.approx(ref.pvalue, rel=1e-9)
        assert (got["lo"], got["hi"]) == pytest.approx((ci.low, ci.high), abs=1e-9)
    assert estimators.binomial_coverage(180, 200)["p_under"] < 0.05 < estimators.binomial_coverage(190, 200)["p_under"]
    with pytest.raises(InputError):
        estimators.binomial_coverage(3, 2)
