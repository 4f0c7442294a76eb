"""Tests of `markov` expectations: the derived rate, the asymptote and the conditional estimate against
independent computations (brute-force enumeration, closed forms, the exact tree)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from netrepro.errors import InputError
from netrepro.papers.markov import exact, expectations as xp
from netrepro.papers.markov.model import parity_bound_example2

from .systems import EX1, EX2
from .test_exact import _brute_force_mean


def test_two_step_rate_closed_forms():
    # Example II: parity renewal rate lambda^4 (pq + (1-q)^2); 1 exactly on the parity critical curve
    assert xp.two_step_rate(EX2.A, EX2.C, EX2.Q, 0.99, 0.5) == pytest.approx(1.2 ** 4 * (0.495 + 0.25))
    q = 0.5
    p_c = float(parity_bound_example2(1.2, q))
    assert xp.two_step_rate(EX2.A, EX2.C, EX2.Q, p_c, q) == pytest.approx(1.0, abs=1e-12)
    # Example I (no parity lock): the loss-run rate (|lambda|^2 (1-q))^2
    assert xp.two_step_rate(EX1.A, EX1.C, EX1.Q, 0.5, 0.65) == pytest.approx((1.69 * 0.35) ** 2)


@pytest.mark.parametrize("p", [0.45, 0.99])
def test_two_step_rate_against_exact_ratios(p):
    """Exact two-step increment ratios of Example II approach the derived rate monotonically."""
    m = exact.exact_moments(EX2, np.eye(3), 16).mean(p, 0.5)
    rate2 = xp.two_step_rate(EX2.A, EX2.C, EX2.Q, p, 0.5)
    D = m[2:] - m[:-2]
    r = D[2:] / D[:-2]
    dev = np.abs(r - rate2)
    for par in (0, 1):
        assert np.all(np.diff(dev[6:][par::2]) < 0)
    assert dev[-1] < 0.01 * rate2


def test_asymptote_exact_on_geometric_sequence():
    k = np.arange(1, 41)
    R = 0.9
    seq = 5.0 - 3.0 * R ** (k / 2) + 0.5 * (-1) ** k * R ** (k / 2)  # two parity classes, exact ratio R
    mean, lo, hi = xp.asymptote_extrapolation(seq[:20], 40, R)
    assert np.allclose(mean, seq[20:], rtol=1e-12)
    assert np.allclose(lo, hi, rtol=1e-12)
    inside, err, mono = xp.asymptote_backtest(seq, R, 12)
    assert inside and err < 1e-12
    with pytest.raises(InputError, match="at least 6 exact values"):
        xp.asymptote_extrapolation(seq[:4], 10, R)


@pytest.mark.parametrize("p", [0.45, 0.99])
def test_asymptote_backtest_on_example2(p):
    """Extrapolating from k <= 12 brackets the exact E||P_k|| at k = 13..18 (Figs 5, 6 settings)."""
    m = exact.exact_moments(EX2, np.eye(3), 17).mean(p, 0.5)
    rate2 = xp.two_step_rate(EX2.A, EX2.C, EX2.Q, p, 0.5)
    inside, err, mono = xp.asymptote_backtest(m, rate2, 12)
    assert inside and mono
    assert err < 0.02


def test_conditional_estimate_against_enumeration():
    """Example I, k <= 8: the conditional estimate agrees with brute-force enumeration within its interval."""
    S0 = np.eye(2)
    mean, half = xp.conditional_estimate(EX1, S0, 0.5, 0.65, 3000, 7, np.random.default_rng(7), 1.96)
    exact_vals = np.array([_brute_force_mean(EX1, S0, 0.5, 0.65, k) for k in range(2, 9)])
    exact_vals = np.concatenate([[np.linalg.norm(S0, 2)], exact_vals])
    zmax, ok = xp.conditional_validation(mean, half, exact_vals, 4.0, 1.96, 1e-9)
    assert ok, zmax
    assert np.all(half[1:] / mean[1:] < 0.1)


def test_conditional_validation_rejects():
    exact_vals = np.array([1.0, 2.0, 3.0])
    zmax, ok = xp.conditional_validation(np.array([1.0, 2.0, 3.5]), np.array([0.0, 0.0, 0.196]), exact_vals, 4.0, 1.96, 1e-9)
    assert not ok and zmax == pytest.approx(5.0)
    # deterministic value (zero half-width) that disagrees: rejected
    zmax, ok = xp.conditional_validation(np.array([1.0, 2.1, 3.0]), np.array([0.0, 0.0, 0.196]), exact_vals, 4.0, 1.96, 1e-9)
    assert not ok and np.isinf(zmax)
    with pytest.raises(InputError, match="need at least the 3 exact ones"):
        xp.conditional_validation(np.array([1.0]), np.array([0.0]), exact_vals, 4.0, 1.96, 1e-9)


def test_expectations_table(markov_tables, markov_cfg):
    t = pd.read_csv(markov_tables["expectations"])
    assert list(t.columns) == ["example", "p", "q", "k", "mean_norm", "lo", "hi", "method", "limit", "limit_lo",
                               "limit_hi"]
    asym = t.method == "asymptote"
    assert t.limit[~asym].isna().all() and (t.limit_lo[asym] <= t.limit[asym]).all()
    assert (t.limit[asym] <= t.limit_hi[asym]).all()
    k_max = markov_cfg["paths"]["horizon"] + 1
    K = {"I": markov_cfg["exact"]["depth"] + 1, "II": markov_cfg["expectations"]["split_depth"] + 1}
    assert len(t) == len(markov_cfg["paths"]["cases"]) * k_max
    assert set(t.method) <= {"exact", "estimate_conditional", "asymptote", "not_trustworthy"}
    for ex, g in t.groupby("example"):
        assert (g.method[g.k <= K[ex]] == "exact").all() and (g.method[g.k > K[ex]] != "exact").all()
    bad = t.method == "not_trustworthy"
    assert t.mean_norm[bad].isna().all() and t.mean_norm[~bad].notna().all()
    ok = ~bad
    assert (t.lo[ok] <= t.mean_norm[ok] * (1 + 1e-12)).all() and (t.hi[ok] >= t.mean_norm[ok] * (1 - 1e-12)).all()
    est = t[t.method == "estimate_conditional"]
    assert ((est.hi - est.lo) / (2 * est.mean_norm) < markov_cfg["expectations"]["rel_tol"]).all()
    # the parity-locked Example II never uses the conditional estimator beyond the exact range
    assert not ((t.example == "II") & (t.method == "estimate_conditional")).any()
    # exact rows against the full (unsplit) tree recursion, computed independently here
    systems = {"I": EX1, "II": EX2}
    for (ex, p, q), g in t[t.method == "exact"].groupby(["example", "p", "q"]):
        m = exact.exact_moments(systems[ex], np.eye(systems[ex].n), K[ex] - 1).mean(p, q)
        assert np.allclose(g.sort_values("k").mean_norm, m, rtol=1e-10)


def test_asymptote_above_certified_lower_bound(markov_tables):
    """Fig. 6 setting: the asymptote never falls below the certified parity lower bound."""
    from netrepro.papers.markov.certificates import parity_lower_bound, parity_structure
    t = pd.read_csv(markov_tables["expectations"])
    a = t[(t.example == "II") & (t.method == "asymptote") & (t.p == 0.99)]
    st = parity_structure(EX2.A, EX2.C, EX2.Q)
    for r in a.itertuples():
        assert r.lo >= parity_lower_bound(st, r.p, r.q, int(r.k))


def test_asymptote_limit_is_the_limit_of_the_extrapolation():
    """Two parity classes with exact ratio R = 0.9 and limit 5 (written out), and the extrapolation carried far."""
    R = 0.9
    k = np.arange(1, 41)
    seq = 5.0 - 3.0 * R ** (k / 2) + 0.5 * (-1) ** k * R ** (k / 2)
    limit, lo, hi = xp.asymptote_limit(seq[:20], R)
    assert limit == pytest.approx(5.0, rel=1e-12) and lo == pytest.approx(5.0, rel=1e-12)
    assert hi == pytest.approx(5.0, rel=1e-12)
    far, far_lo, far_hi = xp.asymptote_extrapolation(seq[:20], 2000, R)
    assert far[-1] == pytest.approx(limit, rel=1e-10) and far_lo[-1] >= lo - 1e-9 and far_hi[-1] <= hi + 1e-9
    assert xp.asymptote_limit(seq[:20] * 0 + np.arange(20) ** 2, 1.1)[0] == np.inf
    with pytest.raises(InputError, match="at least 6 exact values"):
        xp.asymptote_limit(seq[:4], R)
