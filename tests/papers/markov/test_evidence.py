"""The enumeration (enumeration.py), map and closed-form helpers behind the evidence of `markov`, against
independent computations; the evidence step and its data files."""

from __future__ import annotations

import ast
import itertools
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from netrepro.papers.markov import analysis as enumeration, evidence, exact, model, stability
from netrepro.judging.paperdata import load_paper_data
from netrepro.judging.verdicts import claims_table, errata_table, findings_table, read_evidence

from .systems import EX1, EX2
from .tables import PKG


def _psi(P, g, system):
    return model.riccati_g(P, system.A, system.C, system.Q, system.R) if g else model.riccati_h(P, system.A, system.Q)


@pytest.mark.parametrize("system", [EX1, EX2])
def test_enumeration_matches_exact_tree(system):
    """Brute force over all 2^(k-1) paths (gamma_1 = 1) equals the transition-count tree of exact.py."""
    paths = enumeration.enumerate_norms(system, np.eye(system.n), 8)
    em = exact.exact_moments(system, np.eye(system.n), 7)
    for p, q in ((0.3, 0.6), (0.9, 0.95)):
        assert np.allclose(enumeration.mean_norm_enumerated(paths, p, q, "gamma1"), em.mean(p, q), rtol=1e-10)


def test_stationary_start_by_hand():
    """E||P_3|| with gamma_1 drawn from the stationary law, by the two-step formula written out."""
    p, q = 0.7, 0.8
    S0 = np.eye(2)
    pi1 = q / (p + q)
    law = {1: pi1, 0: 1 - pi1}
    trans = {(1, 1): 1 - p, (1, 0): p, (0, 1): q, (0, 0): 1 - q}
    want = sum(law[a] * trans[(a, b)] * np.linalg.norm(_psi(_psi(S0, a, EX1), b, EX1), 2)
               for a, b in itertools.product([0, 1], repeat=2))
    got = enumeration.mean_norm_enumerated(enumeration.enumerate_norms(EX1, S0, 3), p, q, "stationary")
    assert got[2] == pytest.approx(want, rel=1e-12)
    assert got[0] == pytest.approx(1.0)


def test_monotonicity_violation_on_a_hand_table():
    means = np.array([[1.0, 2.0], [1.5, 1.8], [2.0, 2.1]])
    v = enumeration.monotonicity_violation(means, [0.1, 0.2, 0.3])
    assert v["violation"] == pytest.approx(0.2 / 1.8)
    assert (v["p1"], v["p2"], v["k"]) == (0.2, 0.1, 2)
    assert enumeration.monotonicity_violation(means, [0.1, 0.2, 0.3], rtol=0.2)["violation"] == 0.0
    assert enumeration.monotonicity_violation(np.sort(means, axis=0), [0.1, 0.2, 0.3])["violation"] == 0.0


def test_prop1_closed_form_value():
    """Section 5.1: |lambda| = 1.3, q = 0.65 gives 0.22 (by hand: 0.4085 / 1.856465)."""
    assert float(model.prop1_closed_form(1.3, 0.65)) == pytest.approx(0.4085 / 1.856465, rel=1e-12)


def test_single_transition():
    rows = [("I", p, 0.5, "bounded" if p < 0.4 else "unbounded") for p in (0.1, 0.3, 0.5, 0.7)]
    ok, _ = stability.single_transition(*zip(*rows))
    assert ok
    rows[3] = ("I", 0.7, 0.5, "bounded")
    bad, note = stability.single_transition(*zip(*rows))
    assert not bad and "1 of 1" in note


def _signed_coupling(p1, p2, q, k):
    """Paths of the Fig. 1 chain on {(0,0), (0,1), (1,1)} from (1,1), with (signed) weights."""
    step = {(1, 1): {(1, 1): 1 - p1, (0, 1): p1 - p2, (0, 0): p2},
            (0, 1): {(1, 1): q, (0, 0): p2, (0, 1): 1 - q - p2},
            (0, 0): {(1, 1): q, (0, 0): 1 - q}}
    paths = [((1, 1),)]
    weights = [1.0]
    for _ in range(k - 2):
        paths, weights = zip(*[(s + (t,), w * pr) for s, w in zip(paths, weights) for t, pr in step[s[-1]].items()])
    return paths, np.array(weights)


def test_signed_coupling_argument_fails_from_gamma1():
    """Erratum E10: the signed chain has the right marginals and phi_1 >= phi_2 in norm on every path, yet
    E_p1||P_k|| < E_p2||P_k|| with gamma_1 = 1: ordering integrals under a signed measure is invalid."""
    q, k = 0.95, 8
    em = exact.exact_moments(EX1, np.eye(2), k - 1)
    ps = np.linspace(0.5, 0.99, 50)
    means = em.mean(ps, q)[:, k - 1]
    i1 = int(np.argmin(means[ps > 0.9]) + np.flatnonzero(ps > 0.9)[0])
    i2 = int(np.argmax(means[:i1]))
    p1, p2 = ps[i1], ps[i2]
    assert means[i2] > means[i1] and p2 < p1 and p2 + q > 1
    paths, w = _signed_coupling(p1, p2, q, k)
    assert w.min() < 0
    norm1, norm2 = [], []
    for path in paths:
        P1 = P2 = np.eye(2)
        for z, zt in path:  # (gamma_1, ..., gamma_{k-1}) of both chains: P_k
            P1, P2 = _psi(P1, z, EX1), _psi(P2, zt, EX1)
        norm1.append(np.linalg.norm(P1, 2))
        norm2.append(np.linalg.norm(P2, 2))
    norm1, norm2 = np.array(norm1), np.array(norm2)
    assert np.all(norm1 >= norm2 - 1e-9)
    # marginals: the signed integrals are the two channels' expectations at k (paths give P_{k})
    e1, e2 = em.mean(p1, q)[k - 1], em.mean(p2, q)[k - 1]
    assert w @ norm1 == pytest.approx(e1, rel=1e-9)
    assert w @ norm2 == pytest.approx(e2, rel=1e-9)
    assert w @ (norm1 - norm2) < 0


def test_data_files_load():
    data = load_paper_data("markov")
    ids = {c.claim_id for c in data.claims}
    assert {"ref16_p004", "ref16_p0045", "exI_fig3_stable", "thm5_lower_bound", "prop2_threshold"} <= ids
    assert "exI_iid_consistent" not in ids
    kinds = {c.claim_id: c.kind for c in data.claims}
    assert kinds["ref16_p004"] == kinds["ref16_p0045"] == "not_checkable"
    assert {e["id"] for e in data.errata} >= {"E10_prop2_signed_measure"}
    assert not {"E4_ref16_value", "E8_prop1_form"} & {e["id"] for e in data.errata}


def test_evidence_step_feeds_every_claim(markov_tables):
    """On the tiny configuration every claim, erratum and finding finds its evidence."""
    ev = read_evidence(markov_tables["evidence"])
    data = load_paper_data("markov")
    claims = claims_table(data, {}, ev).set_index("claim_id")
    assert claims.loc["exII_p0465_certified", "verdict"] == "erratum"
    assert claims.loc["exII_fig6_diverges", "robust"] == "yes"
    assert claims.loc["ref16_p004", "verdict"] == "not_checkable"
    assert claims.loc["thm3_peak_implies_ms", "verdict"] == "reproduced"
    assert "U = " in claims.loc["thm3_peak_implies_ms", "note"]
    errata = errata_table(data, ev).set_index("erratum_id")
    assert float(errata.loc["E10_prop2_signed_measure", "residual_printed"]) > 0
    assert float(errata.loc["E10_prop2_signed_measure", "residual_corrected"]) == 0
    assert len(findings_table(data, ev)) == len(data.findings)


def test_tight_variants_bracket_the_closed_form(markov_tables):
    """Every tolerance's certified bracket at q = 0.5 contains the Example II critical value derived by hand:
    |lambda|^4 (pq + (1-q)^2) = 1 with |lambda| = 1.2, i.e. p = (1 - 2.0736 / 4) / (2.0736 / 2)."""
    t = pd.read_csv(markov_tables["tight"])
    t = t[t.check == "exII_q05"]
    assert len(t) >= 2
    p_c = (1 - 2.0736 / 4) / (2.0736 / 2)
    assert p_c == pytest.approx(0.4645061728, abs=1e-10)
    assert ((t.p_lower <= p_c) & (t.p_upper >= p_c)).all()
    # below ~1e-7 the certified bracket stops shrinking with the tolerance (solver accuracy near the edge)
    assert ((t.p_upper - t.p_lower)[t.tol <= 1e-6] < 1e-6).all()


def test_path_weights_from_codes_equal_the_direct_form():
    """path_weights via transition_codes: bit for bit the product of the nested-where step probabilities."""
    G = np.array(np.meshgrid(*[[0, 1]] * 6, indexing="ij")).reshape(6, -1).T
    for p, q in ((0.3, 0.7), (0.97, 0.05), (np.float64(0.123456789), 0.9)):
        a, b = G[:, :-1], G[:, 1:]
        step = np.where(a == 1, np.where(b == 1, 1 - p, p), np.where(b == 1, q, 1 - q))
        for gamma1 in (0, 1):
            ref = np.where(G[:, 0] == gamma1, 1.0, 0.0) * np.prod(step, axis=1)
            assert np.array_equal(enumeration.path_weights(G, p, q, gamma1), ref)
            assert np.array_equal(enumeration.path_weights(G, p, q, gamma1, enumeration.transition_codes(G)), ref)



@pytest.mark.parametrize("system", [EX1, EX2])
def test_mean_norms_enumerated_equal_the_per_p_form_bit_for_bit(system):
    """mean_norms_enumerated (weights as prefix products along the path tree, all p at once) gives exactly
    mean_norm_enumerated (every path's steps gathered and multiplied by numpy.prod) at every p, both starts;
    paths not in enumerate_norms' order go through the per-p form (same numbers)."""
    paths = enumeration.enumerate_norms(system, np.eye(system.n), 10)
    ps = np.linspace(0.05, 0.999, 23)
    for q in (0.3, 0.9, 0.999):
        for start in ("gamma1", "stationary"):
            ref = np.array([enumeration.mean_norm_enumerated(paths, p, q, start) for p in ps])
            assert np.array_equal(enumeration.mean_norms_enumerated(paths, ps, q, start), ref)
            shuffled = [(G[::-1], n[::-1]) for G, n in paths]   # same sums in another order: not the tree
            got = enumeration.mean_norms_enumerated(shuffled, ps, q, start)
            assert np.array_equal(got, np.array([enumeration.mean_norm_enumerated(shuffled, p, q, start) for p in ps]))
            assert np.allclose(got, ref, rtol=1e-12)

def test_evidence_imports_no_private_name_and_defines_no_mathematics():
    """evidence.py assembles: it imports no private name and defines only its step, the settings reader and
    private row builders (issue 29)."""
    tree = ast.parse(Path(evidence.__file__).read_text())
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            assert not [a.name for a in node.names if a.name.startswith("_")], node.module
    public = {n.name for n in tree.body if isinstance(n, ast.FunctionDef) and not n.name.startswith("_")}
    assert public == {"evidence_step", "claim_settings"}


def test_claim_settings_reach_the_evidence_from_the_yaml(markov_cfg, markov_tables, tmp_path):
    """The loss rate of claim exI_loss_rate_004 is computed at the claim's own `at:` (p, q): edit the YAML, the
    value follows (p / (p + q), eq. 3, written out here)."""
    text = (PKG / "claims.yaml").read_text()
    assert "at: {p: 0.04, q: 0.65}" in text
    claims = tmp_path / "claims.yaml"
    claims.write_text(text.replace("at: {p: 0.04, q: 0.65}", "at: {p: 0.1, q: 0.4}"))
    at = evidence.claim_settings(claims, PKG / "findings.yaml")
    assert at["exI_loss_rate_004"]["at"] == {"p": 0.1, "q": 0.4}
    assert at["prop1_is_thm1_K0"]["at"] == {"q": 0.65}
    inputs = {k: markov_tables[k] for k in ("checks", "tight", "curves", "iid", "map", "sensitivity", "moments",
                                            "holdout")}
    out = evidence.evidence_step(markov_cfg, dict(inputs, claims=claims, findings=PKG / "findings.yaml"), {})["table"]
    row = out[(out.quantity == "exI.loss_rate_p004") & (out.variant == "nominal")]
    assert float(row.value.iloc[0]) == pytest.approx(0.1 / (0.1 + 0.4), rel=1e-12)


def test_ceiling_finding_on_the_tiny_tables(markov_tables):
    """The Example II ceiling rows exist, hold, and carry the computed values (not typed in the YAML)."""
    ev = read_evidence(markov_tables["evidence"])
    assert ev["exII.unstable_above_ceiling"]["nominal"][0] is True
    assert ev["exII.p_c_ceiling"]["nominal"][0] == pytest.approx(model.parity_ceiling(1.2)["p_max"], rel=1e-12)
    assert "0.5609" not in (PKG / "findings.yaml").read_text()


def test_configured_points_are_the_claims_settings():
    """The LMI check points and the figure settings of config/config.yaml are the `at:` of the claims they serve
    (a paper setting lives in the claim; the configuration must not drift from it)."""
    import yaml

    cfg = yaml.safe_load((PKG.parents[3] / "config" / "config.yaml").read_text())["markov"]
    at = evidence.claim_settings(PKG / "claims.yaml", PKG / "findings.yaml")
    points = {p["name"]: (p["example"], p["p"], p["q"]) for p in cfg["checks"]["points"]}
    served = {"exI_thm2_p1": "exI_lmi_p1", "exI_fig3_p05": "exI_fig3_stable", "exI_thm2_p099": "exI_fig4_stable",
              "exII_thm2_p1": "exII_lmi_p1_infeasible", "exII_thm5_p0465": "exII_p0465_certified",
              "exII_fig5_p045": "exII_fig5_stable"}
    for check, claim in served.items():
        assert points[check][1:] == (at[claim]["at"]["p"], at[claim]["at"]["q"]), (check, claim)
    figs = {c["figure"]: (c["p"], c["q"]) for c in cfg["paths"]["cases"]}
    for fig, claim in (("fig3", "exI_fig3_stable"), ("fig4", "exI_fig4_stable"), ("fig5", "exII_fig5_stable"),
                       ("fig6", "exII_fig6_diverges")):
        assert figs[fig] == (at[claim]["at"]["p"], at[claim]["at"]["q"]), (fig, claim)
    assert {t["q"] for t in cfg["checks"]["tight"] if t["example"] == "II"} == {at["exII_thm5_q05"]["at"]["q"]}


def test_undecided_certificates_make_undecided_verdicts_never_differs(markov_cfg, markov_tables, tmp_path):
    """An LMI point the certificate leaves undecided and a wide bisection bracket (as from a solver stopped after a
    few iterations) give evidence rows with decided False or a wide uncertainty, and the verdicts read undecided,
    never differs (issue 37); a certified-infeasible point stays decided."""
    checks = pd.read_csv(markov_tables["checks"])
    fig3 = checks.check == "exI_fig3_p05"
    checks.loc[fig3, ["verdict", "certified"]] = ["undecided", False]
    lower = checks.check == "exII_q05_tight_lower"
    checks.loc[lower, "p"] = 0.4167  # a short bisection: the bracket [0.4167, 0.46451] straddles 0.4645
    tight = pd.read_csv(markov_tables["tight"])
    tight.loc[tight.check == "exII_q05", "p_lower"] = 0.4167
    checks.to_csv(tmp_path / "checks.csv", index=False)
    tight.to_csv(tmp_path / "tight.csv", index=False)
    inputs = {k: markov_tables[k] for k in ("curves", "iid", "map", "sensitivity", "moments", "holdout")}
    out = evidence.evidence_step(markov_cfg, dict(inputs, checks=tmp_path / "checks.csv", tight=tmp_path / "tight.csv",
                                                  claims=PKG / "claims.yaml", findings=PKG / "findings.yaml"), {})
    out["table"].to_csv(tmp_path / "evidence.csv", index=False)
    ev = read_evidence(tmp_path / "evidence.csv")
    assert ev["exI.fig3_certified"]["nominal"].decided is False
    assert ev["exII.lmi_p1_infeasible"]["nominal"].decided is True
    assert ev["exII.p_thm5_q05"]["nominal"].uncertainty > 0.02
    claims = claims_table(load_paper_data("markov"), {}, ev).set_index("claim_id")
    assert claims.loc["exI_fig3_stable", "verdict"] == "undecided"
    assert claims.loc["exII_thm5_q05", "verdict"] == "undecided"
    assert claims.loc["exII_lmi_p1_infeasible", "verdict"] == "reproduced"
    assert not (claims.verdict == "differs").any()
