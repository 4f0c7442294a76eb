"""Realisation freedom of Algorithm 1 (H -> -H), the exact cost and the exactly tuned filters (issue 27)."""

from __future__ import annotations

import numpy as np
import pytest

from netrepro.papers.gainsched.model import GainschedError, augmented_initial_moment, p_schedule, realisation, zero_gains
from netrepro.papers.gainsched.moments import error_mse, mode_matrices, second_moments
from netrepro.papers.gainsched.tuning import best_exact_gains, exact_cost
from netrepro.papers.gainsched.analysis import eq15_residuals, gap_relative

from .conftest import random_gains


def test_realisation_is_a_similarity_of_the_filter_state(sys, paper):
    """x_f' = J x_f: the second moment of [x; x_f'] is T X T^T, T = diag(I, J), along the same recursion."""
    J = np.array([[1.5, 0.2], [-0.3, 0.8]])
    g2 = realisation(paper, J)
    p = p_schedule(np.arange(12), sys.p1, sys.p2, 1.0)
    F = 0.5 * (sys.F1 + sys.F2)
    X0 = augmented_initial_moment(np.eye(sys.n), sys.n)  # x_f(0) = 0, so T X0 T^T = X0
    X = second_moments(*mode_matrices(sys, paper, p, F), p, sys.sigma2, X0)
    X2 = second_moments(*mode_matrices(sys, g2, p, F), p, sys.sigma2, X0)
    T = np.block([[np.eye(sys.n), np.zeros((sys.n, sys.n))], [np.zeros((sys.n, sys.n)), J]])
    np.testing.assert_allclose(X2, T @ X @ T.T, rtol=1e-10, atol=1e-12)


def test_flip_is_h_negated_and_changes_the_error(sys, paper):
    flip = realisation(paper, -np.eye(sys.n))
    np.testing.assert_array_equal(flip.G0, paper.G0)
    np.testing.assert_array_equal(flip.H0, -paper.H0)
    np.testing.assert_array_equal(flip.Hf, -paper.Hf)
    p = p_schedule(np.arange(20), sys.p1, sys.p2, 1.0)
    F, X0 = 0.5 * (sys.F1 + sys.F2), augmented_initial_moment(np.eye(sys.n), sys.n)
    X = second_moments(*mode_matrices(sys, paper, p, F), p, sys.sigma2, X0)
    # E||x + x_f||^2 of the original filter is the flipped filter's E||x - x_f'||^2
    n = sys.n
    plus = np.trace(X[:, :n, :n], axis1=1, axis2=2) + np.trace(X[:, n:, n:], axis1=1, axis2=2) \
        + 2 * np.trace(X[:, :n, n:], axis1=1, axis2=2)
    np.testing.assert_allclose(exact_cost(sys, flip, p, F, X0), plus.sum(), rtol=1e-12)
    assert abs(exact_cost(sys, flip, p, F, X0) - exact_cost(sys, paper, p, F, X0)) > 0.1


def test_realisation_rejects_singular_or_misshapen_j(paper):
    with pytest.raises(GainschedError, match="singular"):
        realisation(paper, np.array([[1.0, 2.0], [2.0, 4.0]]))
    with pytest.raises(GainschedError, match="must be 2x2"):
        realisation(paper, np.eye(3))


def test_exact_cost_equals_the_batched_recursion(sys):
    rng = np.random.default_rng(4)
    g = random_gains(rng, sys, scale=0.2)
    p = p_schedule(np.arange(30), sys.p1, sys.p2, 1.0)
    F, X0 = sys.F2, augmented_initial_moment(np.eye(sys.n), sys.n)
    batched = float(error_mse(second_moments(*mode_matrices(sys, g, p, F), p, sys.sigma2, X0)).sum())
    assert exact_cost(sys, g, p, F, X0) == pytest.approx(batched, rel=1e-12)


def test_best_exact_gains_scheduled_never_worse_than_fixed(sys, paper):
    p = p_schedule(np.arange(15), sys.p1, sys.p2, 1.0)
    F, X0 = 0.5 * (sys.F1 + sys.F2), augmented_initial_moment(np.eye(sys.n), sys.n)
    fixed, info_f = best_exact_gains(sys, p, F, X0, False, [("zero", zero_gains(sys))], gtol=1e-6)
    assert np.all(fixed.Gf == 0) and np.all(fixed.Hf == 0)
    assert info_f["cost"] == pytest.approx(exact_cost(sys, fixed, p, F, X0), rel=1e-12)
    assert info_f["cost"] < exact_cost(sys, zero_gains(sys), p, F, X0)
    sched, info_s = best_exact_gains(sys, p, F, X0, True, [("best fixed", fixed), ("paper", paper)], gtol=1e-6)
    assert info_s["cost"] <= info_f["cost"] + 1e-12
    assert set(info_s["costs"]) == {"best fixed", "paper"}
    with pytest.raises(GainschedError, match="at least one start"):
        best_exact_gains(sys, p, F, X0, True, [])


def test_gap_relative():
    assert gap_relative(3.95162, 3.95621) == pytest.approx((3.95621 - 3.95162) / 3.95621, rel=1e-15)
    with pytest.raises(GainschedError, match="positive and finite"):
        gap_relative(1.0, 0.0)


def test_eq15_residuals_signs(sys, t3):
    """With a Theorem 3 certificate the corrected (15) bounds E ΔV (<= rounding); the printed sign does not."""
    from netrepro.papers.gainsched.design import certificate_from_solution, recover_gains

    g, _ = recover_gains(t3.values, "identity_T")
    c = certificate_from_solution(t3.values, "identity_T")
    printed, corrected = eq15_residuals(sys, g, c["Q0"], c["Qp"], np.random.default_rng(0), n_states=300)
    assert corrected < 1e-9 < printed
    with pytest.raises(GainschedError, match="n_states"):
        eq15_residuals(sys, g, c["Q0"], c["Qp"], np.random.default_rng(0), n_states=0)


def test_relative_spread_and_rms_ratio():
    from netrepro.papers.gainsched.analysis import relative_spread, rms_ratio

    assert relative_spread([3.6947, 12.419, 2.9671]) == pytest.approx(12.419 / 2.9671 - 1, rel=1e-15)
    assert relative_spread([2.0]) == 0.0
    with pytest.raises(GainschedError, match="positive finite"):
        relative_spread([1.0, 0.0])
    assert rms_ratio([4.0, 1.0, 0.01]) == pytest.approx(0.05, rel=1e-15)
    with pytest.raises(GainschedError, match=r"E\|\|e\(0\)\|\|\^2 > 0"):
        rms_ratio([0.0, 1.0])
