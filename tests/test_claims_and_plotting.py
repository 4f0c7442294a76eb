"""The shared claims helpers (netrepro.claims) and the plotting helpers (netrepro.plotting)."""

import hashlib

import pytest

from netrepro.claims import CLAIM_COLUMNS, claim_row, claims_frame, errata_frame, reconstructions_frame
from netrepro.plotting import new_figure, save_figure


def row(**kw):
    args = dict(paper="p", claim_id="C1", statement="s", paper_value=0.4, reproduced_value=0.44,
                tolerance=0.05, tolerance_reason="one digit")
    args.update(kw)
    return claim_row(**args)


def test_claim_row_verdict_is_computed_from_the_tolerance():
    assert row()["verdict"] == "reproduced"
    assert row(reproduced_value=0.46)["verdict"] == "differs"
    assert row(reproduced_value=float("nan"))["verdict"] == "differs"
    assert row(paper_value=10.0, reproduced_value=10.9, tolerance=0.1, relative=True)["verdict"] == "reproduced"
    assert row(paper_value=10.0, reproduced_value=11.1, tolerance=0.1, relative=True)["verdict"] == "differs"
    assert row(reproduced_value=0.9, erratum=True)["verdict"] == "erratum"
    # an erratum flag never hides an agreement
    assert row(erratum=True)["verdict"] == "reproduced"
    assert row(paper_value=True, reproduced_value=False)["verdict"] == "differs"
    assert row(paper_value=True, reproduced_value=True)["verdict"] == "reproduced"


def test_claims_frame_checks_ids_and_verdicts():
    frame = claims_frame([row(), row(claim_id="C2")])
    assert list(frame.columns) == CLAIM_COLUMNS
    with pytest.raises(ValueError, match="duplicate claim ids"):
        claims_frame([row(), row()])
    with pytest.raises(ValueError, match="unknown verdicts"):
        claims_frame([dict(row(), verdict="maybe")])
    assert list(errata_frame([]).columns)[:2] == ["paper", "erratum_id"]
    assert list(reconstructions_frame([]).columns) == ["paper", "key", "value", "reason", "sensitivity"]


def _draw(path):
    fig, ax = new_figure()
    ax.plot([0, 1, 2], [1, 0, 2], label="x")
    ax.legend()
    save_figure(fig, path)
    return hashlib.sha256(path.read_bytes()).hexdigest()


def test_figures_are_deterministic_png_without_date_or_software_stamps(tmp_path):
    first, second = _draw(tmp_path / "a.png"), _draw(tmp_path / "b.png")
    data = (tmp_path / "a.png").read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    assert first == second
    assert b"Software" not in data and b"matplotlib" not in data.lower()
    # written atomically: no temporary file left beside it
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.png", "b.png"]
