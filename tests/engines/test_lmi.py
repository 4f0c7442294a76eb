import numpy as np
import pytest

from netrepro.engines.lmi import MareStabilizabilityLMI, bisect_monotone, second_moment_radius


def test_bisection_finds_threshold_and_counts():
    res = bisect_monotone(lambda x: x >= 0.3141, 0.0, 1.0, tol=1e-6)
    assert res.bracketed and abs(res.threshold - 0.3141) < 1e-6
    assert res.n_evals == len(res.history) <= 2 + int(np.ceil(np.log2(1e6))) + 1


def test_bisection_edges():
    assert bisect_monotone(lambda x: True, 0, 1).threshold == 0
    assert np.isnan(bisect_monotone(lambda x: False, 0, 1).threshold)


def test_second_moment_radius_scalar_closed_form():
    # scalar: sum_i w_i f_i^2
    assert second_moment_radius([np.array([[1.5]]), np.array([[0.2]])], [0.4, 0.6]) == pytest.approx(
        0.4 * 2.25 + 0.6 * 0.04)


@pytest.mark.parametrize("a", [1.2, 1.5, 3.0])
def test_scalar_threshold_is_sinopoli_closed_form(a):
    # Sinopoli et al.: for C invertible the critical probability is exactly 1 - 1/a^2
    lmi = MareStabilizabilityLMI([[a]], [None, np.array([[1.0]])])
    res = bisect_monotone(lambda lam: lmi.solve([1 - lam, lam]).certified, 0.0, 1.0, tol=1e-5)
    assert abs(res.threshold - (1 - 1 / a**2)) < 5e-5


def test_infeasible_is_reported_with_status_not_certified():
    lmi = MareStabilizabilityLMI([[2.0]], [None, np.array([[1.0]])])
    out = lmi.solve([0.9, 0.1])  # (1-lambda) a^2 = 3.6 > 1
    assert not out.certified and not out.solver_feasible
    assert isinstance(out.status, str)


def test_matrix_case_certificate_is_independent():
    A = np.array([[1.3, 1.0], [0.0, 1.1]])
    C = np.array([[1.0, 0.0]])  # observable, not invertible
    lmi = MareStabilizabilityLMI(A, [None, C])
    out = lmi.solve([0.05, 0.95])
    assert out.certified
    K = out.variables["K"][1]
    rho = second_moment_radius([A, A + K @ C], [0.05, 0.95])
    assert rho == pytest.approx(out.certificate_value) and rho < 1
    # necessary condition: (1 - lambda) rho(A)^2 < 1 fails -> must not be certified
    assert not lmi.solve([0.7, 0.3]).certified


def test_bad_weights_named():
    lmi = MareStabilizabilityLMI([[1.5]], [None, np.array([[1.0]])])
    with pytest.raises(ValueError, match="weights"):
        lmi.solve([0.5])
