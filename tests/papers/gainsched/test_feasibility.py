"""Certified decisions (issue 16 section 1): point checks, necessary conditions, brackets."""

from __future__ import annotations

import numpy as np
import pytest

from netrepro.papers.gainsched.design import Theorem3
from netrepro.engines.certify import FEASIBLE, INFEASIBLE
from netrepro.papers.gainsched.feasibility import (
    PlantLMI,
    necessary_condition,
    necessary_limit,
    plant_vertex_radius,
    with_sigma2,
)
from netrepro.papers.gainsched.model import System, sector_cases


def _scalar_system(a=0.5, b=0.2, d=0.6, f1=0.5, f2=2.0, sigma2=1.0):
    m = lambda v: np.array([[v]])  # noqa: E731
    return System(m(a), m(b), m(1.0), m(d), m(1.0), m(f1), m(f2), sigma2, 0.4, 0.8)


def test_necessary_condition_callable_matches_the_radius(sys):
    below, above = necessary_limit(sys, 0.25, 10.0)
    assert necessary_condition(sys, above)()[0] and not necessary_condition(sys, below)()[0]
    assert "radius" in necessary_condition(sys, above)()[1]


def test_vertex_radius_and_necessary_limit_against_the_scalar_closed_form():
    """n = 1: radius = max_F (a + b F z)^2 + sigma^2 d^2, so the limit is (1 - max (a + b F)^2) / d^2."""
    s = _scalar_system()
    worst = max((0.5 + 0.2 * f) ** 2 for f in (0.5, 2.0))
    assert plant_vertex_radius(s, 0.7) == pytest.approx(worst + 0.7 * 0.36, rel=1e-14)
    below, above = necessary_limit(s, 0.0, 10.0, tol=1e-9)
    exact = (1 - worst) / 0.36
    assert below <= exact + 1e-8 and above >= exact - 1e-8 and above - below <= 1e-9


def test_plant_lmi_certificate_implies_decrease_at_every_linear_vertex(sys):
    """A certified plant certificate P gives (A+BFZ)^T P (A+BFZ) + sigma^2 D^T P D < P at every vertex F."""
    lmi = PlantLMI(sys)
    v = lmi.certify(sys.sigma2)
    assert v.verdict == FEASIBLE and v.point.slack > 0
    P = np.array(lmi.P.value)
    for F in sector_cases(sys).values():
        AF = sys.A + sys.B @ F @ sys.Z
        assert np.linalg.eigvalsh(AF.T @ P @ AF + sys.sigma2 * sys.D.T @ P @ sys.D - P).max() < 0


def test_plant_lmi_infeasible_beyond_the_necessary_condition(sys):
    _, above = necessary_limit(sys, 0.25, 10.0)
    v = PlantLMI(sys).certify(above + 0.05)
    assert v.verdict == INFEASIBLE and plant_vertex_radius(sys, above + 0.05) >= 1


def test_optimal_inaccurate_at_a_strictly_feasible_point(sys):
    """The case of the issue: near the limit Clarabel ends optimal_inaccurate, yet the returned point
    passes our eigenvalue check of all 16 vertices strictly: feasible, whatever the status."""
    prob = Theorem3(sys, bound=100.0, margin_cap=0.1)
    verdict, sol = prob.certify(3.9)
    assert sol.status == "optimal_inaccurate"
    assert verdict.verdict == FEASIBLE and verdict.point.slack > 0
    # independent of check_point: every vertex matrix evaluated afresh and its eigenvalues read directly
    ps = (sys.p1, sys.p2)
    worst = max(np.linalg.eigvalsh(0.5 * (M + M.T)).max()
                for M in (prob.vertex(ps[i], ps[j], ps[r], ps[l]).value
                          for i in range(2) for j in range(2) for r in range(2) for l in range(2)))
    assert worst < 0


def test_theorem3_infeasible_where_the_plant_is_not_ms_stable(sys):
    _, above = necessary_limit(sys, 0.25, 10.0)
    verdict, _ = Theorem3(sys, bound=100.0).certify(above + 0.5)
    assert verdict.verdict == INFEASIBLE


def test_zero_filter_design_has_zero_gains(sys):
    prob = Theorem3(sys, bound=100.0, zero_filter=True)
    verdict, sol = prob.certify(1.0)
    assert verdict.verdict == FEASIBLE
    for k in ("G0", "Gf", "H0", "Hf"):
        assert np.all(sol.values[k] == 0)


def test_theorem3_decisions_are_monotone_in_sigma2(sys):
    """Feasible below, infeasible above (by point check, dual certificate or the necessary condition)."""
    prob = Theorem3(sys, bound=100.0)
    verdicts = [prob.certify(s2)[0].verdict for s2 in (1.0, 3.5, 3.9, 4.0, 5.0)]
    assert verdicts[:3] == [FEASIBLE] * 3 and verdicts[3:] == [INFEASIBLE] * 2


def test_with_sigma2_changes_only_sigma2(sys):
    s = with_sigma2(sys, 2.5)
    assert s.sigma2 == 2.5 and s.p1 == sys.p1 and np.array_equal(s.A, sys.A)
