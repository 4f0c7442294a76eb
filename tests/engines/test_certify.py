"""Certified LMI decisions, each test against a fact known without the LMI (eigenvalues, closed forms)."""

import warnings

import cvxpy as cp
import numpy as np
import pytest

from netrepro.engines.certify import (FEASIBLE, INFEASIBLE, UNDECIDED, CertifiedLMI, DualCertificate, Verdict,
                                      bisect_certified, check_dual_certificate, find_dual_certificate)
from netrepro.engines.lmi import MareStabilizabilityLMI, bisect_monotone
from netrepro.errors import LMIError


def lyapunov(A, box=None, **kw):
    """Discrete Lyapunov LMI P > 0, P - A'PA > 0 (feasible iff rho(A) < 1), posed as the papers do."""
    n = A.shape[0]
    P = cp.Variable((n, n), symmetric=True, name="P")
    t = cp.Variable(name="t")
    L = P - A.T @ P @ A
    L = 0.5 * (L + L.T)
    prob = cp.Problem(cp.Maximize(t), [P >> t * np.eye(n), L >> t * np.eye(n), P << np.eye(n)])
    return CertifiedLMI([("P", P), ("lyap", L)], problem=prob, box=box, **kw), P, L, t


def rho(A):
    return float(np.max(np.abs(np.linalg.eigvals(A))))


def test_coefficients_reproduce_the_expressions_and_follow_parameters():
    rng = np.random.default_rng(1)
    n = 3
    A, C = rng.standard_normal((n, n)), rng.standard_normal((2, n))
    Y = cp.Variable((n, n), symmetric=True, name="Y")
    K = cp.Variable((n, 2), name="K")
    w = cp.Parameter(nonneg=True, name="w")
    off = w * (Y @ A + K @ C)
    psi = cp.bmat([[Y, off.T], [off, Y + np.eye(n)]])
    psi = 0.5 * (psi + psi.T)
    vec = cp.hstack([Y[0, 0] - 1.0, 2 * K[1, 1]])  # a vector block: each entry > 0
    c = CertifiedLMI([("psi", psi), ("vec", vec)])
    assert c.names == ["psi", "vec[0]", "vec[1]"]
    assert len(c.coordinate_names) == n * (n + 1) // 2 + 2 * n  # symmetric Y counted once
    for wv in (0.3, 0.9):  # one build, parameter updates
        w.value = wv
        X = rng.standard_normal((n, n))
        Y.value, K.value = X + X.T, rng.standard_normal((n, 2))
        co = c.coefficients()
        got = co.evaluate(c.point())
        np.testing.assert_allclose(got[0], psi.value, atol=1e-13)
        assert got[1][0, 0] == pytest.approx(Y.value[0, 0] - 1.0)
        assert got[2][0, 0] == pytest.approx(2 * K.value[1, 1])
    assert not co.homogeneous


def test_rejects_non_affine_blocks_and_unsupported_variables():
    x = cp.Variable((2, 2), name="x")
    with pytest.raises(LMIError, match="affine"):
        CertifiedLMI([cp.abs(x)])
    z = cp.Variable((2, 2), PSD=True, name="z")
    with pytest.raises(LMIError, match="attribute"):
        CertifiedLMI([z + np.eye(2)])


@pytest.mark.parametrize("A", [np.array([[0.9, 0.5], [0.0, 0.8]]), np.diag([0.99, -0.5, 0.3]),
                               np.array([[0.0, 1.0], [-0.5, 1.2]])])
def test_stable_matrix_is_certified_feasible(A):
    assert rho(A) < 1
    c, P, L, _ = lyapunov(A)
    v = c.solve()
    assert v.verdict == FEASIBLE and v.feasible and v.decided
    # the point itself, checked once more by plain numpy
    assert np.linalg.eigvalsh(P.value)[0] > 0 and np.linalg.eigvalsh(P.value - A.T @ P.value @ A)[0] > 0


def test_fully_unstable_matrix_has_an_exact_dual_certificate():
    A = np.array([[1.5, 1.0], [0.0, -1.2]])  # every eigenvalue outside the unit circle
    c, *_ = lyapunov(A)  # no box: only the unconditional argument can decide
    v = c.solve()
    assert v.verdict == INFEASIBLE and v.dual.scope == "exact" and v.dual.valid


def test_partly_unstable_matrix_needs_the_stated_box():
    A = np.diag([1.1, 0.5, 0.2])  # the dual certificate is singular on the stable modes
    c, *_ = lyapunov(A)
    v = c.solve()
    assert v.verdict == UNDECIDED  # never counted as infeasible without a certificate
    c, *_ = lyapunov(A, box=1e3)
    v = c.solve()
    assert v.verdict == INFEASIBLE and v.dual.scope == "box" and v.dual.bound < 0
    assert v.dual.detail["normalised"]  # homogeneous: the box holds after lambda_min = 1


def test_inaccurate_status_at_a_strictly_feasible_point_is_feasible():
    A = np.array([[0.9, 0.5], [0.0, 0.8]])
    c, P, L, _ = lyapunov(A)
    loose = dict(reduced_tol_gap_abs=1e-1, reduced_tol_gap_rel=1e-1, reduced_tol_feas=1e-1, reduced_tol_ktratio=1.0)
    v = c.solve(max_iter=3, tol_gap_abs=1e-14, tol_gap_rel=1e-14, tol_feas=1e-14, **loose)
    assert v.solver_status == "optimal_inaccurate"  # what gainsched read as infeasible
    assert v.verdict == FEASIBLE
    assert np.linalg.eigvalsh(P.value)[0] > 0 and np.linalg.eigvalsh(P.value - A.T @ P.value @ A)[0] > 0


def test_optimal_status_with_positive_margin_on_an_infeasible_lmi_is_not_feasible():
    A = np.array([[1.1, 1.0], [0.0, 0.5]])  # rho = 1.1: the Lyapunov LMI is infeasible
    c, P, L, t = lyapunov(A, box=1e3)
    v = c.solve()
    assert v.solver_status == "optimal" and t.value > 0  # the solver's own answer: a positive margin
    assert np.linalg.eigvalsh(L.value)[0] < 0  # ... at a point that violates the LMI
    assert v.verdict != FEASIBLE
    assert v.verdict == INFEASIBLE and v.dual.valid


def test_tampered_dual_certificate_is_rejected():
    A = np.diag([1.1, 0.5])  # infeasible; its certificates are singular, so no perturbation is repairable
    c, *_ = lyapunov(A, box=1e3)
    co = c.coefficients()
    cert = find_dual_certificate(co, "box", c._box)
    assert check_dual_certificate(co, cert, box=1e3).valid
    rng = np.random.default_rng(0)
    noisy = DualCertificate([V + 1e-2 * rng.standard_normal(V.shape) for V in cert.factors])
    assert not check_dual_certificate(co, noisy, box=1e3).valid  # residual ~1e-2 times the box 1e3
    assert check_dual_certificate(co, noisy, box=1.0).valid  # ... still proves the claim for a small box
    dropped = DualCertificate([cert.factors[0], np.zeros_like(cert.factors[1])])  # one block zeroed
    assert not check_dual_certificate(co, dropped, box=1e3).valid
    assert not check_dual_certificate(co, cert).valid  # without the box only the exact argument is allowed
    # a certificate of one system says nothing about a feasible one
    c2, *_ = lyapunov(np.diag([0.9, 0.5]), box=1e3)
    assert not check_dual_certificate(c2.coefficients(), cert, box=1e3).valid
    with pytest.raises(LMIError, match="factors"):
        check_dual_certificate(co, DualCertificate(cert.factors[:1]))


def test_necessary_condition_certifies_infeasible_and_its_evidence_is_kept():
    lmi = MareStabilizabilityLMI([[2.0]], [None, np.array([[1.0]])])
    v = lmi.certify([0.9, 0.1])  # (1 - lambda) a^2 = 3.6 >= 1
    assert v.verdict == INFEASIBLE and "3.6" in v.evidence and v.necessary is not None
    v = lmi.certify([0.1, 0.9])  # 0.4 < 1: feasible (C invertible)
    assert v.verdict == FEASIBLE


def test_mare_solve_is_unchanged_by_the_certifier():
    lmi = MareStabilizabilityLMI([[1.5]], [None, np.array([[1.0]])])
    lmi.solve([0.3, 0.7])  # the first solve compiles (its last digits differ from later solves, certify or not)
    before = lmi.solve([0.3, 0.7])
    lmi.certify([0.3, 0.7])
    after = lmi.solve([0.3, 0.7])
    assert before.status == after.status and before.margin == after.margin and before.certified == after.certified


@pytest.mark.parametrize("a,necessary", [(1.2, True), (1.5, False), (2.0, True), (2.0, False)])
def test_certified_bisection_brackets_the_sinopoli_threshold(a, necessary):
    lam_c = 1.0 - 1.0 / a ** 2  # Sinopoli et al. (2004): C invertible, closed form
    lmi = MareStabilizabilityLMI([[a]], [None, np.array([[1.0]])])
    lmi.certifier(box=1e4)  # the dual route's stated box (after normalisation)
    decide = (lambda lam: lmi.certify([1 - lam, lam], necessary=necessary))
    br = bisect_certified(decide, 0.0, 1.0, tol=1e-5)
    assert br.certified and br.infeasible_end <= lam_c < br.feasible_end  # at lam_c itself: infeasible (strict)
    assert br.feasible_end - br.infeasible_end <= 2e-5
    assert br.verdicts[br.feasible_end].feasible and br.verdicts[br.infeasible_end].infeasible
    if not necessary:
        assert br.verdicts[br.infeasible_end].dual.valid
    warm = bisect_certified(decide, 0.0, 1.0, tol=1e-5, guess=lam_c + 3e-4, width=1e-4)
    assert (warm.infeasible_end, warm.feasible_end) == (br.infeasible_end, br.feasible_end)
    assert warm.n_evals < br.n_evals
    plain = bisect_monotone(lambda lam: lmi.solve([1 - lam, lam]).certified, 0.0, 1.0, tol=1e-5)
    assert plain.threshold == br.feasible_end  # same lattice as the existing bisection


def _pattern(threshold_i, threshold_f, feasible_above=True):
    """A synthetic decider: infeasible below ``threshold_i``, feasible above ``threshold_f``, undecided between."""
    def decide(x):
        y = x if feasible_above else -x
        ti, tf = (threshold_i, threshold_f) if feasible_above else (-threshold_f, -threshold_i)
        v = INFEASIBLE if y < ti else FEASIBLE if y > tf else UNDECIDED
        return Verdict(v)
    return decide


@pytest.mark.parametrize("feasible_above", [True, False])
@pytest.mark.parametrize("guess", [None, 0.0, 0.3, 0.41, 0.9, 1.0])
def test_certified_bisection_keeps_undecided_points_out_and_ignores_the_guess(feasible_above, guess):
    decide = _pattern(0.4, 0.42, feasible_above)
    ref = bisect_certified(decide, 0.0, 1.0, tol=1e-3, feasible_above=feasible_above)
    got = bisect_certified(decide, 0.0, 1.0, tol=1e-3, feasible_above=feasible_above, guess=guess, width=0.01)
    assert (got.infeasible_end, got.feasible_end) == (ref.infeasible_end, ref.feasible_end)
    ie, fe = ref.infeasible_end, ref.feasible_end
    cell = 1.0 / 1024
    if feasible_above:
        assert ie < 0.4 <= ie + cell and fe > 0.42 >= fe - cell
    else:
        assert fe < 0.4 <= fe + cell and ie > 0.42 >= ie - cell
    assert ref.undecided and all(0.4 <= x <= 0.42 for x in ref.undecided + got.undecided)


def test_certified_bisection_edges_and_contradictions():
    always = bisect_certified(lambda x: Verdict(FEASIBLE), 0.0, 1.0)
    assert always.feasible_end == 0.0 and np.isnan(always.infeasible_end) and not always.certified
    never = bisect_certified(lambda x: Verdict(INFEASIBLE), 0.0, 1.0)
    assert never.infeasible_end == 1.0 and np.isnan(never.feasible_end)
    unknown = bisect_certified(lambda x: Verdict(UNDECIDED), 0.0, 1.0)
    assert not unknown.certified and len(unknown.undecided) == 2
    with pytest.raises(LMIError, match="monotone"):
        bisect_certified(lambda x: Verdict(FEASIBLE if x < 0.5 else INFEASIBLE), 0.0, 1.0)
    with pytest.raises(LMIError, match="lo <= hi"):
        bisect_certified(lambda x: Verdict(FEASIBLE), 1.0, 0.0)


def test_certify_without_a_point_is_never_feasible():
    A = np.array([[0.5]])
    c, P, L, t = lyapunov(A)
    P.value = None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        v = c.certify("solver_error: test")
    assert v.verdict != FEASIBLE and v.solver_status == "solver_error: test"


def test_constraints_with_the_margin_dropped_are_the_same_blocks():
    A = np.array([[0.9, 0.5], [0.0, 0.8]])
    c, P, L, t = lyapunov(A)
    cons = c.problem.constraints[:2]  # P >> t I, L >> t I (not the normalisation P << I)
    c2 = CertifiedLMI(cons, problem=c.problem, drop=[t])
    assert c2.coordinate_names == c.coordinate_names  # t has no coordinate
    v = c2.solve()
    assert v.verdict == FEASIBLE
    for a, b in zip(c.coefficients().F, c2.coefficients().F):
        np.testing.assert_array_equal(a, b)


def test_non_homogeneous_infeasible_system_has_an_exact_certificate():
    A = np.array([[1.5, 1.0], [0.0, -1.2]])
    n = 2
    P = cp.Variable((n, n), symmetric=True, name="P")
    L = P - A.T @ P @ A
    c = CertifiedLMI([P - np.eye(n), 0.5 * (L + L.T) - np.eye(n)])  # P > I, P - A'PA > I
    co = c.coefficients()
    assert not co.homogeneous
    v = c.certify("not solved")
    assert v.verdict == INFEASIBLE and v.dual.scope == "exact"
    assert v.dual.detail["g0"] < 0  # sum_j tr(F_j0 Z_j) < 0
