"""The plant's limit for the paper's class (3) (issue 27): worst linear gain in the sector, scalar multiplier."""

from __future__ import annotations

import numpy as np
import pytest

from netrepro.engines.certify import FEASIBLE, INFEASIBLE
from netrepro.papers.gainsched.feasibility import (
    PlantLMI,
    linear_gain_limit,
    linear_gain_radius,
    necessary_condition,
    necessary_limit,
    plant_vertex_radius,
    sector_class_radius,
    sector_gain,
    worst_sector_gain,
)
from netrepro.papers.gainsched.model import GainschedError, System, sector_cases


def _rotation(t):
    return np.array([[np.cos(t), -np.sin(t)], [np.sin(t), np.cos(t)]])


def _radius_loop(sys, K, s2):
    """rho((A+BKZ) (x) (A+BKZ) + s2 D (x) D) by np.kron, one gain at a time (not the package's batched form)."""
    AK = sys.A + sys.B @ K @ sys.Z
    return max(abs(np.linalg.eigvals(np.kron(AK, AK) + s2 * np.kron(sys.D, sys.D))))


def test_sector_gain_meets_condition3_with_equality(sys):
    rng = np.random.default_rng(1)
    for t in rng.uniform(0, 2 * np.pi, 5):
        for U in (_rotation(t), _rotation(t) @ np.diag([1.0, -1.0])):
            K = sector_gain(sys, U)
            z = rng.standard_normal((50, 2))
            f = z @ K.T
            lhs = np.einsum("ri,ri->r", f - z @ sys.F1.T, f - z @ sys.F2.T)
            assert np.max(np.abs(lhs)) < 1e-12 * (1 + np.max(np.abs(f)) ** 2)


def test_diagonal_vertices_are_sector_gains(sys):
    vertices = {tuple(np.diag(F)) for F in sector_cases(sys).values()}
    for signs in ((1, 1), (1, -1), (-1, 1), (-1, -1)):
        K = sector_gain(sys, np.diag(np.array(signs, dtype=float)))
        assert np.allclose(K, np.diag(np.diag(K))) and tuple(np.round(np.diag(K), 12)) in vertices


def test_batched_radius_matches_the_loop(sys):
    Us = np.stack([_rotation(t) for t in np.linspace(0, 6, 7)])
    Ks = sector_gain(sys, Us)
    got = linear_gain_radius(sys, Ks, 2.5)
    want = [_radius_loop(sys, K, 2.5) for K in Ks]
    np.testing.assert_allclose(got, want, rtol=1e-12)
    assert plant_vertex_radius(sys, 2.5) == pytest.approx(max(_radius_loop(sys, F, 2.5)
                                                                for F in sector_cases(sys).values()), rel=1e-14)


def test_closed_form_limit_against_bisection_on_the_radius(sys):
    K = sector_gain(sys, _rotation(0.7))
    s_star = linear_gain_limit(sys, K)
    a, b = 0.0, 20.0
    for _ in range(60):
        mid = 0.5 * (a + b)
        a, b = (mid, b) if _radius_loop(sys, K, mid) < 1 else (a, mid)
    assert s_star == pytest.approx(a, rel=1e-9)


def test_closed_form_limit_scalar():
    """n = 1: rho = (a + b k)^2 + s d^2, so the limit is (1 - (a + b k)^2) / d^2; 0 if unstable without noise."""
    m = lambda v: np.array([[v]])  # noqa: E731
    s = System(m(0.5), m(0.2), m(1.0), m(0.6), m(1.0), m(0.5), m(2.0), 1.0, 0.4, 0.8)
    assert linear_gain_limit(s, m(1.0)) == pytest.approx((1 - 0.7 ** 2) / 0.36, rel=1e-12)
    assert linear_gain_limit(s, m(4.0)) == 0.0


def test_worst_gain_beats_a_dense_grid_and_the_vertices(sys):
    w = worst_sector_gain(sys)
    ts = np.linspace(0, 2 * np.pi, 20001)
    dense = min(min(linear_gain_limit(sys, sector_gain(sys, _rotation(t))) for t in ts[::10]),
                min(linear_gain_limit(sys, sector_gain(sys, _rotation(t) @ np.diag([1.0, -1.0]))) for t in ts[::10]))
    assert w["value"] <= dense + 1e-9
    assert w["value"] < min(linear_gain_limit(sys, F) for F in sector_cases(sys).values())
    assert np.allclose(w["U"] @ w["U"].T, np.eye(2), atol=1e-14)
    # the returned K's own radius crosses 1 at the returned limit
    assert _radius_loop(sys, w["K"], w["value"] * (1 + 1e-7)) > 1 > _radius_loop(sys, w["K"], w["value"] * (1 - 1e-7))


def test_worst_gain_at_a_sigma2_maximises_the_radius(sys):
    w = worst_sector_gain(sys, 3.9)
    grid = max(_radius_loop(sys, sector_gain(sys, _rotation(t)), 3.9) for t in np.linspace(0, 2 * np.pi, 2001))
    assert w["value"] >= grid - 1e-12
    assert sector_class_radius(sys, 3.9) == pytest.approx(max(w["value"], plant_vertex_radius(sys, 3.9)), rel=1e-14)


def test_worst_gain_needs_two_sector_dimensions():
    m = lambda v: np.array([[v]])  # noqa: E731
    s = System(m(0.5), m(0.2), m(1.0), m(0.6), m(1.0), m(0.5), m(2.0), 1.0, 0.4, 0.8)
    with pytest.raises(GainschedError, match="nz = 2"):
        worst_sector_gain(s)
    with pytest.raises(GainschedError, match="multiple of 4"):
        worst_sector_gain(System(np.eye(2) * 0.5, np.eye(2), np.ones((1, 2)), np.eye(2) * 0.1, np.eye(2),
                                 np.eye(2) * 0.1, np.eye(2), 1.0, 0.4, 0.8), n_grid=10)


def test_class_necessary_limit_is_below_the_componentwise_one(sys):
    c3 = necessary_limit(sys, 0.25, 10.0, sector="condition3")
    cw = necessary_limit(sys, 0.25, 10.0, sector="componentwise")
    assert c3[1] < cw[0]
    assert c3[1] == pytest.approx(worst_sector_gain(sys)["value"], abs=2e-6)
    assert necessary_condition(sys, c3[1])()[0] and not necessary_condition(sys, c3[0])()[0]
    with pytest.raises(GainschedError, match="sector must be"):
        necessary_condition(sys, 1.0, sector="box")()


def test_scalar_multiplier_certificate_covers_every_sector_gain(sys):
    """A certified scalar-multiplier P gives E V decrease for every K = (F1+F2)/2 + U F/2 (the class (3))."""
    lmi = PlantLMI(sys, multiplier="scalar")
    s2 = 3.9
    v = lmi.certify(s2)
    assert v.verdict == FEASIBLE
    P = np.array(lmi.P.value)
    for t in np.linspace(0, 2 * np.pi, 73):
        for U in (_rotation(t), _rotation(t) @ np.diag([1.0, -1.0])):
            AK = sys.A + sys.B @ sector_gain(sys, U) @ sys.Z
            assert np.linalg.eigvalsh(AK.T @ P @ AK + s2 * sys.D.T @ P @ sys.D - P).max() < 0


def test_scalar_and_diagonal_multipliers_differ_between_the_limits(sys):
    """Between the class-(3) necessary end and the componentwise limit: scalar infeasible, diagonal feasible."""
    _, above = necessary_limit(sys, 0.25, 10.0, sector="condition3")
    below_cw, _ = necessary_limit(sys, 0.25, 10.0, sector="componentwise")
    s2 = 0.5 * (above + below_cw) - 0.01
    assert PlantLMI(sys, multiplier="scalar").certify(s2).verdict == INFEASIBLE
    assert PlantLMI(sys, multiplier="diagonal").certify(s2).verdict == FEASIBLE
    with pytest.raises(GainschedError, match="multiplier must be"):
        PlantLMI(sys, multiplier="full")
