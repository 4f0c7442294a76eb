"""A checkout that moves (issue 40 item 1): commands name the interpreter relative to the checkout, the
environment's editable install follows its checkout, a job refuses a package of another checkout, and a
moved built copy reruns nothing."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from netrepro.pipeline import runner
from netrepro.pipeline.venv_paths import editable_pth_files, interpreter, relocate

from .conftest import run_snakemake

ROOT = Path(__file__).resolve().parents[1]


def test_the_interpreter_is_named_relative_to_the_checkout_only_when_inside_it(tmp_path):
    (tmp_path / ".venv/bin").mkdir(parents=True)
    assert interpreter(tmp_path, str(tmp_path / ".venv/bin/python")) == ".venv/bin/python"
    assert interpreter(tmp_path / ".venv", "/usr/bin/python3") == "/usr/bin/python3"
    assert interpreter(tmp_path, "/opt/my python/bin/python") == "'/opt/my python/bin/python'"  # quoted for the shell


def _fake_venv(root: Path, line: str) -> Path:
    site = root / ".venv/lib/python3.11/site-packages"
    site.mkdir(parents=True)
    (site / "__editable__.netrepro-0.1.0.pth").write_text(line + "\n")
    (root / "src/netrepro").mkdir(parents=True)
    return root / ".venv"


def test_a_copied_environment_is_pointed_at_its_own_checkout(tmp_path):
    original, copy = tmp_path / "original", tmp_path / "copy"
    _fake_venv(original, str(original / "src"))
    shutil.copytree(original, copy)
    changed = relocate(copy / ".venv", copy / "src")
    assert len(changed) == 1 and str(original / "src") in changed[0] and str((copy / "src").resolve()) in changed[0]
    (pth,) = editable_pth_files(copy / ".venv")
    line = pth.read_text().strip()
    assert not os.path.isabs(line) and (pth.parent / line).resolve() == (copy / "src").resolve()
    assert relocate(copy / ".venv", copy / "src") == []  # nothing more to do, and silent
    # the relative line moves with the checkout: a second move needs no rewrite
    moved = tmp_path / "moved"
    shutil.move(copy, moved)
    (pth,) = editable_pth_files(moved / ".venv")
    assert (pth.parent / pth.read_text().strip()).resolve() == (moved / "src").resolve()
    assert relocate(moved / ".venv", moved / "src") == []


def test_the_absolute_line_of_this_checkout_is_made_relative_without_a_message(tmp_path):
    _fake_venv(tmp_path, str(tmp_path / "src"))
    assert relocate(tmp_path / ".venv", tmp_path / "src") == []
    (pth,) = editable_pth_files(tmp_path / ".venv")
    assert pth.read_text().strip() == "../../../../src"


def test_the_site_module_reads_a_relative_pth_line_from_its_own_directory(tmp_path):
    # the mechanism the relocation relies on, checked with the interpreter's own site module
    site_dir = tmp_path / "venv/lib/site-packages"
    site_dir.mkdir(parents=True)
    (tmp_path / "src/pkg_probe_x").mkdir(parents=True)
    (tmp_path / "src/pkg_probe_x/__init__.py").write_text("")
    (site_dir / "probe.pth").write_text("../../../src\n")
    code = f"import site, sys; site.addsitedir({str(site_dir)!r}); import pkg_probe_x; print(pkg_probe_x.__file__)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.strip()
    assert Path(out).resolve() == (tmp_path / "src/pkg_probe_x/__init__.py").resolve()


def test_a_job_refuses_the_package_of_another_checkout(tmp_path):
    (tmp_path / "src/netrepro").mkdir(parents=True)
    with pytest.raises(ImportError, match="not from its own checkout's"):
        runner._own_package(tmp_path)
    assert runner._own_package(ROOT) == "src/netrepro"  # relative: no path of the build machine in provenance
    assert runner._own_package(tmp_path / "elsewhere") == str((ROOT / "src/netrepro").resolve())  # no own package


@pytest.mark.slow
@pytest.mark.xdist_group("workflow")
def test_a_moved_built_checkout_reruns_nothing(built_repo, tmp_path):
    moved = tmp_path / "somewhere" / "else"
    shutil.copytree(built_repo, moved, symlinks=True)
    proc = run_snakemake(moved, "-n", "report")
    assert "Nothing to be done" in proc.stdout + proc.stderr, (proc.stdout + proc.stderr)[-3000:]
