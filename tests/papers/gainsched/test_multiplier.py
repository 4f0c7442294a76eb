"""The S-procedure multiplier of the performance LMI (issue 37), the certified cost bracket, and the mean-square
stability test of the printed gains with the rotated worst gain of class (3)."""

from __future__ import annotations

import numpy as np
import pytest

from netrepro.papers.gainsched.design import Theorem3, certified_cost, guaranteed_cost_bracket
from netrepro.papers.gainsched.feasibility import with_sigma2, worst_sector_gain
from netrepro.papers.gainsched.model import augmented_initial_moment, p_schedule, zero_gains
from netrepro.papers.gainsched.moments import error_mse, linear_gains, mode_matrices, second_moments
from netrepro.papers.gainsched.analysis import frozen_ms_radius, ms_stable_decision

X0 = augmented_initial_moment(np.eye(2), 2)


@pytest.fixture(scope="module")
def zero_costs(sys):
    """Certified guaranteed costs of the zero filter x_f = 0, multiplier fixed as in (12) and free."""
    out = {}
    for mult in ("fixed", "free"):
        prob = Theorem3(sys, performance=True, output_slack=True, zero_filter=True, X0=X0, bound=100.0,
                        multiplier=mult)
        sol = prob.solve()
        ok, _ = prob.check_point(sol.values, sys.sigma2)
        assert ok, (mult, sol.status)
        out[mult] = (prob, sol, certified_cost(sol.values, X0, sys.p1, sys.p2))
    return out


def test_free_multiplier_is_a_variable_only_where_asked(sys):
    assert "lam" in Theorem3(sys, performance=True, X0=X0).vars
    assert "lam" not in Theorem3(sys).vars
    assert "lam" not in Theorem3(sys, performance=True, X0=X0, multiplier="fixed").vars
    with pytest.raises(Exception, match="multiplier"):
        Theorem3(sys, multiplier="diagonal")


def test_free_multiplier_lowers_the_zero_filters_guarantee_which_still_holds(sys, zero_costs):
    """Free multiplier: the certified cost of x_f = 0 falls well below the fixed one (6.55 -> 3.83 for the example)
    and still bounds the exact sum_k E||x(k)||^2 (independent: the exact second-moment recursion) for linear f at the
    sector's edge and several admissible p(k)."""
    fixed, free = zero_costs["fixed"][2], zero_costs["free"][2]
    assert free < 0.7 * fixed
    lam = float(zero_costs["free"][1].values["lam"])
    assert 0 < lam < 1  # the fixed multiplier (1) is not the best one
    sums = []
    for F in linear_gains(sys).values():
        for p_seq in (np.full(80, sys.p1), np.full(80, sys.p2), p_schedule(np.arange(80), sys.p1, sys.p2, 1.0),
                      np.where(np.arange(80) % 2, sys.p1, sys.p2)):
            M1, M0, W = mode_matrices(sys, zero_gains(sys), p_seq, F)
            sums.append(error_mse(second_moments(M1, M0, W, p_seq, sys.sigma2, X0)).sum())
    assert max(sums) <= free


def test_cost_bracket_contains_the_certified_cost_and_the_solver_optimum(sys, zero_costs):
    """The certified lower bound of the least cost is below the certified point's cost, and the solver's optimum of
    the same problem (a point with margin eps, independent of the bisection) does not go below the lower bound."""
    prob, sol, cost = zero_costs["free"]
    b = guaranteed_cost_bracket(prob, sol.values, X0, cost, span=0.05, resolution=1e-3)
    assert b.certified
    assert b.infeasible_end < cost <= b.feasible_end + 1e-12
    assert sol.objective >= b.infeasible_end
    with pytest.raises(Exception, match="performance"):
        guaranteed_cost_bracket(Theorem3(sys), sol.values, X0, cost)


def test_rotated_worst_gain_refutes_stability_where_the_diagonal_vertices_do_not(sys, paper):
    """Inside (3.9562, 3.9844) (the class-(3) necessary end and the diagonal vertices' end) the printed gains are not
    mean-square stable for the rotated gain: the test must read False there, while the four vertices alone read stable.
    Independent: the plant's own second-moment operator (A + BKZ) (x) (A + BKZ) + sigma^2 D (x) D, built here."""
    ps = np.linspace(sys.p1, sys.p2, 5)
    s2 = 3.97
    s = with_sigma2(sys, s2)
    K = worst_sector_gain(s, s2)["K"]
    AK = s.A + s.B @ K @ s.Z
    plant = np.max(np.abs(np.linalg.eigvals(np.kron(AK, AK) + s2 * np.kron(s.D, s.D))))
    assert plant > 1
    with_rot, diag = frozen_ms_radius(s, paper, ps), frozen_ms_radius(s, paper, ps, worst_gain=False)
    assert with_rot >= plant - 1e-12 and diag < 1  # (10) is block-triangular: its radius is at least the plant's
    assert ms_stable_decision(with_rot, s2, certified_to=3.95, refuted_from=np.nan) == (False, True)
    assert ms_stable_decision(diag, s2, certified_to=3.95, refuted_from=np.nan) == (True, False)  # undecided
    assert ms_stable_decision(diag, s2, certified_to=3.95, refuted_from=3.9562) == (False, True)
    assert ms_stable_decision(0.5, 1.0, certified_to=3.95, refuted_from=3.9562) == (True, True)
