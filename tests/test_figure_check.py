"""The figure check (issue 26): real edits of a plotting function, in a scratch copy, must fail it.

Every figure is drawn in this process from the committed reference tables (``tests/reference``),
which is how the committed figures were drawn: byte-identical PNGs and data sidecars within the
table tolerances. Each planted edit is a one-line change of a copy of a paper's ``figures.py``;
the check must fail naming that figure, and only figures that the edit really changes.
"""

import importlib.util
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from netrepro.figures.check import (RMS_TOLERANCE, compare_figures, figure_jobs, load_figure_rules, open_baseline,
                                  regenerate_figures)
from netrepro.judging.regression import PLATFORM_RULES

ROOT = Path(__file__).resolve().parents[1]
# every test reads the figure jobs from a dry run of the workflow (Snakemake), hence slow
pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("figures")]


@pytest.fixture(scope="module")
def jobs():
    return figure_jobs(ROOT)


@pytest.fixture(scope="module")
def rebuilt(jobs, tmp_path_factory):
    """Every figure drawn from the committed reference tables into a scratch ``figures/``."""
    out = tmp_path_factory.mktemp("rebuild") / "figures"
    regenerate_figures(jobs, out, tables_dir=ROOT / "tests" / "reference")
    return out


def _baseline():
    return open_baseline("git:HEAD", ROOT / "figures")


def _check(figures):
    return compare_figures(_baseline(), figures, rules=load_figure_rules(PLATFORM_RULES))


def test_an_identical_rebuild_passes_and_is_bit_identical_run_to_run(rebuilt, jobs, tmp_path):
    count, diffs = _check(rebuilt)
    assert count == len(jobs) >= 30
    assert [d.problems for d in diffs if d.problems] == []
    # (here, and on the machine that drew the references, every figure is byte-identical: diffs == [])
    # one machine, drawn again: the same bytes (PNG and data sidecar)
    names = ["markov/fig2", "markov/fig3", "hinf/figS3", "gainsched/fig1"]
    regenerate_figures(jobs, tmp_path, tables_dir=ROOT / "tests" / "reference", names=names)
    for name in names:
        for suffix in (".png", ".data.json"):
            assert (tmp_path / f"{name}{suffix}").read_bytes() == (rebuilt / f"{name}{suffix}").read_bytes(), name


def _edited(tmp_path, paper, old, new):
    """A scratch copy of ``netrepro.papers.<paper>.figures`` with ``old`` replaced by ``new`` once."""
    source = (ROOT / "src" / "netrepro" / "papers" / paper / "figures.py").read_text()
    assert source.count(old) == 1, f"the planted edit no longer matches {paper}/figures.py: {old!r}"
    path = tmp_path / f"{paper}_figures_edited.py"
    path.write_text(source.replace(old, new))
    name = f"netrepro.papers.{paper}._figures_edited"
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


def _planted(tmp_path, rebuilt, jobs, paper, old, new, names):
    figures = tmp_path / "figures"
    shutil.copytree(rebuilt, figures)
    module = _edited(tmp_path, paper, old, new)
    regenerate_figures(jobs, figures, tables_dir=ROOT / "tests" / "reference", names=names, module={paper: module})
    count, diffs = _check(figures)
    return {d.name: d for d in diffs if d.problems}


EDITS = {
    # the edit of the issue: twice the exact E||P_k|| curve
    "doubled_curve": ("markov", "ax.plot(sub.k, sub.mean_norm, **style)", "ax.plot(sub.k, 2 * sub.mean_norm, **style)",
                      ["markov/fig3", "markov/fig4", "markov/fig5", "markov/fig6"], "line", "'E||P_k|| exact"),
    "dropped_legend_entry": ("markov", ', ms=7, label="Sinopoli lower bound")', ', ms=7)',
                             ["markov/fig2"], "legend", "Sinopoli lower bound"),
    "axis_scale": ("markov", '    ax.set_yscale("log")\n    ax.set_ylabel("||P_k||")',
                   '    ax.set_yscale("symlog")\n    ax.set_ylabel("||P_k||")',
                   ["markov/fig3", "markov/fig4", "markov/fig5"], "yscale", "'symlog', reference 'log'"),
    # one point of the stability map, 1 % up
    "scatter_point_1pct": ("markov", "ax.scatter(sub.q, sub.p, s=7,",
                           "ax.scatter(sub.q, sub.p * np.where(np.arange(len(sub)) == 0, 1.01, 1.0), s=7,",
                           ["markov/fig2"], "PathCollection", "1 of"),
    # one point of the Monte Carlo 5-95 % band, 1 % up
    "band_point_1pct": ("markov", "ax.fill_between(t.k, t.q05, t.q95,",
                        "ax.fill_between(t.k, t.q05, t.q95 * np.where(np.arange(len(t)) == 5, 1.01, 1.0),",
                        ["markov/fig3", "markov/fig4", "markov/fig5"], "FillBetweenPolyCollection", "1 of"),
}


@pytest.mark.parametrize("edit", sorted(EDITS))
def test_a_planted_edit_fails_naming_the_figure_and_artist(edit, tmp_path, rebuilt, jobs):
    paper, old, new, drawn, artist, detail = EDITS[edit]
    failing = _planted(tmp_path, rebuilt, jobs, paper, old, new, drawn)
    assert failing, f"{edit}: the check passed"
    assert set(failing) <= set(drawn)
    for name, d in failing.items():
        text = "\n".join(d.problems)
        assert f"figures/{name}" in text
        assert artist in text and detail in text, (edit, text)


def test_a_deleted_or_new_figure_fails(tmp_path, rebuilt):
    figures = tmp_path / "figures"
    shutil.copytree(rebuilt, figures)
    (figures / "onebit" / "fig2.png").unlink()
    (figures / "onebit" / "fig2.data.json").unlink()
    shutil.copy(figures / "onebit" / "fig1.png", figures / "onebit" / "fig9.png")
    shutil.copy(figures / "onebit" / "fig1.data.json", figures / "onebit" / "fig9.data.json")
    failing = {d.name: d.problems for d in _check(figures)[1] if d.problems}
    assert set(failing) == {"onebit/fig2", "onebit/fig9"}
    assert "missing" in failing["onebit/fig2"][0] and "no reference" in failing["onebit/fig9"][0]


def test_a_missing_data_sidecar_or_resized_image_fails(tmp_path, rebuilt):
    from PIL import Image

    figures = tmp_path / "figures"
    shutil.copytree(rebuilt, figures)
    (figures / "hinf" / "fig1.data.json").unlink()
    im = Image.open(figures / "intermittent" / "fig1.png")
    im.crop((0, 0, im.width - 1, im.height)).save(figures / "intermittent" / "fig1.png")
    failing = {d.name: "\n".join(d.problems) for d in _check(figures)[1] if d.problems}
    assert set(failing) == {"hinf/fig1", "intermittent/fig1"}
    assert "fig1.data.json: missing" in failing["hinf/fig1"]
    assert "image size" in failing["intermittent/fig1"]


def test_pixels_alone_fail_beyond_the_tolerance(tmp_path, rebuilt):
    """A change the data do not record (a colour drawn over the figure) is caught by the pixels."""
    import numpy as np
    from PIL import Image

    figures = tmp_path / "figures"
    shutil.copytree(rebuilt, figures)
    path = figures / "onebit" / "fig1.png"
    a = np.asarray(Image.open(path).convert("RGB")).copy()
    a[10:30, 10:30] = [255, 0, 0]  # a 20 x 20 red square
    Image.fromarray(a).save(path)
    failing = {d.name: d for d in _check(figures)[1] if d.problems}
    assert list(failing) == ["onebit/fig1"]
    assert failing["onebit/fig1"].rms > RMS_TOLERANCE
    assert "pixels differ" in failing["onebit/fig1"].problems[0]


def test_the_command_fails_and_writes_the_difference_page(tmp_path, rebuilt):
    """``python -m netrepro regression compare`` (CI's command) on a drifted figure: exit 1 and the page."""
    figures = tmp_path / "figures"
    shutil.copytree(rebuilt, figures)
    (figures / "markov" / "fig6.png").unlink()
    page = tmp_path / "regeneration"
    cmd = [sys.executable, "-m", "netrepro", "regression", "compare", "--reference", "tests/reference",
           "--results", "tests/reference", "--figures", str(figures), "--html", str(page / "index.html")]
    proc = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
    assert proc.returncode == 1, proc.stdout + proc.stderr
    assert "figures/markov/fig6.png: missing" in proc.stdout
    text = (page / "index.html").read_text()
    assert "markov/fig6" in text
    # the difference page runs nothing either (issue 38): a strict content security policy
    assert "http-equiv=\"Content-Security-Policy\"" in text and "script-src 'none'" in text
    shutil.copy(rebuilt / "markov" / "fig6.png", figures / "markov" / "fig6.png")
    proc = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
    assert proc.returncode == 0, proc.stdout + proc.stderr
