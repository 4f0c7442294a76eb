"""Unit tests of the report generator's pure parts (no workflow run)."""

from pathlib import Path

import pandas as pd

from netrepro.reportgen import config_keys, relocate, rule_for, scorecard, strip_external_scripts


def test_scorecard_counts_and_total():
    claims = {
        "a": pd.DataFrame({"verdict": ["reproduced", "differs", "reproduced"]}),
        "b": pd.DataFrame({"verdict": ["erratum", "reproduced", "pending"]}),
    }
    score = scorecard(claims).set_index("paper")
    assert score.loc["a", ["claims", "reproduced", "differs", "erratum", "other"]].tolist() == [3, 2, 1, 0, 0]
    assert score.loc["b", ["claims", "reproduced", "differs", "erratum", "other"]].tolist() == [3, 1, 0, 1, 1]
    assert score.loc["total", ["claims", "reproduced", "differs", "erratum", "other"]].tolist() == [6, 3, 1, 1, 1]


def test_rule_for_files_and_wildcard_patterns():
    producers = {"files": {"figures/x/fig1.png": "x_fig1"},
                 "patterns": [[r"results/x/shards/part_(?P<i>[^/]+)\.csv$", "x_shard"]]}
    assert rule_for("figures/x/fig1.png", producers) == "x_fig1"
    assert rule_for("results/x/shards/part_3.csv", producers) == "x_shard"
    assert rule_for("results/y.csv", producers) is None
    assert rule_for("figures/x/fig1.png", None) is None


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


def test_source_pages_in_two_processes_equal_the_serial_pages():
    """The report rule (threads: 2) highlights the source pages in two processes: same pages, same order."""
    from netrepro.reportgen import _source_page, _source_pages

    root = Path(__file__).resolve().parents[1]
    rels = ["src/netrepro/io.py", "src/netrepro/errors.py", "src/netrepro/reportgen.py", "src/netrepro/runner.py"]
    serial = [_source_page(rel, (root / rel).read_text()) for rel in rels]
    assert _source_pages(root, rels, workers=2) == serial
    assert _source_pages(root, rels, workers=1) == serial
    assert _source_pages(root, rels[:1], workers=4) == serial[:1]  # never more processes than files
