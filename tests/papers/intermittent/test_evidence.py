from pathlib import Path

import numpy as np
import pytest

from netrepro.errors import InputError
from netrepro.papers.intermittent import evidence
from netrepro.judging.paperdata import load_paper_data

REFERENCE = Path(__file__).resolve().parents[2] / "reference"

A, R1, R2, P0 = 1.5, 0.1, 0.5, 10.0
LAM = 1 - 1 / A**2 + 0.1


def test_paper_data_loads_and_every_dependent_claim_names_a_reconstruction():
    data = load_paper_data("intermittent")
    keys = {r["key"] for r in data.reconstructions}
    assert {"C15", "C16"} <= {c.claim_id for c in data.claims}
    assert {"E15", "E16", "E17", "E18", "E19", "E20"} <= {e["id"] for e in data.errata}
    # E3 (eq. (11)) follows algebraically from E2's printed condition: merged, not counted twice (issue 27)
    assert "E3" not in {e["id"] for e in data.errata}
    kinds = {e["id"]: e["kind"] for e in data.errata}
    assert kinds["E12"] == kinds["E14"] == "notation"
    assert all(set(c.depends_on) <= keys for c in data.claims)


def test_evidence_imports_no_private_name_of_another_module():
    import ast
    import inspect

    tree = ast.parse(inspect.getsource(evidence))
    private = [f"{node.module}.{alias.name}" for node in ast.walk(tree) if isinstance(node, ast.ImportFrom)
               for alias in node.names if alias.name.startswith("_")]
    assert private == []


def test_evidence_defines_no_mathematical_helper():
    # issue 29: evidence is assembly only; its public interface is the step
    assert evidence.__all__ == ["evidence_step"]


def test_claim_settings_come_from_the_yaml():
    data = load_paper_data("intermittent")
    c15 = next(c for c in data.claims if c.claim_id == "C15")
    assert c15.at == {"k": 25}
    assert evidence._claim_settings(data.claims, "C15") == {"k": 25}
    with pytest.raises(InputError, match="C99"):
        evidence._claim_settings(data.claims, "C99")


def test_only_declared_ranges_label_the_variants_of_the_intermittent_claims(tmp_path):
    # convention 2 (issue 27): a variant decides only if labelled <key>=... with <key> in depends_on
    import pandas as pd

    ref = pd.read_csv(REFERENCE / "evidence" / "intermittent.csv")
    data = load_paper_data("intermittent")
    entries = [(c.claim_id, (c.ours or {}).get("quantity"), c.depends_on) for c in data.claims]
    entries += [(f.finding_id, f.quantity, f.depends_on) for f in data.findings]
    for name, q, depends_on in entries:
        labels = ref.loc[(ref["quantity"] == q) & (ref["variant"] != "nominal"), "variant"]
        for label in labels:
            key = label.split("=", 1)[0]
            assert "=" in label and key in depends_on, (name, label)


def test_every_finding_has_a_rule_evidence_and_prior_work():
    import pandas as pd

    ref = pd.read_csv(REFERENCE / "evidence" / "intermittent.csv")
    for f in load_paper_data("intermittent").findings:
        # an observation is measured, not judged: no rule; its registered rule (amendments) had one
        assert f.prior_work and (f.kind == "observation" or (f.rule_reason and f.kind in ("numeric", "boolean"))), \
            f.finding_id
        assert f.kind != "observation" or f.amendments, f.finding_id
        assert f.quantity in f.evidence_quantities, f.finding_id
        assert set(f.evidence_quantities) <= set(ref["quantity"]), f.finding_id
        assert isinstance(f.known, bool)


def test_mean_is_concave_in_p0_so_the_two_point_laws_bracket_the_p0_range():
    # the range of reconstruction scalar.Ep0 rests on E(p_k | p0 = q) being concave in q (enumeration, k <= 8)
    from netrepro.papers.intermittent.model import exact_mean_enumeration

    m = {q: exact_mean_enumeration(q, A, R1, R2, LAM, 8) for q in (0.0, 5.0, 10.0, 15.0, 20.0)}
    assert np.all(m[10.0] >= 0.5 * (m[5.0] + m[15.0]) - 1e-12)
    assert np.all(0.5 * (m[5.0] + m[15.0]) >= 0.5 * (m[0.0] + m[20.0]) - 1e-12)
    assert np.any(m[10.0][1:] > 0.5 * (m[0.0] + m[20.0])[1:] + 1e-6)


def test_e19_gap_grid_batched_equals_the_scalar_calls():
    """E19 evaluates X -> g(X) - X on its bracketing grid in one batched expected_riccati_map call: for
    scalar sensors every entry is the per-X call's number bit for bit (1 x 1 products and divisions), which
    is what the row relied on when it called the map once per grid point."""
    from netrepro.engines.riccati import Sensor, expected_riccati_map

    sensors = [Sensor([[1.0]], [[1.0]]), Sensor([[1.0]], [[4.0]])]
    xs = np.logspace(-3, 8, 111)
    for a, lams in ((1.25, [0.3, 0.0]), (1.25, [0.3, 0.57]), (2.0, [0.9, 1.0]), (0.7, [0.01, 0.99])):
        batched = expected_riccati_map(xs[:, None, None], [[a]], [[1.0]], sensors, lams)[:, 0, 0] - xs
        scalar = np.array([float(expected_riccati_map([[x]], [[a]], [[1.0]], sensors, lams)[0, 0]) - x for x in xs])
        assert np.array_equal(batched, scalar)
        # and against the closed form of the corrected eq. (15) (two scalar sensors, independent losses)
        l1, l2 = lams
        post = lambda x, r: x - x * x / (x + r)  # noqa: E731
        both = post(post(xs, 1.0), 4.0)
        ref = a * a * ((1 - l1) * (1 - l2) * xs + l1 * (1 - l2) * post(xs, 1.0) + (1 - l1) * l2 * post(xs, 4.0)
                       + l1 * l2 * both) + 1.0 - xs
        assert np.allclose(batched, ref, rtol=1e-9, atol=1e-9 * xs)


def test_exact_is_exact_mean_computed_once_per_argument_set():
    """The evidence step's kept E(p_k): bit for bit a fresh exact_mean call (np.float64 and float arguments
    alike), the same object on a repeat, read-only so that no reader can change what the next one gets."""
    from netrepro.papers.intermittent.exact import exact_mean

    sc = {"a": 1.5, "R1": 0.1, "R2": 0.5}
    lam = float(np.float64(1.0 - 1.0 / 1.5**2) + 0.1)
    evidence._exact_once.cache_clear()
    for p0, horizon in ((10.0, 60), (0.0, 60), (15.0, 30)):
        fresh = exact_mean(p0, sc["a"], sc["R1"], [sc["R2"]], [lam], horizon)
        kept = evidence._exact(np.float64(p0), sc, np.float64(lam), horizon)
        assert kept is evidence._exact(p0, sc, lam, np.int64(horizon))
        for name in ("mean", "rel_error_bound", "mu", "mu_error_bound"):
            assert np.array_equal(getattr(kept, name), getattr(fresh, name))
            assert getattr(kept, name).tobytes() == getattr(fresh, name).tobytes()
            with pytest.raises(ValueError, match="read-only"):
                getattr(kept, name)[0] = 1.0
        assert (kept.rho, kept.degree) == (fresh.rho, fresh.degree)
    assert evidence._exact_once.cache_info().misses == 3
