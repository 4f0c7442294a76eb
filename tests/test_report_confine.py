"""Paths the report reads or copies stay inside the checkout (netrepro.report.confine, issue 38)."""

import json
import os
from pathlib import Path

import pytest

from netrepro.report import panel
from netrepro.report.build import _run_sidecars
from netrepro.report.confine import OutsideCheckoutError, confine_sidecar, confined, resolves_outside, sidecar_paths
from netrepro.report.site import Site


@pytest.fixture
def checkout(tmp_path, monkeypatch):
    """A checkout in ``tmp_path/repo`` (the working directory) with one table and its sidecar, and a
    file outside it, ``tmp_path/etc/hostname``."""
    root = tmp_path / "repo"
    (root / "results" / "p").mkdir(parents=True)
    (root / "report").mkdir()
    (root / "results" / "p" / "t.csv").write_text("a\n1\n")
    (tmp_path / "etc").mkdir()
    (tmp_path / "etc" / "hostname").write_text("secret-host\n")
    monkeypatch.chdir(root)
    panel._sidecar.cache_clear()
    yield root
    panel._sidecar.cache_clear()


def write_sidecar(root: Path, table: str, **fields) -> Path:
    side = root / (table + ".meta.json")
    side.write_text(json.dumps({"output": table, "rule": "p_step", "source_file": "src/netrepro/x.py",
                                "inputs": {}, **fields}))
    return side


def files_under(folder: Path) -> set[str]:
    return {p.relative_to(folder).as_posix() for p in folder.rglob("*") if p.is_file()}


@pytest.mark.parametrize(("path", "outside"), [
    ("results/p/t.csv", False), ("./results/../results/p/t.csv", False), ("../etc/hostname", True),
    ("results/../../etc/hostname", True), ("/etc/hostname", True)])
def test_resolves_outside(checkout, path, outside):
    assert resolves_outside(path, checkout) is outside


def test_a_symbolic_link_out_of_the_checkout_is_outside(checkout, tmp_path):
    os.symlink(tmp_path / "etc" / "hostname", checkout / "results" / "p" / "link.csv")
    assert resolves_outside("results/p/link.csv", checkout)


def test_confined_gives_the_path_as_written_inside(checkout):
    assert confined("./results/x/../p/t.csv", checkout, "test") == "results/p/t.csv"
    assert confined(checkout / "results/p/t.csv", checkout, "test") == "results/p/t.csv"


def test_confined_names_where_the_path_came_from(checkout):
    with pytest.raises(OutsideCheckoutError, match=r"the provenance sidecar S \(field 'output'\) names the path "
                                                   r"'\.\./etc/hostname', which resolves to .*etc/hostname, "
                                                   r"outside the checkout"):
        confined("../etc/hostname", checkout, "the provenance sidecar S (field 'output')")


def test_sidecar_paths_lists_output_inputs_and_source():
    meta = {"output": "results/p/t.csv", "source_file": "src/x.py",
            "inputs": {"table": {"path": "results/p/a.csv", "sha256": "0"}, "odd": "not a dict"}}
    assert sidecar_paths(meta) == [("output", "results/p/t.csv"), ("inputs.table.path", "results/p/a.csv"),
                                   ("source_file", "src/x.py")]


def test_a_source_file_of_an_editable_install_elsewhere_is_read_in_its_checkout_form(checkout):
    meta = {"output": "results/p/t.csv", "source_file": "/home/someone/clone/src/netrepro/x.py"}
    confine_sidecar(meta, "S", checkout, source_form=panel.repo_relative)  # src/netrepro/x.py: inside
    confine_sidecar({"output": "results/p/t.csv", "source_file": "?"}, "S", checkout)
    with pytest.raises(OutsideCheckoutError, match="field 'source_file'"):
        confine_sidecar({"source_file": "/usr/lib/python3/site.py"}, "S", checkout, source_form=panel.repo_relative)


@pytest.mark.parametrize("field", ["output", "input", "source_file"])
def test_a_sidecar_naming_a_file_outside_is_refused_and_nothing_is_copied(checkout, tmp_path, field):
    """Issue 38: a `../` path in a provenance sidecar made the report copy /etc/hostname outside the report."""
    hostile = "../etc/hostname"
    fields = {"output": hostile} if field == "output" else \
        {"inputs": {"table": {"path": hostile, "sha256": "0"}}} if field == "input" else {"source_file": hostile}
    side = write_sidecar(checkout, "results/p/t.csv", **fields)
    papers = {"p": {"tables": ["results/p/t.csv"], "figures": []}}
    before = files_under(tmp_path)
    with pytest.raises(OutsideCheckoutError) as refused:
        sidecars = _run_sidecars(papers)
        # (the source file is read by the figure's panel, through the site)
        site = Site(checkout, checkout / "report" / "files")
        site.tables.update(sidecars)
        for meta in sidecars.values():
            site.source_link(meta["source_file"])
        site.write()
    message = str(refused.value)
    assert str(side.relative_to(checkout)) in message and repr(hostile) in message and "outside the checkout" in message
    assert files_under(tmp_path) == before  # nothing copied anywhere, inside the report or out


def test_the_site_refuses_to_copy_from_or_to_outside(checkout, tmp_path):
    site = Site(checkout, checkout / "report" / "files")
    with pytest.raises(OutsideCheckoutError, match="a table linked from the report names the path '../etc/hostname'"):
        site.table_link("../etc/hostname")
    with pytest.raises(OutsideCheckoutError, match="a source file linked from the report"):
        site.source_link(str(tmp_path / "etc" / "hostname"))
    # registered behind the links' back (the crate's copies): refused before the first copy
    site.tables.update({"results/p/t.csv", "../etc/hostname"})
    before = files_under(tmp_path)
    with pytest.raises(OutsideCheckoutError, match="the report's copy data/../etc/hostname"):
        site.write()
    assert files_under(tmp_path) == before
    site.tables, site.raw = set(), {"workflow/../../../../x": "Snakefile"}
    with pytest.raises(OutsideCheckoutError, match="the report's copy of Snakefile"):
        site.write()


def test_a_table_inside_is_copied_with_its_sidecar(checkout):
    write_sidecar(checkout, "results/p/t.csv")
    site = Site(checkout, checkout / "report" / "files")
    assert site.table_link("results/p/t.csv") == "files/data/results/p/t.csv"
    site.write()
    assert files_under(checkout / "report") == {"files/data/results/p/t.csv", "files/data/results/p/t.csv.meta.json"}
