import itertools
from fractions import Fraction

import numpy as np
import pytest

from netrepro.errors import InputError
from netrepro.papers.intermittent import tails
from netrepro.papers.intermittent.model import exact_mean_enumeration, riccati_step

A, R1, R2, P0 = 1.5, 0.1, 0.5, 10.0
LAM = 1 - 1 / A**2 + 0.1


def _brute_force(lam, m, T):
    total = 0.0
    for seq in itertools.product((0, 1), repeat=T):
        run, hit = 0, False
        for g in seq:
            run = 0 if g else run + 1
            hit |= run >= m
        if hit:
            total += np.prod([lam if g else 1 - lam for g in seq])
    return total


@pytest.mark.parametrize("lam,m,T", [(0.4, 1, 6), (0.4, 2, 8), (0.4, 3, 10), (0.8, 2, 12), (0.3, 4, 4), (0.5, 5, 3)])
def test_loss_run_probability_against_enumeration(lam, m, T):
    exact = _brute_force(lam, m, T)
    assert tails.loss_run_probability(lam, m, T) == pytest.approx(exact, rel=1e-12, abs=1e-300)
    assert tails.loss_run_probability_recursion(lam, m, T) == pytest.approx(exact, rel=1e-12, abs=1e-300)


def test_loss_run_probability_of_a_single_loss():
    assert tails.loss_run_probability(0.7, 1, 25) == pytest.approx(1 - 0.7**25, rel=1e-12)
    assert tails.loss_run_probability(0.7, 1, 0) == 0.0


def test_squaring_against_the_renewal_recursion_at_a_long_horizon():
    # three different computations: repeated squaring of the substochastic block, a renewal recursion (summed in
    # the complementary form, error ~ T eps relative to P) and the dominant root. The squaring's log survival
    # carries an absolute error ~ T m eps (2e-10 here), i.e. ~2e-5 relative to P = 1.2e-5: tolerance 1e-5 is
    # that bound with room; the two others agree to 1e-9
    m = tails.losses_to_exceed(1e6, A, R1)
    T = 100_000
    p_rec = tails.loss_run_probability_recursion(LAM, m, T)
    assert tails.loss_run_probability(LAM, m, T) == pytest.approx(p_rec, rel=1e-5)
    assert tails.loss_run_probability_dominant_root(LAM, m, T) == pytest.approx(p_rec, rel=1e-9)


def test_issue_27_values_and_bounds_at_huge_horizons():
    # runs of >= 21 losses at lambda_c + 0.1: about 1.25e-4 at T = 1e6 and 0.1173 at T = 1e9; never above 1
    m = tails.losses_to_exceed(1e6, A, R1)
    assert m == 21
    p6, p9 = tails.loss_run_probability(LAM, m, 10**6), tails.loss_run_probability(LAM, m, 10**9)
    assert p6 == pytest.approx(1.2476e-4, rel=1e-3)
    assert p9 == pytest.approx(0.11730, rel=1e-4)
    assert p9 == pytest.approx(tails.loss_run_probability_dominant_root(LAM, m, 10**9), rel=1e-6)
    # first-order check independent of both: P ~ 1 - exp(-T lambda (1 - lambda)^m) for T >> m
    assert p6 == pytest.approx(-np.expm1(-1e6 * LAM * (1 - LAM) ** m), rel=1e-3)
    for T in (10**12, 10**15, 10**18):
        p = tails.loss_run_probability(LAM, m, T)
        assert 0.0 <= p <= 1.0 and p == 1.0
        assert tails.loss_run_survival_log(LAM, m, T) < -100


def test_loss_run_inputs_are_checked():
    with pytest.raises(InputError, match="lambda"):
        tails.loss_run_probability(0.0, 3, 10)
    with pytest.raises(InputError, match="run length"):
        tails.loss_run_probability(0.5, 0, 10)
    with pytest.raises(InputError, match="number of steps"):
        tails.loss_run_probability(0.5, 2, -1)
    with pytest.raises(InputError, match="must lie in"):
        tails.loss_run_probability_dominant_root(0.5, 1, 10)


def test_losses_to_exceed_iterating_eq6_without_arrivals():
    level = 1e6
    m = tails.losses_to_exceed(level, A, R1)
    p = 0.0  # the worst start
    for _ in range(m - 1):
        p = float(riccati_step(p, 0.0, A, R1, R2))
    assert p < level
    assert float(riccati_step(p, 0.0, A, R1, R2)) >= level
    # a level reached exactly after m losses from 0
    exact_level = R1 * (A**6 - 1) / (A**2 - 1)
    assert tails.losses_to_exceed(exact_level, A, R1) == 3


def test_tail_index_against_the_exact_law_of_p_k():
    # independent: P(p_k > x) from the enumerated law of p_16 falls like x^-alpha over the losses-only range
    lam = 0.7
    alpha = tails.tail_index(lam, A)
    assert alpha == pytest.approx(np.log(1 / 0.3) / np.log(2.25))
    _, vals, w = exact_mean_enumeration(1.0, A, R1, R2, lam, 16, return_distribution=True)
    xs = np.array([1e2, 1e4])
    tail = np.array([w[vals > x].sum() for x in xs])
    slope = -np.log(tail[1] / tail[0]) / np.log(xs[1] / xs[0])
    assert slope == pytest.approx(alpha, rel=0.1)
    assert tails.tail_index(1.0, A) == np.inf


def test_moment_thresholds():
    assert tails.moment_finite_threshold(1, A) == pytest.approx(1 - 1 / A**2)
    assert tails.moment_finite_threshold(2, A) == pytest.approx(1 - 1 / A**4)
    # alpha = n exactly at the threshold of the n-th moment
    for n in (1, 2, 3):
        assert tails.tail_index(tails.moment_finite_threshold(n, A), A) == pytest.approx(n)


def test_quantile_interval_against_a_sorted_sample():
    rng = np.random.default_rng(3)
    vals = rng.exponential(size=1000)
    w = np.full(1000, 1e-3)
    # the weights are the decimal 1e-3 rounded once: relative error u
    lo, hi = tails.quantile_interval(vals, w, [0.1, 0.5, 0.999, 0.1234], weight_rtol=1.2e-16)
    s = np.sort(vals)
    # q n an integer: F = q on [s_(qn), s_(qn+1)), so the quantile is that interval (1-based order statistics);
    # q n not an integer: the ceil(q n)-th order statistic, lo = hi
    np.testing.assert_array_equal(lo, s[[99, 499, 998, 123]])
    np.testing.assert_array_equal(hi, s[[100, 500, 999, 123]])
    lo, hi = tails.quantile_interval([3.0, 1.0, 2.0], [0.2, 0.5, 0.3], [0.5, 0.51, 0.8, 0.81], weight_rtol=1.2e-16)
    assert lo.tolist() == [1.0, 2.0, 2.0, 3.0]
    assert hi.tolist() == [2.0, 2.0, 3.0, 3.0]
    with pytest.raises(InputError, match="levels"):
        tails.quantile_interval([1.0], [1.0], [1.0])


def _exact_law(lam_num, lam_den, k):
    """Support of p_k and integer weights lam_num^j (lam_den - lam_num)^(k - j) over lam_den^k (j = arrivals)."""
    _, vals, _ = exact_mean_enumeration(P0, A, R1, R2, lam_num / lam_den, k, return_distribution=True)
    # the enumeration doubles the paths per step, arrivals in the upper half: path i has popcount(i) arrivals
    j = np.array([bin(i).count("1") for i in range(2**k)])
    w_int = [lam_num ** int(x) * (lam_den - lam_num) ** (k - int(x)) for x in j]
    return vals, w_int, lam_den**k


def test_quantile_interval_against_the_exact_rational_law():
    # lambda = 9/10 exactly in rationals: the exact CDF in integers gives the exact Q^- and Q^+; the float
    # computation must enclose them, and here (no weight within the rounding of a level) hit them exactly
    k = 12
    vals, w_int, den = _exact_law(9, 10, k)
    order = np.argsort(vals, kind="stable")
    cum = np.cumsum(np.array([w_int[i] for i in order], dtype=object))
    levels = [0.5, 0.9, 0.99, 0.999]
    w = vals * 0 + np.array([x / den for x in w_int])
    lo, hi = tails.quantile_interval(vals, w, levels, weight_rtol=(k + 1) * 1.2e-16)
    for q, qn, x, y in zip(levels, [(1, 2), (9, 10), (99, 100), (999, 1000)], lo, hi):
        target = qn[0] * den // qn[1]
        first_ge = next(i for i, c in enumerate(cum) if c >= target)
        first_gt = next(i for i, c in enumerate(cum) if c > target)
        assert x == vals[order][first_ge] and y == vals[order][first_gt], q
    # P(p_k <= v) = 0.9 exactly on a stretch: the quantile at 0.9 is an interval of positive length
    assert hi[1] > lo[1] and hi[0] == lo[0]


def test_exceedance_probability_against_the_exact_rational_law():
    k = 10
    vals, w_int, den = _exact_law(3, 5, k)
    w = np.array([x / den for x in w_int])
    mean = float(sum(Fraction(x, den) * Fraction(v) for x, v in zip(w_int, vals)))
    exact = Fraction(sum(x for x, v in zip(w_int, vals) if v > mean), den)
    p, err = tails.exceedance_probability(vals, w, mean, 1e-14, (k + 1) * 1.2e-16)
    assert abs(p - float(exact)) <= err + 1e-16 and err < 1e-13
    # a level on a support point: its weight enters the error bound, not the probability
    p, err = tails.exceedance_probability([1.0, 2.0, 3.0], [0.25, 0.5, 0.25], 2.0, 1e-12)
    assert p == 0.25 and err == pytest.approx(0.5)
