"""Shared fixtures. Tests never write into the repository's results/ or figures/."""

import os
import re

# one BLAS thread per test worker: pytest -n 2 on 2 cores, small matrices (threads only add contention)
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import subprocess  # noqa: E402

import numpy as np  # noqa: E402
import pytest
from hypothesis import settings

# `make test-fast` (pytest --hypothesis-profile fast): fewer examples per property test
settings.register_profile("fast", max_examples=10)


@pytest.fixture
def rng():
    return np.random.default_rng(12345)


# ----------------------------------------------------------------------------- the fast lane stays fast
def runs_snakemake(args) -> bool:
    """Whether a subprocess command line (list or shell string) starts Snakemake."""
    import shlex

    words = [str(args)] if isinstance(args, (str, bytes, os.PathLike)) else [str(w) for w in args]
    if len(words) == 1:
        words = shlex.split(words[0])
    return (bool(words) and os.path.basename(words[0]) == "snakemake") or any(
        a == "-m" and b == "snakemake" for a, b in zip(words, words[1:]))


@pytest.fixture(autouse=True)
def _snakemake_only_in_slow_tests(request, monkeypatch):
    """A test that starts Snakemake must be marked ``slow`` (``make test-fast`` leaves those out)."""
    if request.node.get_closest_marker("slow"):
        return
    real = subprocess.Popen

    class Guarded(real):
        def __init__(self, args, *rest, **kwargs):
            if runs_snakemake(args):
                raise AssertionError(f"{request.node.nodeid} starts Snakemake but is not marked slow")
            super().__init__(args, *rest, **kwargs)

    monkeypatch.setattr(subprocess, "Popen", Guarded)


# ----------------------------------------------------------------------------- one built workflow per session
import shutil  # noqa: E402
import sys  # noqa: E402
from pathlib import Path  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
TOP_LEVEL_IGNORE = {".venv", ".git", "results", "logs", ".snakemake", "report", "figures", ".pytest_cache",
                    ".hypothesis", "build", "dist"}


def _ignore(directory, names):
    """Leave out the repository's build products (only at the top level: workflow/report/ is source)."""
    if Path(directory).resolve() == ROOT:
        return [n for n in names if n in TOP_LEVEL_IGNORE]
    return [n for n in names if n == "__pycache__" or n.endswith(".egg-info")]


def copy_repo(target: Path) -> Path:
    """A scratch copy of the repository's sources (no results, figures or report)."""
    shutil.copytree(ROOT, target, ignore=_ignore)
    (target / "report").mkdir()
    (target / "figures").mkdir()
    return target


def run_snakemake(workdir, *args, config="config/test.yaml", check=True, timeout=900, env=None):
    """Snakemake in ``workdir``, running that copy's own ``src/`` (not the live checkout); ``env`` adds variables."""
    cmd = [sys.executable, "-m", "snakemake", "--configfile", config, *args]
    env = dict(os.environ, **(env or {}), PYTHONPATH=str(Path(workdir) / "src"))
    proc = subprocess.run(cmd, cwd=workdir, capture_output=True, text=True, timeout=timeout, env=env)
    if check and proc.returncode != 0:
        raise AssertionError(f"{' '.join(cmd)} failed:\n{proc.stdout[-4000:]}\n{proc.stderr[-4000:]}"
                             f"{failed_job_logs(workdir, proc.stdout + proc.stderr)}")
    return proc


def failed_job_logs(workdir, console: str, tail: int = 3000) -> str:
    """The end of every log file snakemake names for a failed job, so a CI failure shows its cause."""
    names = []
    for line in console.splitlines():
        match = re.match(r"\s*log: (.+?) \(check log file", line)
        names.extend(n for n in (match.group(1).split(", ") if match else []) if n not in names)
    return "".join(f"\n--- end of {name} ---\n{(Path(workdir) / name).read_text(errors='replace')[-tail:]}"
                   for name in names if (Path(workdir) / name).is_file())


@pytest.fixture(scope="session")
def built_repo(tmp_path_factory):
    """A scratch repository with the whole report built on the small test configuration.

    Shared by the workflow and report tests (both in xdist group "workflow", so one worker
    builds it once). ``NETREPRO_BUILT_REPORT=/path`` reuses an already built copy.
    """
    if os.environ.get("NETREPRO_BUILT_REPORT"):
        return Path(os.environ["NETREPRO_BUILT_REPORT"])
    work = copy_repo(tmp_path_factory.mktemp("wf") / "repo")
    run_snakemake(work, "-j2", "report")
    return work
