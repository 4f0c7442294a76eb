"""Figure captions (workflow/report/<slug>/<id>.rst) are valid reStructuredText, one per listed figure."""

import io
from pathlib import Path

import docutils.core
import pytest

from netrepro.figurespec import load_figure_specs
from netrepro.registry import load_registry

PAPERS = load_registry()

ROOT = Path(__file__).resolve().parents[1]
CAPTIONS = sorted((ROOT / "workflow" / "report").glob("*/*.rst"))


@pytest.mark.parametrize("path", CAPTIONS, ids=lambda p: f"{p.parent.name}/{p.name}")
def test_caption_parses_without_warnings(path):
    # `snakemake --report` renders captions as RST: |x| is a substitution, *x* emphasis
    warnings = io.StringIO()
    docutils.core.publish_string(path.read_text(), writer="null",
                                 settings_overrides={"warning_stream": warnings, "report_level": 2})
    assert warnings.getvalue() == "", warnings.getvalue()


@pytest.mark.parametrize("slug", sorted(PAPERS))
def test_every_listed_figure_has_a_caption(slug):
    for spec in load_figure_specs(slug):
        assert (ROOT / "workflow" / "report" / slug / f"{spec.figure_id}.rst").is_file(), spec.rule


@pytest.mark.parametrize("slug", sorted(PAPERS))
def test_every_figure_says_which_layout_choices_are_the_papers(slug):
    """Issue 15: each figure states which layout choices come from the paper and which are ours."""
    for spec in load_figure_specs(slug):
        assert spec.layout.get("from_paper", "").strip() and spec.layout.get("ours", "").strip(), spec.rule


def test_a_malformed_layout_is_rejected(tmp_path):
    from netrepro.errors import ConfigError

    folder = tmp_path / "papers" / "x"
    folder.mkdir(parents=True)
    (folder / "figures.yaml").write_text("fig1:\n  plot: f\n  layout: {paper: axes}\n")
    with pytest.raises(ConfigError, match="figure 'fig1': field 'layout'"):
        load_figure_specs("x", src=tmp_path)
