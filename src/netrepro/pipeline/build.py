"""The build driver behind ``make report``, ``make repair`` and ``make unlock`` (issue 38 items 2 and 5).

``python -m netrepro build -- OPTIONS`` runs ``snakemake report OPTIONS`` and tells the truth about how it
ended: an interrupt (Ctrl-C, SIGTERM) reads "interrupted; rerun to resume", not a failed job; a run
stopped at Snakemake's lock says whether another build of this checkout still holds it (then wait) or the
lock is a killed build's leftover (then ``make unlock``). ``repair`` first removes every output that
``verify`` finds corrupt, unfinished or unverifiable and lists every declared output that is missing
(``snakemake --summary``), then builds the report with exactly those files as extra targets: Snakemake
rebuilds a missing file only when a job that needs it runs, so a deleted output that nothing reads (a
figure's data file, a step's second table) would otherwise stay missing. What depends on a rebuilt file
reruns because its input is newer. ``unlock`` refuses while a build of this checkout runs.

A build of this checkout is a running process whose command line runs Snakemake and whose working
directory is the checkout (Linux ``/proc``; elsewhere the check finds none and Snakemake's own lock
decides).
"""

from __future__ import annotations

import argparse
import contextlib
import signal
import subprocess
import sys
from pathlib import Path

from .processes import RunningBuild, running_builds

__all__ = ["damaged_outputs", "missing_outputs", "main", "split_options", "summary_rows"]

INTERRUPTED = 130  # the shell's exit status after SIGINT
# verify's statuses that mean "this output cannot be trusted or is gone" (netrepro.pipeline.provenance.verify_tree)
DAMAGED = ("corrupt", "no-sidecar", "unfinished", "partial", "missing")


def _locks(root: Path) -> list[Path]:
    locks = root / ".snakemake" / "locks"
    return sorted(locks.glob("*.lock")) if locks.is_dir() else []


def _describe(builds: list[RunningBuild]) -> str:
    return "; ".join(f"pid {b.pid}: {b.command[:160]}" for b in builds)


def damaged_outputs(paths=("results", "figures"), stream=None) -> list[Path]:
    """Remove every output that does not verify (with its sidecar); return the outputs to rebuild.

    Parameters
    ----------
    paths : sequence of str or Path
        Directories to verify (those that exist).
    stream : file-like, optional
        Where to say what was removed (default ``sys.stdout``).

    Returns
    -------
    list of Path
        Corrupt, unverifiable and unfinished outputs (now removed), and outputs whose sidecar remains but
        whose file is gone.
    """
    from .provenance import sidecar_path, verify_tree

    stream = stream or sys.stdout
    paths = [p for p in paths if Path(p).is_dir()]
    targets = []
    for verdict in verify_tree(paths) if paths else []:
        if verdict.status not in DAMAGED:
            continue
        for path in (verdict.path, sidecar_path(verdict.path)):
            with contextlib.suppress(FileNotFoundError):
                path.unlink()
        print(f"repair: {verdict.status}: {verdict.path} (removed, to rebuild)", file=stream)
        targets.append(Path(verdict.path))
    return targets


def split_options(argv=None) -> tuple[list[str], list[str]]:
    """A command line split at ``--``: the command's own arguments, then the options handed to Snakemake.

    Parameters
    ----------
    argv : list of str, optional
        The command line without the program name (default ``sys.argv[1:]``).

    Returns
    -------
    tuple of (list of str, list of str)
    """
    argv = list(sys.argv[1:] if argv is None else argv)
    if "--" not in argv:
        return argv, []
    return argv[: argv.index("--")], argv[argv.index("--") + 1:]


def summary_rows(snakemake: list[str], options: list[str]) -> list[list[str]]:
    """``snakemake report --summary``: one row of fields per declared output of the report's jobs.

    Parameters
    ----------
    snakemake : list of str
        The command that starts Snakemake.
    options : list of str
        The build's options (configuration, profile); report options are left out.

    Returns
    -------
    list of list of str
        The rows without the header: output path, date, rule, log files, status, plan.

    Raises
    ------
    RuntimeError
        If Snakemake cannot list the outputs (its message included).
    """
    skip_next = {"--report", "--report-stylesheet"}
    kept, skipping = [], False
    for option in options:
        if skipping:
            skipping = False
            continue
        if option in skip_next:
            skipping = True
            continue
        if option == "--report-after-run":
            continue
        kept.append(option)
    proc = subprocess.run([*snakemake, "report", "--summary", *kept], capture_output=True, text=True)
    if proc.returncode != 0:
        raise RuntimeError(f"`snakemake --summary` failed:\n{proc.stderr[-3000:]}")
    return [line.split("\t") for line in proc.stdout.splitlines()[1:] if line.strip()]


def missing_outputs(snakemake: list[str], options: list[str]) -> list[Path]:
    """The declared outputs of the report's jobs that do not exist (``snakemake report --summary``).

    Parameters
    ----------
    snakemake : list of str
        The command that starts Snakemake.
    options : list of str
        The build's options (configuration, profile); report options are left out.

    Returns
    -------
    list of Path

    Raises
    ------
    RuntimeError
        If Snakemake cannot list the outputs (its message included).
    """
    return [Path(fields[0]) for fields in summary_rows(snakemake, options)
            if len(fields) >= 5 and fields[4].strip() == "missing"]


def _run(command: list[str], make_target: str) -> int:
    """Run Snakemake; on an interrupt wait for it to clean up, then say so (exit 130)."""
    interrupted, started = [], []

    def on_signal(signum, frame):  # noqa: ARG001 - the signal handler's signature
        interrupted.append(signum)
        if signum != signal.SIGINT and started:  # Ctrl-C reached Snakemake through the terminal already
            with contextlib.suppress(ProcessLookupError):
                started[0].send_signal(signal.SIGINT)

    # handlers first: a signal between the start and the handlers would end the driver silently
    # (a child starts with the default handlers whatever ours are)
    previous = {s: signal.signal(s, on_signal) for s in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)}
    try:
        code = INTERRUPTED
        if not interrupted:  # nothing is started after an interrupt
            proc = subprocess.Popen(command)
            started.append(proc)
            code = proc.wait()
    finally:
        for s, handler in previous.items():
            signal.signal(s, handler)
    if interrupted:
        print(f"\n{make_target}: interrupted ({signal.Signals(interrupted[0]).name}); rerun `{make_target}` to "
              "resume: finished steps are kept, the interrupted ones rerun, and no output of theirs is "
              "taken as complete.", file=sys.stderr)
        return INTERRUPTED
    return code


def _explain_failure(root: Path, make_target: str) -> None:
    """After a failed run: if a lock is left, say whose it is."""
    if not _locks(root):
        return
    builds = running_builds(root)
    if builds:
        print(f"{make_target}: another build of this checkout holds Snakemake's lock ({_describe(builds)}); "
              "wait for it to end. Do not unlock while it runs: `make unlock` refuses.", file=sys.stderr)
    else:
        print(f"{make_target}: no build of this checkout is running, so the lock was left by a killed "
              "build: `make unlock`, then rerun.", file=sys.stderr)


def _refuse_if_running(root: Path, make_target: str) -> bool:
    builds = running_builds(root)
    if builds:
        print(f"{make_target}: a build of this checkout is running ({_describe(builds)}); wait for it to end "
              "(or stop it) and rerun. Nothing was changed.", file=sys.stderr)
    return bool(builds)


def main(argv=None) -> int:
    """``python -m netrepro {build,repair,unlock} [-- SNAKEMAKE OPTIONS]``.

    Parameters
    ----------
    argv : list of str, optional
        The command line without the program name (default ``sys.argv[1:]``).

    Returns
    -------
    int
        Snakemake's exit status; 130 after an interrupt; 1 when refused.
    """
    argv, options = split_options(argv)
    parser = argparse.ArgumentParser(prog="python -m netrepro", description=__doc__.splitlines()[0])
    parser.add_argument("command", choices=["build", "repair", "unlock"])
    parser.add_argument("--make-target", default=None, help="what to tell the user to rerun (default: make COMMAND)")
    parser.add_argument("--snakemake", default=None,
                        help="the Snakemake command (default: this interpreter's `-m snakemake`)")
    args = parser.parse_args(argv)
    make_target = args.make_target or f"make {'report' if args.command == 'build' else args.command}"
    snakemake = args.snakemake.split() if args.snakemake else [sys.executable, "-m", "snakemake"]
    root = Path.cwd()
    if args.command == "unlock":
        if _refuse_if_running(root, make_target):
            return 1
        return subprocess.run([*snakemake, "--unlock", *options]).returncode
    if _refuse_if_running(root, make_target):
        return 1
    targets = []
    if args.command == "repair":
        targets = damaged_outputs()
        try:
            missing = missing_outputs(snakemake, options)
        except RuntimeError as exc:
            print(f"{make_target}: {exc}", file=sys.stderr)
            return 1
        for path in missing:
            print(f"repair: missing: {path} (to rebuild)")
        targets = sorted({*map(str, targets), *map(str, missing)})
        print(f"repair: {len(targets)} outputs to rebuild" + (", and what depends on them" if targets else
                                                               "; building the report as `make report` does"))
    code = _run([*snakemake, "report", *targets, *options], make_target)
    if code not in (0, INTERRUPTED):
        _explain_failure(root, make_target)
    return code
