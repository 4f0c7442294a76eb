"""The difference page of the figure check, as a person sees it: opened in headless Chromium (issue 26).

A real planted edit (the exact E||P_k|| curve of markov fig3 doubled, in a scratch copy of the
paper's ``figures.py``) and a changed table cell; ``python -m netrepro regression compare`` fails
and writes ``index.html``, served from its folder alone. Every image loads (reference, new and
pixel difference per figure), the data differences and the table's differing cell are shown, and
the page makes no request outside its folder and logs no error.
"""

import shutil
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest

from netrepro.figures.check import figure_jobs, open_baseline, regenerate_figures

from .test_figure_check import EDITS, _edited
from .test_report_browser import browser, console_errors, load, serve  # noqa: F401 (fixture)

ROOT = Path(__file__).resolve().parents[1]
pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("workflow")]


@pytest.fixture(scope="module")
def page(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("regeneration")
    figures = tmp / "figures"
    baseline = open_baseline("git:HEAD", ROOT / "figures")
    for name in baseline.figures():  # the committed figures, as a fresh clone has them
        for suffix in (".png", ".data.json"):
            (figures / f"{name}{suffix}").parent.mkdir(parents=True, exist_ok=True)
            (figures / f"{name}{suffix}").write_bytes(baseline.read(f"{name}{suffix}"))
    paper, old, new, *_ = EDITS["doubled_curve"]
    regenerate_figures(figure_jobs(ROOT), figures, tables_dir=ROOT / "tests" / "reference", names=["markov/fig3"],
                       module={paper: _edited(tmp, paper, old, new)})
    results = tmp / "results"
    shutil.copytree(ROOT / "tests" / "reference", results)
    table = results / "markov" / "iid_line.csv"
    frame = pd.read_csv(table)
    column = frame.select_dtypes("number").columns[0]
    frame.loc[0, column] = frame.loc[0, column] * 1.5 + 1.0
    frame.to_csv(table, index=False)
    html = tmp / "regeneration" / "index.html"
    proc = subprocess.run([sys.executable, "-m", "netrepro", "regression", "compare", "--reference", "tests/reference",
                           "--results", str(results), "--figures", str(figures), "--html", str(html)],
                          cwd=ROOT, capture_output=True, text=True)
    assert proc.returncode == 1, proc.stdout + proc.stderr
    assert "figures/markov/fig3" in proc.stdout and "iid_line.csv" in proc.stdout
    return html, column


def test_the_difference_page_shows_the_drifted_figure_and_table(page, browser):  # noqa: F811
    html, column = page
    with serve(html.parent) as url:
        state = load(browser, url + "index.html")
        assert console_errors(browser) == []
        assert all(r.startswith(url) for r in state["requests"]), state["requests"]
        sections = browser.execute_script("""
            return Array.from(document.querySelectorAll('section')).map(s => ({
                id: s.id, cls: s.className, title: s.querySelector('h2').textContent,
                imgs: Array.from(s.querySelectorAll('img')).map(i => ({alt: i.alt, w: i.naturalWidth})),
                items: Array.from(s.querySelectorAll('li')).map(li => li.textContent),
                cells: Array.from(s.querySelectorAll('td')).map(td => td.textContent)}));""")
    figures = [s for s in sections if s["cls"] == "figure"]
    assert [s["title"] for s in figures] == ["Figure markov/fig3"]
    imgs = figures[0]["imgs"]
    assert len(imgs) == 3 and all(i["w"] > 100 for i in imgs), imgs  # reference, new, difference: all loaded
    assert any("E||P_k|| exact" in item and "xy" in item for item in figures[0]["items"])
    tables = [s for s in sections if s["cls"] == "table"]
    assert len(tables) == 1 and "markov/iid_line.csv" in tables[0]["title"]
    assert column in tables[0]["cells"]  # the differing cell: row, column, new value, reference
