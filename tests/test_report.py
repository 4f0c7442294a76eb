"""Unit tests of the report generator's pure parts (no workflow run)."""

import random
import re
from pathlib import Path

import pandas as pd

from netrepro.report.markup import relocate, strip_external_scripts
from netrepro.report.panel import config_keys, rule_name
from netrepro.report.sections import table_view
from netrepro.judging.summary import scorecard


def test_scorecard_counts_and_total():
    claims = {
        "a": pd.DataFrame({"verdict": ["reproduced", "differs", "reproduced"]}),
        "b": pd.DataFrame({"verdict": ["erratum", "reproduced", "pending"]}),
    }
    score = scorecard(claims).set_index("paper")
    assert score.loc["a", ["claims", "reproduced", "differs", "erratum", "other"]].tolist() == [3, 2, 1, 0, 0]
    assert score.loc["b", ["claims", "reproduced", "differs", "erratum", "other"]].tolist() == [3, 1, 0, 1, 1]
    assert score.loc["total", ["claims", "reproduced", "differs", "erratum", "other"]].tolist() == [6, 3, 1, 1, 1]


def test_rule_name_is_the_one_the_sidecar_records():
    assert rule_name({"rule": "x_shard", "output": "results/x/shards/part_3.csv"}) == "x_shard"
    assert rule_name({"output": "results/y.csv"}) == "?"
    assert rule_name({"rule": None}) == "?"


def test_config_keys_names_the_configuration_entry():
    section = {"scalar": {"a": 1.5, "seed": 7, "n": 10}, "two": {"a": 1.5, "sigma": [0.2]}}
    keys = {k: (v, c) for k, v, c in config_keys({"a": 1.5, "seed": 7, "n": 10, "which": "stable"}, section, "p")}
    assert keys["p.scalar.seed"] == (7, True)
    assert keys["p.scalar.a"] == (1.5, True)  # ambiguous alone; the step's other keys come from `scalar`
    assert keys["which"] == ("stable", False)  # a constant fixed in the rule


def test_strip_external_scripts_leaves_no_network_request():
    page = ('<html><head><script src="https://cdn.example/x.js"></script>'
            '<link rel="stylesheet" href="https://cdn.example/s.css"></head><body>'
            '<script type="module">const m = await import("https://cdn.example/m.mjs");</script>'
            "<script>var keep = 1;</script></body></html>")
    out = strip_external_scripts(page)
    assert "https://" not in out
    assert "var keep = 1" in out
    assert 'rel="icon" href="data:,"' in out


def test_relocate_makes_paths_relative_and_shortens_interpreters(tmp_path):
    root = tmp_path.resolve()
    text = (f"cd {root} && {root}/.venv/bin/python3 -m netrepro 'x=/usr/bin/python3.11' "
            f"<b>/opt/conda/bin/python</b> a/bin/python ~/bin/python {root}/results/a.csv")
    assert relocate(text, root) == ("cd . && .venv/bin/python3 -m netrepro 'x=python3.11' <b>python</b> "
                                    "a/bin/python ~/bin/python results/a.csv")


def test_relocate_leaves_long_words_without_interpreter_alone(tmp_path):
    # an inline image: one long word full of '/' (the path pattern used to backtrack over it)
    blob = "data:image/png;base64," + "iVBOR/w0K+GgoA/" * 20000
    text = f"<img src=\"{blob}\"> ran /usr/bin/python3"
    assert relocate(text, tmp_path) == f"<img src=\"{blob}\"> ran python3"


def _relocate_word_by_word(text, root):
    """The reference: every whitespace/quote/bracket-delimited word holding /bin/python shortened."""
    text = text.replace(f"{root}/", "").replace(str(root), ".")
    interpreter = re.compile(r"(?<![\w.~-])/[^\s'\"<>]*/bin/(python[0-9.]*)")
    return re.sub(r"[^\s'\"<>]+", lambda w: interpreter.sub(r"\1", w.group(0)), text)


def test_relocate_equals_the_word_by_word_rewrite_on_random_text(tmp_path):
    # relocate visits only the words around each "/bin/python"; its word bounds must be the same
    root = tmp_path.resolve()
    pieces = ["/bin/python", "/bin/python3.11", "/usr", "/x/", "a", " ", "\n", "\t", "'", '"', "<", ">", ".", "~",
              "-", "\u00a0", "\u2003", str(root), f"{root}/", "/", "python", "A" * 300]
    rng = random.Random(20261127)
    for _ in range(3000):
        text = "".join(rng.choice(pieces) for _ in range(rng.randint(0, 60)))
        assert relocate(text, root) == _relocate_word_by_word(text, root), repr(text)


def test_source_pages_in_two_processes_equal_the_serial_pages():
    """The report rule (threads: 2) highlights the source pages in two processes: same pages, same order."""
    from netrepro.report.site import source_page, source_pages

    root = Path(__file__).resolve().parents[1]
    rels = ["src/netrepro/pipeline/io.py", "src/netrepro/errors.py", "src/netrepro/report/site.py", "src/netrepro/pipeline/runner.py"]
    serial = [source_page(rel, (root / rel).read_text()) for rel in rels]
    assert source_pages(root, rels, workers=2) == serial
    assert source_pages(root, rels, workers=1) == serial
    assert source_pages(root, rels[:1], workers=4) == serial[:1]  # never more processes than files
    assert 'id="L-1" class="line"' in serial[0] and serial[0].count('class="line"') == len(
        (root / rels[0]).read_text().splitlines())


def test_findings_table_labels_known_results_and_shows_every_column():
    frame = pd.DataFrame({"paper": ["p", "p"], "finding_id": ["F1", "F2"], "verdict": ["holds", "conditional"],
                          "condition": ["", "sigma2 <= 3"], "known": [True, False]})
    view = table_view(frame, "findings")
    assert view["columns"] == ["finding_id", "verdict", "condition", "known"]
    assert view["known"] == [True, False]
    from netrepro.report.markup import render

    page = render("table.html", table=view, table_id="t")
    assert page.count("known result") == 1 and "sigma2 &lt;= 3" in page
    old = table_view(frame.drop(columns=["known"]), "findings")  # a findings table without the new columns
    assert old["known"] == [] and "known result" not in render("table.html", table=old, table_id="t")


def test_reconstruction_value_of_an_integer_setting_shows_as_an_integer():
    frame = pd.DataFrame({"paper": ["m"] * 3, "key": ["paths.seed", "scalar.Ep0", "note"],
                          "value": ["20150101.0", "10.0", "[C; CA]"]})
    config = {"paths": {"seed": 20150101}, "scalar": {"Ep0": 10.0}}
    rows = table_view(frame, "reconstructions", config)["rows"]
    assert [r[1] for r in rows] == ["20150101", "10.0", "[C; CA]"]  # a float setting keeps its form


def test_blank_and_num_treat_missing_numbers_as_empty():
    import numpy as np

    from netrepro.report.markup import blank, num

    for missing in (None, float("nan"), np.float64("nan")):
        assert blank(missing) == "" and str(num(missing)) == ""
    assert blank(0.0) == 0.0 and blank("x") == "x"
    assert str(num(3.0)) == "3.0" and str(num(True)) == "True" and str(num("n/a")) == "n/a"
    assert str(num(0.123456789)) == '<span title="0.123456789">0.1234568</span>'
    assert str(num(float("inf"))) == "inf" and str(num(-np.inf)) == "-inf"  # raised OverflowError before


def test_notebook_driver_and_relocate_do_not_import_pandas():
    """The notebook jobs and `relocate` (the last, serial step of `make report`) never read a table:
    pandas (~0.3 s of start-up per process) is imported only where one is read."""
    import subprocess
    import sys

    code = "import sys, netrepro.report.cli; print('pandas' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "False"


def test_source_pages_made_ahead_are_linked_not_remade(tmp_path, monkeypatch):
    """report_sources writes the pages; the report links a page it finds and the checkout's file otherwise."""
    from netrepro.report.site import Site, source_page, source_pages_step

    monkeypatch.chdir(tmp_path)
    (tmp_path / "pkg").mkdir()
    (tmp_path / "pkg/a.py").write_text("x = 1\n")
    (tmp_path / "pkg/b.py").write_text("def f():\n    return 2\n")
    (tmp_path / "pkg/c.py").write_text("y = 3\n")
    pages = tmp_path / "files/source"
    source_pages_step({}, {"sources": ["pkg/b.py", "pkg/a.py", "pkg/a.py"]}, {"pages": pages})
    assert sorted(p.relative_to(pages).as_posix() for p in pages.rglob("*.html")) == ["pkg/a.py.html", "pkg/b.py.html"]
    assert (pages / "pkg/a.py.html").read_text() == source_page("pkg/a.py", "x = 1\n")

    (pages / "pkg/a.py.html").write_text("MADE AHEAD")
    site = Site(tmp_path, tmp_path / "files", pages_made=True)
    assert site.source_link("pkg/a.py", 3) == "files/source/pkg/a.py.html#L-3"
    assert site.source_link("pkg/c.py") == "../pkg/c.py"  # no page made: the checkout's file
    site.write()
    assert (pages / "pkg/a.py.html").read_text() == "MADE AHEAD"  # not remade
    assert not (pages / "pkg/c.py.html").exists()
    assert (tmp_path / "files/data").is_dir() and (tmp_path / "files/workflow").is_dir()

    fresh = Site(tmp_path, tmp_path / "other")  # without report_sources: the linked pages are made here
    fresh.source_link("pkg/c.py")
    fresh.write()
    assert (tmp_path / "other/source/pkg/c.py.html").read_text() == source_page("pkg/c.py", "y = 3\n")


def test_a_notebook_page_is_titled_by_its_paper_and_shows_its_parameters_once():
    import nbformat.v4 as nbf

    from netrepro.report.notebooks import _cells, page_notebook

    nb = nbf.new_notebook(cells=_cells("markov"))
    injected = nbf.new_code_cell('# Parameters\nslug = "markov"\nroot = "."')
    injected.metadata["tags"] = ["injected-parameters"]
    nb.cells.insert(1, injected)
    page_notebook(nb, "markov", title="A title")
    assert nb.metadata["title"] == "markov: A title \u2014 notebook"
    params = [c for c in nb.cells if 'root = "."' in c.source]
    assert params == [injected]  # the values it ran with, once
    plain = nbf.new_notebook(cells=_cells("markov"))  # not run by papermill: its parameters cell stays
    assert len(page_notebook(plain, "markov", title="t").cells) == len(_cells("markov"))
