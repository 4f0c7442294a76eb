"""Processes of a build, read from Linux ``/proc``: which Snakemake runs in a checkout, which Snakemake
started a job, and whether it still runs. Used by the build driver (:mod:`netrepro.pipeline.build`) and by every
job (:mod:`netrepro.pipeline.runner`), so it is kept apart from the driver: an edit of the driver reruns no step.
Where ``/proc`` is not available, nothing is found and nothing is refused.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

__all__ = ["RunningBuild", "running_builds", "snakemake_ancestor", "process_alive", "is_snakemake", "STARTER_VARIABLE",
           "starter_mark", "starter_from_environment"]

# set by the workflow (workflow/rules/common.smk) in the Snakemake process that parses it, inherited by its jobs
STARTER_VARIABLE = "NETREPRO_SNAKEMAKE"

PROC = Path("/proc")


@dataclass(frozen=True)
class RunningBuild:
    """A Snakemake process working in this checkout.

    Attributes
    ----------
    pid : int
        Its process id.
    command : str
        Its command line.
    """

    pid: int
    command: str


def _cmdline(pid: int) -> list[str]:
    try:
        raw = (PROC / str(pid) / "cmdline").read_bytes()
    except OSError:
        return []
    return [part.decode(errors="replace") for part in raw.split(b"\0") if part]


def is_snakemake(argv: list[str]) -> bool:
    """Whether a command line runs Snakemake (not a job that merely names a Snakemake file).

    Parameters
    ----------
    argv : list of str
        The command line, as ``/proc/PID/cmdline`` holds it.

    Returns
    -------
    bool
        True for ``snakemake ...``, ``python .../bin/snakemake ...`` and ``python -m snakemake ...``.
    """
    if not argv:
        return False
    # the console script runs as `python .../bin/snakemake ...` (its shebang), or is exec'd directly
    if any(Path(a).name == "snakemake" for a in argv[:2]):
        return True
    return any(a == "-m" and b == "snakemake" for a, b in zip(argv, argv[1:]))


def _stat_fields(pid: int) -> list[str] | None:
    """Fields of ``/proc/PID/stat`` after the command name (state, ppid, ..., starttime at index 19)."""
    try:
        text = (PROC / str(pid) / "stat").read_text()
    except OSError:
        return None
    return text[text.rfind(")") + 2:].split()


def _parent(pid: int) -> int | None:
    fields = _stat_fields(pid)
    return int(fields[1]) if fields else None


def _ancestors(pid: int) -> set[int]:
    seen = set()
    while pid and pid not in seen:
        seen.add(pid)
        pid = _parent(pid) or 0
    return seen


def running_builds(root: str | Path = ".") -> list[RunningBuild]:
    """The Snakemake processes whose working directory is ``root``, other than this process and its ancestors.

    Parameters
    ----------
    root : str or Path, default "."
        The checkout.

    Returns
    -------
    list of RunningBuild
        Empty where ``/proc`` is not available.
    """
    if not PROC.is_dir():
        return []
    root = Path(root).resolve()
    mine = _ancestors(os.getpid())
    found = []
    for entry in PROC.iterdir():
        if not entry.name.isdigit() or int(entry.name) in mine:
            continue
        argv = _cmdline(int(entry.name))
        if not is_snakemake(argv):
            continue
        try:
            cwd = Path(os.readlink(entry / "cwd")).resolve()
        except OSError:  # ended meanwhile, or not ours to read
            continue
        if cwd == root and (_stat_fields(int(entry.name)) or ["Z"])[0] != "Z":
            found.append(RunningBuild(int(entry.name), " ".join(argv)))
    return sorted(found, key=lambda b: b.pid)


def snakemake_ancestor(pid: int | None = None) -> tuple[int, str] | None:
    """The nearest ancestor of ``pid`` (default: this process) that runs Snakemake, as ``(pid, start time)``.

    Parameters
    ----------
    pid : int, optional
        The process to start from.

    Returns
    -------
    tuple of (int, str) or None
        None when no ancestor runs Snakemake (a step run by hand) or ``/proc`` is not available.
    """
    pid = _parent(pid or os.getpid())
    while pid and pid > 1:
        if is_snakemake(_cmdline(pid)):
            fields = _stat_fields(pid)
            return (pid, fields[19]) if fields else None
        pid = _parent(pid)
    return None


def process_alive(process: tuple[int, str]) -> bool:
    """Whether the process ``(pid, start time)`` still runs (the same process: a reused pid has another start).

    Parameters
    ----------
    process : tuple of (int, str)
        As :func:`snakemake_ancestor` returns it.

    Returns
    -------
    bool
    """
    fields = _stat_fields(process[0])
    return bool(fields) and fields[19] == process[1] and fields[0] != "Z"


def starter_mark(pid: int | None = None) -> str:
    """``host:pid:start time`` of a process (default: this one), for :data:`STARTER_VARIABLE`.

    Parameters
    ----------
    pid : int, optional
        The process; default this one.

    Returns
    -------
    str
        Empty where ``/proc`` is not available.
    """
    import socket

    pid = pid or os.getpid()
    fields = _stat_fields(pid)
    return f"{socket.gethostname()}:{pid}:{fields[19]}" if fields else ""


def starter_from_environment(environ=None) -> tuple[int, str] | None:
    """The Snakemake process that started this job, from :data:`STARTER_VARIABLE`, on this host only.

    Read from the environment rather than the process tree: a Snakemake killed before the job's
    interpreter started leaves no ancestor to find. A mark of another host (a cluster job that
    inherited the login node's environment before its own Snakemake set it) is ignored.

    Parameters
    ----------
    environ : mapping, optional
        Default ``os.environ``.

    Returns
    -------
    tuple of (int, str) or None
        ``(pid, start time)``, as :func:`process_alive` takes it.
    """
    import socket

    mark = (os.environ if environ is None else environ).get(STARTER_VARIABLE, "")
    parts = mark.rsplit(":", 2)
    if len(parts) != 3 or not parts[1].isdigit() or parts[0] != socket.gethostname():
        return None
    return int(parts[1]), parts[2]
