"""The exact E(p_k) (exact.py) against independent computations: full enumeration of all arrival
sequences (two different enumerations), closed forms of special cases, and the Monte Carlo."""

import itertools

import numpy as np
import pytest

from netrepro.engines.riccati import Sensor, covariance_paths
from netrepro.errors import ModelError
from netrepro.papers.intermittent import exact, model

A, R1, R2, P0 = 1.5, 0.1, 0.5, 10.0
LAM_C = model.critical_probability(A)
REL = 1e-10  # the tolerance; the method's own bound is ~1e-13, float64 enumeration sums carry ~1e-14


@pytest.mark.parametrize("lam", [LAM_C + 0.1, LAM_C - 0.1, LAM_C, 0.95, 0.1])
def test_matches_full_enumeration_up_to_k20(lam):
    enum = model.exact_mean_enumeration(P0, A, R1, R2, lam, 20)  # all 2^20 sequences
    res = exact.exact_mean(P0, A, R1, [R2], [lam], 20)
    rel = np.abs(res.mean / enum - 1)
    assert rel.max() < REL
    assert res.rel_error_bound.max() < 1e-12
    # the stated bound holds against an enumeration in extended precision (the float64 one carries
    # summation errors of ~1e-13 over 2^20 terms, more than the bound)
    ld = _enumeration_extended(lam, 20)
    assert np.all(np.abs(res.mean / ld - 1) <= res.rel_error_bound + 1e-16)


def _enumeration_extended(lam, n):
    """E(p_k) by enumerating all 2^k arrival sequences in 80-bit arithmetic (eq. (6) written out)."""
    LD = np.longdouble
    a2, q, r, lam = LD(A) * LD(A), LD(R1), LD(R2), LD(lam)
    vals, w = np.array([LD(P0)]), np.array([LD(1)])
    means = [LD(P0)]
    for _ in range(n):
        vals = np.concatenate([a2 * vals + q, a2 * vals + q - a2 * vals * vals / (vals + r)])
        w = np.concatenate([(1 - lam) * w, lam * w])
        means.append((w * vals).sum())
    return np.array(means, dtype=float)


def test_two_sensor_matches_enumeration_of_all_pattern_sequences():
    T, probs, variances, p0 = 8, [0.3, 0.45], [0.2, 0.5], 1.0
    seqs = np.array(list(itertools.product([False, True], repeat=2 * T)), dtype=bool).reshape(-1, T, 2)
    weights = np.prod(np.where(seqs, probs, 1 - np.asarray(probs)), axis=(1, 2))
    paths = covariance_paths(p0, [[A]], [[R1]], [Sensor([[1.0]], [[v]]) for v in variances], seqs)
    enum = weights @ paths
    res = exact.exact_mean(p0, A, R1, variances, probs, T)
    assert np.max(np.abs(res.mean / enum - 1)) < REL


def test_no_arrivals_is_the_loss_recursion_in_closed_form():
    res = exact.exact_mean(P0, A, R1, [R2], [0.0], 30)
    k = np.arange(31)
    closed = A ** (2 * k) * P0 + R1 * (A ** (2 * k) - 1) / (A * A - 1)
    assert np.allclose(res.mean, closed, rtol=1e-13, atol=0)


def test_every_packet_arrives_is_the_riccati_iteration():
    res = exact.exact_mean(P0, A, R1, [R2], [1.0], 40)
    p = [P0]
    for _ in range(40):
        p.append(model.riccati_step(p[-1], 1.0, A, R1, R2))
    assert np.allclose(res.mean, p, rtol=1e-13, atol=0)


def test_stationary_mean_brackets_the_long_run_and_the_closed_form_at_lambda_one():
    lam = LAM_C + 0.1
    st = exact.stationary_mean(A, R1, [R2], [lam], p0=P0)
    assert st["hi"] - st["lo"] < 1e-12 * st["mean"]
    # the exact mean at large k converges into the bracket (independent of where the iteration stopped)
    long = exact.exact_mean(P0, A, R1, [R2], [lam], 400).mean[-1]
    assert st["lo"] - 1e-12 <= long <= st["hi"] + 1e-12
    # lambda = 1: p_inf is the fixed point of the Riccati map (quadratic formula)
    one = exact.stationary_mean(A, R1, [R2], [1.0])
    assert one["mean"] == pytest.approx(model.mare_fixed_point(A, R1, R2, 1.0), rel=1e-13)
    # and the bounds of eq. (7) hold in the limit
    assert R1 / (1 - (1 - lam) * A * A) < st["lo"] and st["hi"] < model.mare_fixed_point(A, R1, R2, lam)


def test_stationary_mean_refuses_the_unstable_case():
    with pytest.raises(ModelError, match="unbounded"):
        exact.stationary_mean(A, R1, [R2], [LAM_C - 0.1])


def test_mare_fixed_point_is_the_limit_of_the_upper_bound():
    lam = LAM_C + 0.1
    r = model.upper_bound_sequence(P0, A, R1, R2, lam, 2000)[-1]
    assert model.mare_fixed_point(A, R1, R2, lam) == pytest.approx(r, rel=1e-12)
    assert np.isinf(model.mare_fixed_point(A, R1, R2, LAM_C - 0.1))


def test_cheb_coeffs_cached_cosines_equal_direct_dct():
    from netrepro.papers.intermittent import exact as ex

    vals = np.linspace(0.3, 2.0, 33).astype(ex._LD) ** 3
    n = len(vals) - 1
    j = np.arange(n + 1, dtype=ex._LD)
    w = np.ones(n + 1, dtype=ex._LD)
    w[[0, -1]] = 0.5
    direct = (ex._LD(2) / n) * (np.cos(ex._PI * np.outer(j, j) / n) @ (w * vals))
    direct[[0, -1]] *= 0.5
    for _ in range(2):  # second call reads the cached matrix
        np.testing.assert_array_equal(ex._cheb_coeffs(vals), direct)
