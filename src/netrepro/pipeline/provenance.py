"""Provenance sidecars: ``<output>.meta.json`` beside every table and figure.

A sidecar records what made a file: rule, source function, parameters and
their hash, git commit and dirty flag, package versions, seeds, input
checksums, the output's own checksum and the wall time. :func:`verify_output`
uses the recorded checksum to detect truncated or edited results, and
:func:`verify_tree` checks every result under a directory (``python -m
netrepro verify``).
"""

from __future__ import annotations

import datetime as _dt
import hashlib
import json
import logging
import platform
import shlex
import subprocess
import sys
from dataclasses import dataclass, field
from importlib import metadata
from pathlib import Path

from .io import sha256_file, write_json
from ..errors import CorruptOutputError, UnfinishedOutputError

__all__ = [
    "params_hash",
    "git_state",
    "step_environment",
    "package_versions",
    "find_seeds",
    "job_command",
    "sidecar_path",
    "write_sidecar",
    "read_sidecar",
    "verify_output",
    "verify_tree",
    "Verdict",
    "CorruptOutputError",
    "UnfinishedOutputError",
    "PARTIAL_MARK",
    "write_unfinished_sidecar",
]

# Marker in the names of the temporary files of :func:`netrepro.pipeline.io.atomic_path`.
PARTIAL_MARK = ".part"

_LOG = logging.getLogger("netrepro.pipeline.provenance")
_COMMAND_LOGGED = False

TRACKED_PACKAGES = (
    "numpy", "scipy", "cvxpy", "clarabel", "numba", "matplotlib", "pandas", "snakemake", "papermill",
)




def params_hash(params) -> str:
    """SHA-256 (first 16 hex digits) of the canonical JSON of ``params``.

    Parameters
    ----------
    params : object
        A JSON-like value (keys sorted; other objects as their ``str``).

    Returns
    -------
    str
        16 hexadecimal digits.
    """
    blob = json.dumps(params, sort_keys=True, separators=(",", ":"), default=str)
    return hashlib.sha256(blob.encode()).hexdigest()[:16]


# Tracked files that the workflow itself writes (the figures are committed and rebuilt). A build
# that rewrites them has not changed the sources: they do not make the working tree "dirty",
# else every job after the first figure of a build, and every figure panel of the report, said
# "dirty" while the report's run identity (taken after the figures were committed) said "clean".
BUILD_OUTPUTS = ("figures",)


def git_state(repo: str | Path = ".", exclude=BUILD_OUTPUTS) -> dict:
    """Commit hash and dirty flag of the repository holding ``repo`` (None outside git).

    Parameters
    ----------
    repo : str or Path, default "."
        A directory of the checkout.
    exclude : tuple of str, default :data:`BUILD_OUTPUTS`
        Paths (relative to the top of the checkout) whose changes do not count as dirty.

    Returns
    -------
    dict
        ``{"commit": sha or None, "dirty": bool or None}``: dirty when a tracked file outside
        ``exclude`` differs from the commit.
    """
    def _git(*args):
        return subprocess.run(["git", *args], cwd=repo, capture_output=True, text=True, timeout=20)

    try:
        head = _git("rev-parse", "HEAD")
        if head.returncode != 0:
            return {"commit": None, "dirty": None}
        status = _git("status", "--porcelain", "--untracked-files=no", "--", ":/",
                      *(f":(top,exclude){path}" for path in exclude))
        return {"commit": head.stdout.strip(), "dirty": bool(status.stdout.strip())}
    except (OSError, subprocess.TimeoutExpired):
        return {"commit": None, "dirty": None}


def package_versions(names=TRACKED_PACKAGES) -> dict:
    """Installed versions of the packages that shape the numbers.

    Parameters
    ----------
    names : tuple of str, default :data:`TRACKED_PACKAGES`
        Distribution names.

    Returns
    -------
    dict
        ``{"python": version, name: version or None}``.
    """
    versions = {"python": platform.python_version()}
    for name in names:
        try:
            versions[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            versions[name] = None
    return versions


def job_command() -> str:
    """The command line of this process, as the shell would run it again (``sys.orig_argv``).

    Snakemake's console shows one line per job; the full command of a step is kept here, in the
    sidecar of each output and once in the job's log (see :func:`write_sidecar`).

    Returns
    -------
    str
        The shell-quoted command, with paths under the checkout relative.
    """
    argv = getattr(sys, "orig_argv", None) or [sys.executable, *sys.argv]
    return shlex.join(_relative(arg) for arg in argv)


def _relative(arg: str) -> str:
    """A path under the working directory (the checkout) as a relative path: sidecars name no
    absolute path of the machine (the interpreter is ``.venv/bin/python`` after ``make``)."""
    if not arg.startswith("/"):
        return arg
    try:
        return str(Path(arg).relative_to(Path.cwd()))
    except ValueError:
        return arg


def find_seeds(params, prefix="") -> dict:
    """All entries of a nested parameter dict whose key contains 'seed'.

    Parameters
    ----------
    params : dict
        A step's parameters.
    prefix : str, default ""
        Dotted path of ``params`` inside the outer dict (recursion).

    Returns
    -------
    dict
        ``{dotted key: seed}``.
    """
    seeds = {}
    if isinstance(params, dict):
        for key, value in params.items():
            path = f"{prefix}.{key}" if prefix else str(key)
            if "seed" in str(key).lower() and not isinstance(value, dict):
                seeds[path] = value
            else:
                seeds.update(find_seeds(value, path))
    return seeds


def sidecar_path(output: str | Path) -> Path:
    """The provenance sidecar of a file.

    Parameters
    ----------
    output : str or Path
        A table or figure.

    Returns
    -------
    Path
        ``<output>.meta.json``.
    """
    output = Path(output)
    return output.with_name(output.name + ".meta.json")


@dataclass(frozen=True)
class StepRecord:
    """What the runner knows about one executed step."""

    rule: str
    function: str
    source_file: str
    source_line: int
    params: dict
    inputs: dict
    wall_time_s: float
    extra: dict
    # inputs' checksums, git state and package versions: the same for every output of the step,
    # so the runner computes them once (:func:`step_environment`); empty: computed per sidecar
    environment: dict = field(default_factory=dict)


def step_environment(inputs: dict) -> dict:
    """The part of a sidecar shared by all outputs of a step: the checksum of every input file,
    the git state of the checkout and the versions of the packages that shape the numbers.

    Parameters
    ----------
    inputs : dict
        ``{name: path}`` of the step's inputs (flattened); paths that are not files are left out.

    Returns
    -------
    dict
        ``{"inputs": {name: {"path", "sha256"}}, "git": ..., "packages": ...}``.
    """
    return {
        "inputs": {
            name: {"path": str(path), "sha256": sha256_file(path)}
            for name, path in inputs.items()
            if Path(path).is_file()
        },
        "git": git_state(),
        "packages": package_versions(),
    }


def write_sidecar(output: str | Path, record: StepRecord) -> Path:
    """Write the provenance sidecar of ``output`` (which must exist).

    Parameters
    ----------
    output : str or Path
        The file the step wrote.
    record : StepRecord
        What the runner knows about the step.

    Returns
    -------
    Path
        The sidecar.
    """
    global _COMMAND_LOGGED
    output = Path(output)
    command = job_command()
    if not _COMMAND_LOGGED:  # once per job, into its log (the runner's stderr)
        _LOG.info("command: %s", command)
        _COMMAND_LOGGED = True
    meta = {
        "output": str(output),
        "output_sha256": sha256_file(output),
        "rule": record.rule,
        "function": record.function,
        "source_file": record.source_file,
        "source_line": record.source_line,
        "params": record.params,
        "params_hash": params_hash(record.params),
        "seeds": find_seeds(record.params),
        **(record.environment or step_environment(record.inputs)),
        "machine": {"platform": platform.platform(), "processor": platform.machine()},
        "wall_time_s": round(record.wall_time_s, 3),
        "finished": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
        "command": command,
        **({"extra": record.extra} if record.extra else {}),
    }
    return write_json(meta, sidecar_path(output))


def read_sidecar(output: str | Path) -> dict:
    """The provenance sidecar of a file, parsed.

    Parameters
    ----------
    output : str or Path
        A table or figure.

    Returns
    -------
    dict
        The sidecar.
    """
    return json.loads(sidecar_path(output).read_text())


def write_unfinished_sidecar(output: str | Path, rule: str) -> Path:
    """Mark ``output`` as being written by ``rule``'s job: a sidecar without a checksum.

    The runner writes it before the step runs and replaces it (atomically) with the full sidecar
    once the output is complete, so a job killed at any moment leaves its output either absent,
    marked unfinished, or complete with its checksum; never a result that looks written outside
    the pipeline, and never one that verifies.

    Parameters
    ----------
    output : str or Path
        The file about to be written.
    rule : str
        The job's rule.

    Returns
    -------
    Path
        The sidecar.
    """
    meta = {"output": str(output), "unfinished": True, "rule": rule,
            "started": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds")}
    return write_json(meta, sidecar_path(output))


def verify_output(output: str | Path) -> dict:
    """Check ``output`` against its sidecar checksum; return the sidecar.

    Parameters
    ----------
    output : str or Path
        A table or figure.

    Returns
    -------
    dict
        The sidecar.

    Raises
    ------
    CorruptOutputError
        If the file or its sidecar is missing, the sidecar is unreadable, or
        the checksum differs (truncated or edited file);
        :class:`~netrepro.errors.UnfinishedOutputError` if the sidecar marks
        the file as still being written (:func:`write_unfinished_sidecar`).
    """
    output = Path(output)
    side = sidecar_path(output)
    if not output.is_file():
        raise CorruptOutputError(f"{output}: missing, but its sidecar {side.name} exists; rebuild it with snakemake")
    if not side.is_file():
        raise CorruptOutputError(f"{output}: no provenance sidecar {side.name}; `make repair` rebuilds it")
    try:
        meta = json.loads(side.read_text())
        if isinstance(meta, dict) and meta.get("unfinished"):
            raise UnfinishedOutputError(
                f"{output}: its job (rule {meta.get('rule', '?')}) has not finished: the sidecar {side.name} "
                "marks it unfinished (the job is running, or was interrupted). Rerun snakemake to rebuild it.")
        recorded = meta["output_sha256"]
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise CorruptOutputError(
            f"{output}: its provenance sidecar {side.name} is unreadable ({type(exc).__name__}: {exc}); "
            f"`make repair` rebuilds both.") from None
    actual = sha256_file(output)
    if actual != recorded:
        raise CorruptOutputError(
            f"{output}: checksum {actual[:12]}… differs from the sidecar's "
            f"{str(recorded)[:12]}…; the file was truncated or edited. "
            f"`make repair` rebuilds it and what depends on it."
        )
    return meta


@dataclass(frozen=True)
class Verdict:
    """The state of one file checked by :func:`verify_tree`.

    Attributes
    ----------
    path : Path
        The file.
    status : str
        ``"ok"``, ``"corrupt"``, ``"missing"``, ``"no-sidecar"``, ``"partial"`` or ``"unfinished"``.
    message : str
        What is wrong, for a reader.
    """

    path: Path
    status: str  # "ok", "corrupt", "missing", "no-sidecar", "partial", "unfinished"
    message: str

    @property
    def ok(self) -> bool:
        """Whether the file verified."""
        return self.status == "ok"


def _is_partial(path: Path) -> bool:
    return path.name.startswith(".") and PARTIAL_MARK in path.name


DIFFERENCE_PAGE_DIR = "regeneration"  # results/regeneration/: written by `regression compare`


def verify_tree(paths, inputs_only: bool = False) -> list[Verdict]:
    """Check files and directory trees against their provenance sidecars.

    Parameters
    ----------
    paths : sequence of path
        Files or directories (searched recursively).
    inputs_only : bool
        Check only files that have a sidecar (the mode of a rule's inputs,
        which include source files and notebooks); otherwise a result file
        without a sidecar is reported as ``no-sidecar``.

    Returns
    -------
    list of :class:`Verdict`
        One per result file, sidecar without its file (``missing``),
        leftover temporary file of an interrupted write (``partial``), or
        output of a job that is running or was interrupted (``unfinished``).
    """
    verdicts = []
    files = []
    for root in map(Path, paths):
        if root.is_dir():
            # the regeneration check's difference page (results/regeneration/) is a report, not an output
            files.extend(sorted(p for p in root.rglob("*") if p.is_file()
                                and DIFFERENCE_PAGE_DIR not in p.relative_to(root).parts[:1]))
        else:
            files.append(root)
    seen = set()
    for path in files:
        if path in seen:
            continue
        seen.add(path)
        if _is_partial(path):
            verdicts.append(Verdict(path, "partial", f"{path}: leftover temporary file of an interrupted write "
                                    "(never read by the pipeline; safe to delete)"))
            continue
        if path.name.endswith(".meta.json"):
            output = path.with_name(path.name[: -len(".meta.json")])
            if not output.exists():
                verdicts.append(Verdict(output, "missing", f"{output}: missing, but its sidecar {path.name} exists "
                                        "(an interrupted job, or a deleted table); nothing can read it, and "
                                        "snakemake rebuilds it"))
            continue
        if not sidecar_path(path).is_file():
            if inputs_only:
                continue
            if not path.exists():
                verdicts.append(Verdict(path, "missing", f"{path}: does not exist"))
            else:
                verdicts.append(Verdict(path, "no-sidecar", f"{path}: no provenance sidecar "
                                        f"{sidecar_path(path).name}; it was not written by the pipeline (or its "
                                        "writer was interrupted): delete it and rerun snakemake"))
            continue
        try:
            verify_output(path)
        except UnfinishedOutputError as exc:
            verdicts.append(Verdict(path, "unfinished", f"{exc} No step reads it."))
        except CorruptOutputError as exc:
            verdicts.append(Verdict(path, "corrupt", str(exc)))
        else:
            verdicts.append(Verdict(path, "ok", f"{path}: ok"))
    return verdicts
