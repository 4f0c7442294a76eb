"""Certificates of the stability map against independent computations: exact enumeration of all channel
paths, brute-force event probabilities, the closed-form parity curve and the LMI of Theorem 2."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from netrepro.errors import ModelError
from netrepro.papers.markov import certificates as ce
from netrepro.papers.markov.exact import exact_moments
from netrepro.papers.markov.lmis import GilbertElliottLMI
from netrepro.papers.markov.model import H_matrix, parity_bound_example2

from .systems import A1, A2, C1, C2, EX1, EX2

DEPTH = 15
EM1 = exact_moments(EX1, np.eye(2), DEPTH)
EM2 = exact_moments(EX2, np.eye(3), DEPTH)
Q_NEC1 = 1 - 1 / 1.3 ** 2


@pytest.mark.parametrize("p,q", [(0.5, 0.65), (0.98, 0.45), (0.1, 0.42), (0.9, 0.9), (0.3, 0.5)])
def test_two_reception_bound_dominates_exact_means(p, q):
    """sup_k E||P_k|| <= U: checked against the exact expectation over all 2^14 channel paths."""
    U = ce.two_reception_bound(EX1, np.eye(2), p, q)
    exact = EM1.mean(p, q)
    assert np.isfinite(U) and U >= exact.max()


def test_two_reception_bound_infinite_below_necessary_condition_and_rejects_n_ne_2m():
    assert np.isinf(ce.two_reception_bound(EX1, np.eye(2), 0.5, Q_NEC1 - 0.01))
    with pytest.raises(ValueError, match="needs n = 2 m"):
        ce.two_reception_bound(EX2, np.eye(3), 0.5, 0.5)


@pytest.mark.parametrize("p,q", [(0.99, 0.5), (0.45, 0.5), (0.9, 0.25), (0.7, 0.8)])
def test_lower_bounds_below_exact_means(p, q):
    """Parity and loss-run lower bounds never exceed the exact E||P_k|| (both examples for the loss run)."""
    st = ce.parity_structure(A2, C2, np.eye(3))
    exact2 = EM2.mean(p, q)
    for k in range(2, DEPTH + 2):
        assert ce.parity_lower_bound(st, p, q, k) <= exact2[k - 1] * (1 + 1e-12)
    for k in range(3, DEPTH + 2):
        assert ce.loss_run_lower_bound(A2, np.eye(3), p, q, k) <= exact2[k - 1] * (1 + 1e-12)
        assert ce.loss_run_lower_bound(A1, np.eye(2), p, q, k) <= EM1.mean(p, q)[k - 1] * (1 + 1e-12)


def test_parity_event_probability_by_enumeration():
    """P(E_k) of parity_lower_bound against a brute-force sum over all channel paths."""
    st = ce.parity_structure(A2, C2, np.eye(3))
    p, q = 0.6, 0.35
    trans = {(1, 1): 1 - p, (1, 0): p, (0, 1): q, (0, 0): 1 - q}
    for k in range(2, 12):
        total = 0.0
        for tail in itertools.product([0, 1], repeat=k - 2):  # gamma_2..gamma_{k-1}
            gam = (1,) + tail
            if any(g == 1 and t % 2 == 0 for t, g in enumerate(gam, start=1)):
                continue
            total += np.prod([trans[(a, b)] for a, b in zip(gam[:-1], gam[1:])])
        factor = st["sigma2"] / st["f_norm2"] * sum(1.44 ** j for j in range(k - 1))
        assert ce.parity_lower_bound(st, p, q, k) == pytest.approx(factor * total, rel=1e-12)


def test_parity_growth_is_the_rate_of_the_bound_and_its_zero_set_is_the_closed_form_curve():
    st = ce.parity_structure(A2, C2, np.eye(3))
    p, q = 0.8, 0.5
    L = [float(ce.parity_lower_bound(st, p, q, k)) for k in (60, 62)]
    assert np.log(L[1] / L[0]) / 2 == pytest.approx(float(ce.parity_growth(1.2, p, q)), abs=1e-3)
    qs = np.linspace(0.35, 0.99, 7)
    assert np.allclose(ce.parity_growth(1.2, parity_bound_example2(1.2, qs), qs), 0.0, atol=1e-12)
    assert ce.parity_structure(A1, C1, np.eye(2)) is None


def test_thm1_radius_matches_closed_form_and_lmi():
    """Example II: 1 / min_K rho = the parity closed form; Example I: the LMI of Theorem 2 agrees on both sides."""
    qs = np.array([0.4, 0.5, 0.8])
    rho, K = ce.thm1_radius(A2, C2, qs)
    assert np.allclose(1 / rho, parity_bound_example2(1.2, qs), rtol=1e-9)
    for q, k, r in zip(qs, K, rho):  # the certificate is the gain: recompute its radius independently
        assert 0.999 * (1 / r) * np.max(np.abs(np.linalg.eigvals(H_matrix(A2, C2, [k], 1.0, q)))) < 1
    rho1, _ = ce.thm1_radius(A1, C1, [0.5])
    lmi = GilbertElliottLMI(A1, C1)
    assert lmi.solve(0.99 / rho1[0], 0.5).certified
    assert not lmi.solve(1.01 / rho1[0], 0.5).certified


def test_decide_certified_never_contradicts_and_raises_on_a_contradiction():
    P, Qg = np.meshgrid(np.linspace(0.02, 0.98, 7), np.linspace(0.02, 0.98, 7), indexing="ij")
    facts = ce.certificate_grid(EX2, np.eye(3), P, Qg)
    verdict, _ = ce.decide_certified(facts, P, 1e-9, 0.0)
    pc = parity_bound_example2(1.2, Qg)
    q_nec = 1 - 1 / 1.44
    truth = np.where((Qg > q_nec) & (P < pc), "bounded", "unbounded")
    assert (verdict == truth).all()
    facts1 = ce.certificate_grid(EX1, np.eye(2), P, Qg)
    v1, _ = ce.decide_certified(facts1, P, 1e-9, 0.0)
    assert (v1 == np.where(Qg > Q_NEC1, "bounded", "unbounded")).all()
    bad = dict(facts, upper=np.zeros(P.shape))  # claims every point bounded, contradicting the lower bounds
    with pytest.raises(ModelError, match="certified both bounded and unbounded"):
        ce.decide_certified(bad, P, 1e-9, 0.0)


def test_critical_distance():
    q, p = ce.true_critical_curve("nondegenerate", 1.3)
    d = ce.critical_distance(np.array([0.5, Q_NEC1]), np.array([0.5, 0.3]), q, p)
    assert d == pytest.approx([0.5 - Q_NEC1, 0.0], abs=1e-4)


def test_iid_instability_end_is_where_the_lower_bounds_start_to_grow():
    """On p + q = 1: Example II's parity bound grows exactly below 1 - |lambda|^-4 (parity_growth evaluated on
    both sides), Example I's loss-run bound exactly up to 1 - |lambda|^-2 (|lambda|^2 (1 - lambda) >= 1)."""
    end2, why2 = ce.iid_instability_end(A2, C2, np.eye(3))
    assert end2 == pytest.approx(1 - 1.2 ** -4, abs=1e-15) and "parity" in why2
    for lam_, sign in ((end2 - 1e-6, 1), (end2 + 1e-6, -1)):
        assert np.sign(ce.parity_growth(1.2, 1 - lam_, lam_)) == sign
    end1, why1 = ce.iid_instability_end(A1, C1, np.eye(2))
    assert end1 == pytest.approx(1 - 1.3 ** -2, abs=1e-15) and "loss-run" in why1
    assert 1.3 ** 2 * (1 - (end1 - 1e-6)) > 1 > 1.3 ** 2 * (1 - (end1 + 1e-6))
