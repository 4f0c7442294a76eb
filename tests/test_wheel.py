"""A self-contained package (issue 39): the wheel holds every file the package reads, and works alone.

The slow test builds the wheel from a scratch copy of the repository, installs it into a folder
outside the repository and imports it from there, in a Python that sees the locked dependencies
but neither this checkout's ``src/`` nor the editable install's path hook; every paper's data,
the schemas and the report's templates load from the installed wheel.
"""

import json
import os
import shutil
import subprocess
import sys
import sysconfig
import textwrap
import zipfile
from pathlib import Path

import pytest
import yaml

from netrepro import locations
from netrepro.pipeline.registry import paper_slugs

from .conftest import _ignore

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "src" / "netrepro"


def _package_data_files() -> list[str]:
    """Every non-Python file of the package's source tree (following the schemas link), wheel-relative."""
    files = []
    for directory, dirs, names in os.walk(PACKAGE, followlinks=True):
        dirs[:] = [d for d in dirs if d != "__pycache__"]
        for name in names:
            if not name.endswith((".py", ".pyc")):
                files.append((Path(directory) / name).relative_to(PACKAGE.parent).as_posix())
    return sorted(files)


# ----------------------------------------------------------------------------- fast: the checkout's side
def test_no_module_finds_its_files_by_counting_parent_directories():
    offenders = [f"{path.relative_to(ROOT)}:{number}" for path in sorted((ROOT / "src").rglob("*.py"))
                 for number, line in enumerate(path.read_text().splitlines(), 1) if "parents[2]" in line]
    assert not offenders, f"use netrepro.locations (package data or the checkout), not parents[2]: {offenders}"


def test_the_package_schemas_are_the_workflow_schemas_in_a_checkout():
    # one copy of the schemas: the workflow reads workflow/schemas, the package its link to them
    link = PACKAGE / "schemas"
    assert link.is_symlink() and os.readlink(link) == "../../workflow/schemas"
    assert locations.SCHEMA_DIR.resolve() == (ROOT / "workflow" / "schemas").resolve()
    assert (locations.PAPER_SCHEMA_DIR / "claims.schema.yaml").is_file()
    assert locations.PAPERS_DIR == PACKAGE / "papers"
    assert locations.checkout_root() == ROOT
    assert locations.checkout_file("config", "config.yaml") == ROOT / "config" / "config.yaml"
    assert (PACKAGE / "py.typed").is_file()


def test_a_clone_without_symbolic_links_reads_the_workflow_schemas(tmp_path, monkeypatch):
    package = tmp_path / "site-packages" / "netrepro"
    package.mkdir(parents=True)
    (package / "schemas").write_text("../../workflow/schemas")  # what git writes where links are off
    monkeypatch.setattr(locations, "package_root", lambda: package)
    monkeypatch.chdir(ROOT / "workflow")
    assert locations._schema_dir() == ROOT / "workflow" / "schemas"
    monkeypatch.chdir(tmp_path)
    assert locations._schema_dir() == package / "schemas"  # nothing better: loading names the missing file


def test_a_checkout_is_known_by_its_top_level_files(tmp_path):
    assert locations.is_checkout(ROOT) and not locations.is_checkout(tmp_path)
    for marker in ("pyproject.toml", "Snakefile", "workflow/rules"):
        (tmp_path / marker).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / marker).mkdir() if marker.startswith("workflow") else (tmp_path / marker).write_text("")
    assert locations.is_checkout(tmp_path)


# ----------------------------------------------------------------------------- slow: the wheel alone
CHECK = textwrap.dedent("""
    import json, sys
    from pathlib import Path

    import yaml

    import netrepro
    from netrepro.pipeline import config, figurespec, registry
    from netrepro import locations
    from netrepro.judging import paperdata, regression
    from netrepro.report import markup
    from netrepro.scaffold.skeleton import TEMPLATES

    out = {"file": netrepro.__file__, "sys_path": sys.path, "checkout": str(locations.checkout_root()),
           "schema_dir": str(locations.SCHEMA_DIR), "platform_rules": regression.load_platform_rules(), "papers": {}}
    for slug in registry.paper_slugs():
        data = paperdata.load_paper_data(slug)
        out["papers"][slug] = {"dir": str(paperdata.paper_dir(slug)), "claims": len(data.claims),
                               "findings": len(data.findings), "figures": len(figurespec.load_figure_specs(slug))}
    top, schemas = config.load_schemas()
    out["schemas"] = sorted(str(uri) for uri in schemas)
    config.validate_config(yaml.safe_load(Path(sys.argv[1]).read_text()))
    out["stylesheet"] = len(markup.stylesheet())
    out["templates"] = (TEMPLATES / "schema.yaml.tmpl").is_file()
    print(json.dumps(out))
""")


@pytest.fixture(scope="module")
def wheel(tmp_path_factory):
    """The wheel built (pip, the locked setuptools, no network) from a scratch copy of the repository.

    The copy keeps ``src/netrepro/schemas`` a link, as in a clone: the build copies what it points to.
    """
    base = tmp_path_factory.mktemp("wheel")
    source = base / "repo"
    shutil.copytree(ROOT, source, ignore=_ignore, symlinks=True)
    assert (source / "src/netrepro/schemas").is_symlink()
    dist = base / "dist"
    proc = subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation", "--no-index",
                           "--quiet", "-w", str(dist), str(source)], capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stdout[-4000:] + proc.stderr[-4000:]
    (built,) = dist.glob("netrepro-*.whl")
    return built


@pytest.mark.slow
def test_the_wheel_holds_every_data_file_of_the_package(wheel):
    names = set(zipfile.ZipFile(wheel).namelist())
    missing = [f for f in _package_data_files() if f not in names]
    assert not missing, f"package data missing from the wheel (pyproject.toml [tool.setuptools.package-data]): {missing}"
    for slug in paper_slugs():
        for name in ("claims.yaml", "findings.yaml", "findings.lock", "errata.yaml", "reconstructions.yaml"):
            assert f"netrepro/papers/{slug}/{name}" in names
        assert f"netrepro/schemas/{slug}.schema.yaml" in names
    for schema in ("config", "paper/claims", "paper/errata", "paper/findings", "paper/reconstructions"):
        assert f"netrepro/schemas/{schema}.schema.yaml" in names
    assert {"netrepro/py.typed", "netrepro/papers.yaml", "netrepro/report/templates/report.css"} <= names
    # the schemas are files in the wheel, not a link back into a checkout
    info = zipfile.ZipFile(wheel).getinfo("netrepro/schemas/config.schema.yaml")
    assert info.file_size == (ROOT / "workflow/schemas/config.schema.yaml").stat().st_size


@pytest.mark.slow
def test_the_installed_wheel_loads_every_paper_without_the_checkout(wheel, tmp_path):
    target, elsewhere = tmp_path / "installed", tmp_path / "elsewhere"
    elsewhere.mkdir()
    proc = subprocess.run([sys.executable, "-m", "pip", "install", "--no-deps", "--no-index", "--quiet",
                           "--target", str(target), str(wheel)], capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stdout[-4000:] + proc.stderr[-4000:]
    # -S: no site-packages, so no .pth file (the editable install's path to a checkout's src/); the
    # dependencies come from this interpreter's site-packages, after the installed wheel
    site_packages = sysconfig.get_paths()["purelib"]
    env = {k: v for k, v in os.environ.items() if not k.startswith(("PYTHON", "NETREPRO"))}
    env.update(PYTHONPATH=os.pathsep.join([str(target), site_packages]), PYTHONNOUSERSITE="1",
               MPLBACKEND="Agg", PYTHONDONTWRITEBYTECODE="1")
    proc = subprocess.run([sys.executable, "-S", "-c", CHECK, str(ROOT / "config" / "config.yaml")],
                          cwd=elsewhere, env=env, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stdout[-4000:] + proc.stderr[-4000:]
    out = json.loads(proc.stdout.strip().splitlines()[-1])

    assert Path(out["file"]).resolve().is_relative_to(target.resolve()), out["file"]
    # the dependencies' site-packages may lie in the checkout (CI's .venv/ does); the checkout's own code may not
    assert not [p for p in out["sys_path"] if p and Path(p).resolve().is_relative_to(ROOT)
                and Path(p).resolve() != Path(site_packages).resolve()], out["sys_path"]
    assert not [p for p in out["sys_path"] if p and Path(p).resolve().is_relative_to(ROOT / "src")], out["sys_path"]
    assert out["checkout"] == "None" and out["platform_rules"] == {}
    assert Path(out["schema_dir"]).resolve().is_relative_to(target.resolve())
    assert sorted(out["papers"]) == sorted(paper_slugs())
    for slug, paper in out["papers"].items():
        assert Path(paper["dir"]).resolve().is_relative_to(target.resolve()), paper
        assert paper["claims"] > 0 and paper["findings"] > 0 and paper["figures"] > 0, (slug, paper)
    assert {f"{slug}.schema.yaml" for slug in paper_slugs()} | {"config.schema.yaml"} <= set(out["schemas"])
    assert out["stylesheet"] > 0 and out["templates"]
    # the check ran on the real configuration
    assert set(yaml.safe_load((ROOT / "config" / "config.yaml").read_text())["papers"]) <= set(out["papers"])
    # the console script: installed beside the package, and the same command as python -m netrepro
    assert (target / "bin" / "netrepro").is_file()
    proc = subprocess.run([sys.executable, "-S", "-m", "netrepro", "--help"], cwd=elsewhere, env=env,
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0 and "check-paper" in proc.stdout and "regression" in proc.stdout, proc.stderr


@pytest.mark.slow
def test_the_wheel_declares_the_netrepro_console_script(wheel):
    archive = zipfile.ZipFile(wheel)
    (entry_points,) = [n for n in archive.namelist() if n.endswith(".dist-info/entry_points.txt")]
    text = archive.read(entry_points).decode()
    assert "[console_scripts]" in text and "netrepro = netrepro.cli.main:console" in text, text
