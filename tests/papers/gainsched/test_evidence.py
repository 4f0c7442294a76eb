"""Evidence of `gainsched` (issue 15): the helpers of :mod:`.analysis` against independent computations, the data files."""

from __future__ import annotations

import numpy as np
import pytest

from netrepro.engines.certify import LMICoefficients
from netrepro.papers.gainsched.design import FixedGainsVertexLMI, Theorem3, zero_diagonal_blocks
from netrepro.papers.gainsched.evidence import feasible_flag
from netrepro.papers.gainsched.analysis import (
    convergence_rate,
    missing_fraction,
    ms_stability_index,
    r2_congruence_residuals,
)
from netrepro.papers.gainsched.feasibility import with_sigma2
from netrepro.papers.gainsched.model import Gains, sector_cases, theorem1_matrix, zero_gains
from netrepro.judging.paperdata import load_paper_data

from .conftest import random_gains


def _plant_radius(sys, Fs) -> float:
    """max_F rho((A+BFZ) (x) (A+BFZ) + sigma^2 D (x) D), by a dense eigenvalue solve (not the package's helper)."""
    out = 0.0
    for F in Fs:
        AF = sys.A + sys.B @ F @ sys.Z
        op = np.kron(AF, AF) + sys.sigma2 * np.kron(sys.D, sys.D)
        out = max(out, max(abs(np.linalg.eigvals(op))))
    return out


def test_paper_data_loads_and_covers_section5():
    data = load_paper_data("gainsched")
    ids = {c.claim_id: c for c in data.claims}
    assert sum(c.kind == "not_identifiable" for c in data.claims) == 12
    assert ids["remark5_lmi_hour"].kind == "context"
    assert ids["remark2_missing_bound"].erratum_id == "E6_remark2_example"
    assert {"paper_gains_vertex_lmi", "vertex_combination", "less_conservative"} <= set(ids)
    assert "gamma3_rows" in {r["key"] for r in data.reconstructions}
    assert {"D1_trivial_filter_passes", "D4_noise_free_case"} <= {f.finding_id for f in data.findings}
    assert ids["remark2_missing_bound"].at == {"bound": 0.5}  # the paper's setting reaches the evidence from here
    assert len(ids["vertex_combination"].at["pairs"]) == 3
    assert not any(e["id"].startswith(("D", "E4")) for e in data.errata)
    for c in data.claims:  # every claim that depends on a reconstruction names where it is nominal
        assert not c.depends_on or c.nominal


def test_feasible_flag_never_counts_undecided():
    assert feasible_flag("feasible") is True
    assert feasible_flag("infeasible") is False
    assert feasible_flag("undecided") is None


def test_r2_residuals_closed_form():
    rng = np.random.default_rng(3)
    n = 2
    S11, S12 = rng.standard_normal((n, n)), rng.standard_normal((n, n))
    S22 = rng.standard_normal((n, n)) + 3 * np.eye(n)
    # (23) with S21 = I: R1 = S12 S22^{-1}, R2 = S22^{-T}
    vals = {"S11": S11, "R1": S12 @ np.linalg.inv(S22), "R2": np.linalg.inv(S22).T}
    res = r2_congruence_residuals(vals)
    assert res["corrected"] < 1e-12
    assert res["printed"] > 1e-3  # R2 not symmetric: the printed relation gives another S22
    sym = np.array([[2.0, 0.3], [0.3, 1.5]])  # symmetric R2: both relations coincide
    both = r2_congruence_residuals({"S11": S11, "R1": vals["R1"], "R2": sym})
    assert both["printed"] < 1e-12 and both["corrected"] < 1e-12


def test_missing_fraction_matches_bernoulli():
    p = np.full(40, 0.7)
    frac, se = missing_fraction(p, 3000, 11)
    assert se == pytest.approx(np.sqrt(0.7 * 0.3 / (3000 * 40)), rel=1e-12)
    assert abs(frac - 0.3) < 4 * se


def test_rates_of_the_zero_filter_are_the_plant_radius(sys):
    """x_f = 0: the augmented second moment grows like the plant's; rates -> the Kronecker spectral radius."""
    p_seq = np.full(400, 0.6)
    rate = convergence_rate(sys, zero_gains(sys), p_seq)
    Fs = [sys.F1, sys.F2, 0.5 * (sys.F1 + sys.F2)]
    assert rate == pytest.approx(_plant_radius(sys, Fs), rel=0.02)
    for s2 in (1.0, 4.0):
        s = with_sigma2(sys, s2)
        idx = ms_stability_index(s, zero_gains(s), [0.4, 0.8], p_seq)
        assert idx == pytest.approx(_plant_radius(s, sector_cases(s).values()), rel=0.02)
    assert ms_stability_index(with_sigma2(sys, 4.0), zero_gains(sys), [0.4], p_seq) > 1.0


def test_fixed_gain_vertex_equals_theorem1_matrix_on_the_diagonal(sys):
    """Vertex (p, p, p, p+) of (24) in original coordinates == (12) at (p, p+) (independent builder)."""
    rng = np.random.default_rng(5)
    g = random_gains(rng, sys)
    lmi = FixedGainsVertexLMI(sys, g)
    nn = 2 * sys.n
    Q0, Qp, S = np.eye(nn) * 2, np.diag(rng.random(nn)), rng.standard_normal((nn, nn))
    lmi.Q0.value, lmi.Qp.value, lmi.S.value = Q0, Qp, S
    for p, pn in ((sys.p1, sys.p2), (0.55, 0.7)):
        V = lmi.vertex(p, p, p, pn).value
        M = theorem1_matrix(sys, g, Q0 + p * Qp, Q0 + pn * Qp, S, p)
        assert np.allclose(V, M, atol=1e-12)


def test_fixed_gain_vertex_equals_theorem3_with_T_identity(sys, paper):
    """Theorem 3 with the printed gains and S21 = S22 = R2 (T = I) is the same matrix with S = [[S11, R1], [R2, R2]]."""
    rng = np.random.default_rng(9)
    n, nn = sys.n, 2 * sys.n
    t3 = Theorem3(sys, fixed_gains=paper)
    vals = {"Q0": np.eye(nn), "Qp": 0.5 * np.eye(nn), "S11": rng.standard_normal((n, n)),
            "R1": rng.standard_normal((n, n)), "R2": rng.standard_normal((n, n)) + 2 * np.eye(n)}
    for k, x in vals.items():
        t3.vars[k].value = x
    gen = FixedGainsVertexLMI(sys, paper)
    gen.Q0.value, gen.Qp.value = vals["Q0"], vals["Qp"]
    gen.S.value = np.block([[vals["S11"], vals["R1"]], [vals["R2"], vals["R2"]]])
    ps = (sys.p1, sys.p2)
    for idx in ((0, 1, 0, 1), (1, 0, 1, 1), (1, 1, 0, 0)):
        args = [ps[i] for i in idx]
        assert np.allclose(t3.vertex(*args).value, gen.vertex(*args).value, atol=1e-12)


def test_printed_gains_certified_feasible_and_unstable_gains_infeasible(sys, paper):
    lmi = FixedGainsVertexLMI(sys, paper, bound=100.0)
    v, _, _ = lmi.certify(sys.sigma2)
    assert v.verdict == "feasible"
    v5, _, _ = lmi.certify(5.0)
    assert v5.verdict == "infeasible"  # the plant itself is not MS stable at sigma^2 = 5
    n, m = sys.n, sys.m
    bad = Gains(1.5 * np.eye(n), np.zeros((n, n)), np.zeros((n, m)), np.zeros((n, m)))  # x_f explodes
    vb, _, _ = FixedGainsVertexLMI(sys, bad, bound=100.0).certify(sys.sigma2)
    assert vb.verdict == "infeasible"


def test_zero_diagonal_blocks_finds_only_identically_zero_entries():
    F0 = [np.diag([1.0, 0.0, 0.0]), np.eye(2)]
    F = [np.stack([np.diag([0.0, 1.0, 0.0]), np.zeros((3, 3))]), np.zeros((2, 2, 2))]
    coeffs = LMICoefficients(F0, F, ["a", "b"], ["u0", "u1"])
    assert zero_diagonal_blocks(coeffs) == [("a", 2)]


def test_noise_row_at_sigma0_has_zero_diagonal(sys):
    s0 = with_sigma2(sys, 0.0)
    with_row = Theorem3(s0, noise_row=True)
    with_row.sigma2.value = 0.0
    without = Theorem3(s0, noise_row=False)
    without.sigma2.value = 0.0
    assert len(zero_diagonal_blocks(with_row.certifier.coefficients())) == 16 * 2 * sys.n
    assert zero_diagonal_blocks(without.certifier.coefficients()) == []


def test_every_finding_is_judged_like_a_claim():
    """Issue 27: each finding has a rule with its reason (observations: none, issue 37), evidence quantities,
    depends_on and prior_work; an observation that replaced a registered rule keeps it in its amendments."""
    data = load_paper_data("gainsched")
    keys = {r["key"] for r in data.reconstructions}
    for f in data.findings:
        assert f.kind in ("boolean", "numeric", "observation"), f.finding_id
        if f.kind == "observation":
            assert f.finding_id in ("F6_theorem3_near_robust_limit", "F7_scheduling_buys_little"), f.finding_id
            continue
        assert f.rule_reason.strip(), f.finding_id
        assert f.quantity in f.evidence_quantities, f.finding_id
        assert set(f.depends_on) <= keys, f.finding_id
        assert f.prior_work.strip(), f.finding_id
        if f.kind == "numeric":
            assert f.tolerance > 0, f.finding_id


def test_claim_variants_are_declared_ranges():
    """Convention 2: every variant of the committed evidence table is <key>=... or <key>: ... with key in depends_on."""
    import re
    from pathlib import Path

    import pandas as pd

    path = Path(__file__).resolve().parents[3] / "tests" / "reference" / "evidence" / "gainsched.csv"
    ev = pd.read_csv(path, keep_default_na=False)
    data = load_paper_data("gainsched")
    deps = {c.ours.get("quantity"): set(c.depends_on) for c in data.claims if c.ours.get("quantity")}
    deps.update({f.quantity: set(f.depends_on) for f in data.findings})
    for row in ev[ev["variant"] != "nominal"].itertuples():
        if row.quantity not in deps:
            continue
        key = re.split(r"[=:]", row.variant, maxsplit=1)[0]
        assert key in deps[row.quantity], (row.quantity, row.variant)
