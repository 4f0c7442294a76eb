"""The one entry point that Snakemake rules call, and the checker of cached results.

``python -m netrepro run --rule NAME --func module:function --params JSON --io JSON``
runs one step; ``python -m netrepro verify [PATH ...]`` checks every result
under ``results/`` and ``figures/`` (or the given files and directories)
against the checksums in their provenance sidecars.

The step function has the signature ``fn(params, inputs, outputs)`` where
``inputs`` and ``outputs`` map names to :class:`pathlib.Path`. It returns a
dict: values that are :class:`pandas.DataFrame` under an output's name are
written (atomically) by the runner; a ``"provenance"`` entry adds to the
sidecar. Files the function writes itself (figures) must be written through
:func:`netrepro.pipeline.io.atomic_path`. Every output then gets a provenance sidecar.
Inputs that carry a sidecar are checked against their checksum first.

Warnings the step raises are logged once per distinct warning, with a
count, and listed in the sidecar (no flood of repeated warnings in the logs).

Before the step runs, temporary files left by an interrupted earlier attempt
are removed and each output's sidecar is replaced by a mark that the output is
unfinished; the full sidecar replaces the mark once the output is complete. A
sidecar with a checksum therefore always describes the file written after the
job was (re)started, and a job killed at any moment leaves its outputs absent,
marked unfinished (never read by a step) or complete: never one that verifies
without being complete, and never one that looks written outside the pipeline.
"""

from __future__ import annotations

import argparse
import contextlib
import importlib
import inspect
import json
import logging
import os
import sys
import time
import warnings
from pathlib import Path

from .processes import process_alive, snakemake_ancestor, starter_from_environment
from ..errors import LMIError, OrphanedJobError
from .io import write_table
from .provenance import (PARTIAL_MARK, CorruptOutputError, StepRecord, sidecar_path, step_environment, verify_output,
                         verify_tree, write_sidecar, write_unfinished_sidecar)

__all__ = ["resolve", "run_step", "verify_main", "main"]

log = logging.getLogger("netrepro")


def resolve(spec: str):
    """Import ``package.module:function`` and return the function.

    Parameters
    ----------
    spec : str
        ``package.module:function``.

    Returns
    -------
    callable
        The attribute ``function`` of the imported module.

    Raises
    ------
    ValueError
        If ``spec`` has no ``:`` or the module has no such attribute.
    """
    if ":" not in spec:
        raise ValueError(f"--func must look like 'package.module:function', got {spec!r}")
    module_name, func_name = spec.split(":", 1)
    module = importlib.import_module(module_name)
    try:
        return getattr(module, func_name)
    except AttributeError as exc:
        raise ValueError(f"{module_name} has no function {func_name!r}") from exc


def _as_paths(value):
    return [Path(v) for v in value] if isinstance(value, (list, tuple)) else Path(value)


def _flatten(named: dict) -> dict:
    """``{name: path or [paths]}`` -> ``{name or name[i]: path}``."""
    flat = {}
    for name, value in named.items():
        if isinstance(value, list):
            flat.update({f"{name}[{i}]": v for i, v in enumerate(value)})
        else:
            flat[name] = value
    return flat


def _check_inputs(inputs: dict) -> None:
    """Verify every input that has a sidecar; inputs under ``results/`` must have one.

    Everything under ``results/`` is written by a step, with its sidecar; a
    result without one was written by something else, or by a step that was
    killed between writing it and writing its sidecar: never use it silently.
    """
    for path in _flatten(inputs).values():
        path = Path(path)
        if sidecar_path(path).is_file():
            verify_output(path)
        elif path.parts[:1] == ("results",) and path.is_file():
            raise CorruptOutputError(
                f"{path}: no provenance sidecar {sidecar_path(path).name}, so its checksum cannot be verified "
                "(written outside the pipeline, or by an interrupted job). `make repair` rebuilds it.")


def _described(outputs: dict) -> dict:
    """The outputs that get a sidecar: all but sidecar files a rule names as outputs of its own."""
    return {name: path for name, path in outputs.items() if not path.name.endswith(".meta.json")}


def _clear_stale(outputs: dict, rule: str) -> None:
    """Mark ``outputs`` unfinished (replacing old sidecars) and remove temporary files of interrupted writes."""
    for path in _described(outputs).values():
        path.parent.mkdir(parents=True, exist_ok=True)
        for part in path.parent.glob(f".{path.name}.*{PARTIAL_MARK}*"):
            with contextlib.suppress(FileNotFoundError):
                part.unlink()
        write_unfinished_sidecar(path, rule)


def _nonfinite(frame: pd.DataFrame) -> dict:
    """``{column: {"nan": n, "inf": m}}`` for numeric columns holding NaN or inf (a flag in the sidecar)."""
    import numpy as np
    import pandas as pd

    counts = {}
    for col in frame.columns:
        values = frame[col]
        if not pd.api.types.is_numeric_dtype(values) or pd.api.types.is_bool_dtype(values):
            continue
        arr = values.to_numpy(dtype=float)
        n_nan, n_inf = int(np.isnan(arr).sum()), int(np.isinf(arr).sum())
        if n_nan or n_inf:
            counts[str(col)] = {"nan": n_nan, "inf": n_inf}
    return counts


def _solver_counts() -> tuple[dict, dict]:
    """The solver statuses and certified verdicts counted so far in this process (:mod:`netrepro.engines.cvx`).

    Read only when a step imported the engine: a step without LMIs does not import cvxpy for this.
    """
    module = sys.modules.get("netrepro.engines.cvx")
    return (module.solver_statuses(), module.certified_decisions()) if module is not None else ({}, {})


def _counted_since(before: dict, after: dict) -> dict:
    """The counts of ``after`` less those of ``before`` (a step's own, when one process runs several)."""
    return {k: v - before.get(k, 0) for k, v in after.items() if v - before.get(k, 0)}


def _refuse_undecided_step(rule: str, decisions: dict, statuses: dict) -> None:
    """Stop a step whose certificates decided nothing, naming the solver's statuses (before any table is written).

    Its tables would hold no decision, and a later step would stop on a symptom (a design missing
    from a table) instead of the cause.
    """
    if decisions and set(decisions) == {"undecided"}:
        from ..engines.cvx import FAULT_MAX_ITER, SOLVER

        named = ", ".join(f"{k}: {v}" for k, v in statuses.items()) or "none recorded"
        raise LMIError(f"rule {rule}: every one of its {decisions['undecided']} certified decisions is undecided "
                       f"(solver {SOLVER}, statuses {named}): the solver did not converge, so this step decides "
                       f"nothing; check the solver's installation and settings ({FAULT_MAX_ITER} caps it when set)")


def _summarize_warnings(caught) -> list[dict]:
    """Warnings raised by a step, one entry per distinct (category, message, place) with its count.

    A recursion that warns at every step logs one line, not thousands.
    """
    counts = {}
    for w in caught:
        key = (w.category.__name__, str(w.message), f"{Path(w.filename).name}:{w.lineno}")
        counts[key] = counts.get(key, 0) + 1
    return [{"category": c, "message": m, "where": where, "count": n} for (c, m, where), n in counts.items()]


def run_step(rule: str, func_spec: str, params: dict, inputs: dict, outputs: dict) -> None:
    """Run one step and write its outputs and their provenance sidecars.

    The step is called as ``func(params, inputs, outputs)``; the tables it returns (output
    name -> DataFrame, plus an optional ``provenance`` dict) are written to their outputs,
    then every file output gets its sidecar. Inputs are verified against their sidecars first.
    On failure no sidecar is left behind and the exception propagates.

    Parameters
    ----------
    rule : str
        Name of the Snakemake rule (recorded in the sidecars).
    func_spec : str
        The step, ``package.module:function`` (see :func:`resolve`).
    params : dict
        The step's parameters (JSON-compatible).
    inputs : dict
        Input name -> path, or a list of paths.
    outputs : dict
        Output name -> path.

    Raises
    ------
    CorruptOutputError
        If an input does not match its sidecar, or an input under ``results/`` has none
        (:class:`~netrepro.errors.UnfinishedOutputError`, a subclass, if its sidecar marks it unfinished).
    KeyError
        If the step returns a table that is not one of the rule's outputs.
    TypeError
        If a returned table is not a DataFrame.
    FileNotFoundError
        If an output was not written.
    """
    func = resolve(func_spec)
    inputs = {k: _as_paths(v) for k, v in inputs.items()}
    outputs = {k: Path(v) for k, v in outputs.items()}
    starter = starter_from_environment() or snakemake_ancestor()
    _refuse_orphaned(rule, starter)  # a Snakemake killed while this job's interpreter started
    _check_inputs(inputs)
    _clear_stale(outputs, rule)
    package = _own_package()
    try:
        _run_and_record(rule, func, func_spec, params, inputs, outputs, starter, package)
    except BaseException as exc:
        # a failed step leaves no sidecar (Snakemake deletes its outputs); a killed one cannot get
        # here, and its outputs stay marked unfinished. An orphaned job removes what it wrote itself:
        # no Snakemake is left to do it
        for path in _described(outputs).values():
            for leftover in (sidecar_path(path), path) if isinstance(exc, OrphanedJobError) else (sidecar_path(path),):
                with contextlib.suppress(FileNotFoundError, IsADirectoryError):
                    leftover.unlink()
        raise


def _own_package(cwd: Path | None = None) -> str:
    """The resolved directory of the imported netrepro package, refused when the job's checkout has its own.

    A ``.venv/`` moved or copied from another checkout imported that checkout's code, while the
    provenance recorded this checkout's files (issue 40); ``make`` repoints it (src/netrepro/pipeline/venv_paths.py).
    """
    imported = Path(__file__).resolve().parents[1]
    here = (cwd or Path.cwd()).resolve()
    own = here / "src" / "netrepro"
    if own.is_dir() and own != imported:
        raise ImportError(f"this job imported netrepro from {imported}, not from its own checkout's {own}: the "
                          "environment belongs to another checkout. Run `make` (it repoints .venv/ at this "
                          "checkout), or set PYTHONPATH to this checkout's src/")
    # relative inside the checkout: provenance (and the report) must not name the build machine's folders
    return imported.relative_to(here).as_posix() if imported.is_relative_to(here) else str(imported)


def _refuse_orphaned(rule: str, starter) -> None:
    """Stop before writing when the Snakemake that started this job is gone (``kill -9``, a lost login node).

    Nobody would delete what the job writes then, and a later build could take it for its own work.
    """
    if starter is not None and not process_alive(starter):
        raise OrphanedJobError(f"rule {rule}: the Snakemake process that started this job (pid {starter[0]}) is "
                               "gone, so the job stops without writing its outputs; rerun the build to resume")


def _run_and_record(rule, func, func_spec, params, inputs, outputs, starter=None, package=None) -> None:
    """Run the step, write the tables it returns, then each output's sidecar (replacing its unfinished mark)."""
    import pandas as pd  # here, not at import: `verify` (before every notebook) needs no pandas

    statuses_before, decisions_before = _solver_counts()
    start = time.perf_counter()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = func(params, inputs, outputs) or {}
    elapsed = time.perf_counter() - start
    statuses_after, decisions_after = _solver_counts()
    statuses = _counted_since(statuses_before, statuses_after)
    _refuse_undecided_step(rule, _counted_since(decisions_before, decisions_after), statuses)
    extra = dict(result.pop("provenance", {}) if isinstance(result, dict) else {})
    summary = _summarize_warnings(caught)
    for item in summary:
        log.warning("rule %s: %s: %s (at %s, %d times)", rule, item["category"], item["message"], item["where"],
                    item["count"])
    if summary:
        extra.setdefault("warnings", summary)

    if statuses:
        extra.setdefault("solver_statuses", statuses)
        unsure = {k: v for k, v in statuses.items() if k != "optimal"}
        if unsure:
            log.warning("rule %s: %d of %d solves did not end optimal (%s): their decisions rest on the "
                        "certificates, and points the certificates cannot decide are undecided", rule,
                        sum(unsure.values()), sum(statuses.values()),
                        ", ".join(f"{k}: {v}" for k, v in unsure.items()))
    _refuse_orphaned(rule, starter)
    nonfinite = {}
    for name, value in result.items():
        if name not in outputs:
            raise KeyError(f"{func_spec} returned table {name!r}, which is not an output of rule {rule}")
        if not isinstance(value, pd.DataFrame):
            raise TypeError(f"{func_spec} returned {type(value).__name__} for {name!r}; expected a DataFrame")
        counts = _nonfinite(value)
        if counts:
            nonfinite[name] = counts
            log.info("rule %s: table %r holds non-finite values %s", rule, name, counts)
        write_table(value, outputs[name])
    if nonfinite:
        extra.setdefault("nonfinite", nonfinite)
    source_file = inspect.getsourcefile(func) or "?"
    try:
        source_file = str(Path(source_file).resolve().relative_to(Path.cwd().resolve()))
    except ValueError:
        pass
    flat_inputs = {k: str(v) for k, v in _flatten(inputs).items()}
    record = StepRecord(
        rule=rule,
        function=func_spec,
        source_file=source_file,
        source_line=inspect.getsourcelines(func)[1],
        params=params,
        inputs=flat_inputs,
        wall_time_s=elapsed,
        extra=extra,
        # where the code came from: a job refuses another checkout's package (_own_package), and says which it ran
        environment={**step_environment(flat_inputs), **({"package_path": package} if package else {})},
    )
    for name, path in outputs.items():
        if not path.exists():
            raise FileNotFoundError(f"{func_spec} did not write output {name!r} ({path})")
    for path in _described(outputs).values():
        if path.is_file():
            write_sidecar(path, record)
        else:  # a directory output has no sidecar of its own
            with contextlib.suppress(FileNotFoundError):
                sidecar_path(path).unlink()
    log.info("rule %s: %s done in %.2f s", rule, func_spec, elapsed)


def verify_main(paths, inputs_only=False, remove_corrupt=False, quiet=False, stream=None) -> int:
    """``python -m netrepro verify``: report every result that does not match its sidecar.

    Reported but harmless: leftover temporary files, sidecars whose table is missing
    (Snakemake deletes the outputs of a job it interrupts, which can happen after the runner
    wrote both; nothing can read a missing table, and the next ``snakemake`` run rebuilds it),
    and outputs marked unfinished (their job is running or was killed; no step reads them and
    Snakemake reruns the job), except with ``inputs_only``: a rule must not start on an
    unfinished input.

    Parameters
    ----------
    paths : list of str or Path
        Files or directories to check; empty: ``results/`` and ``figures/`` (those that exist).
    inputs_only : bool, default False
        Check only the given files that have a sidecar (a rule's inputs); unfinished is then an error.
    remove_corrupt : bool, default False
        Delete corrupt files, files without a sidecar and unfinished outputs, with their sidecars
        (and leftover temporary files and orphaned sidecars), so the next ``snakemake`` run
        rebuilds them.
    quiet : bool, default False
        Print only problems and the summary.
    stream : file-like, optional
        Where to print (default ``sys.stdout``).

    Returns
    -------
    int
        0 when every checked file verifies (always 0 with ``remove_corrupt``), 1 otherwise.
    """
    stream = stream or sys.stdout
    if not paths:
        paths = [p for p in ("results", "figures") if Path(p).is_dir()]
    verdicts = verify_tree(paths, inputs_only=inputs_only)
    counts = {}
    for v in verdicts:
        counts[v.status] = counts.get(v.status, 0) + 1
        if not v.ok:
            print(f"{v.status.upper()}: {v.message}", file=stream)
        elif not quiet:
            print(f"OK: {v.path}", file=stream)
        if remove_corrupt and v.status in ("corrupt", "no-sidecar", "partial", "missing", "unfinished"):
            for path in (v.path, sidecar_path(v.path)):
                with contextlib.suppress(FileNotFoundError):
                    path.unlink()
            if v.status not in ("partial", "missing"):
                print(f"REMOVED: {v.path} (rerun snakemake to rebuild it)", file=stream)
    # harmless leftovers of interrupted jobs, unless a rule is about to read them (--inputs)
    harmless = ("ok", "partial", "missing") if inputs_only else ("ok", "partial", "missing", "unfinished")
    bad = sum(n for status, n in counts.items() if status not in harmless)
    summary = ", ".join(f"{n} {status}" for status, n in sorted(counts.items())) or "nothing to check"
    print(f"verify: {len(verdicts)} files checked in {', '.join(map(str, paths))}: {summary}", file=stream)
    if bad and not remove_corrupt:
        print("verify: FAILED. Repair with `make repair` (removes what fails and rebuilds it, with what "
              "depends on it).", file=stream)
    return 1 if bad and not remove_corrupt else 0


def exit_process(code: int) -> None:
    """End a command-line process with ``code`` once its work is written, skipping the interpreter's teardown.

    By the time a command returns, its outputs, sidecars and HTML are closed (written atomically)
    and its worker processes joined; what the normal exit still does is free every module object
    (numba/LLVM, cvxpy, pandas, matplotlib): 0.1-0.4 s of CPU per job, about 30 core-seconds of a
    cold build's ~100 jobs. Log handlers and the standard streams are flushed first. Only the
    ``__main__`` blocks call this; in-process callers (tests) get ``main``'s return value.
    """
    logging.shutdown()
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(Exception):
            stream.flush()
    os._exit(code)


def main(argv=None) -> int:
    """``python -m netrepro {run,verify}``: run one pipeline step, or verify results against their sidecars.

    Parameters
    ----------
    argv : list of str, optional
        Command-line arguments (default ``sys.argv[1:]``).

    Returns
    -------
    int
        Exit status: 0, or 1 when the step failed (logged) or verification found a problem.
    """
    parser = argparse.ArgumentParser(prog="python -m netrepro", description=__doc__.splitlines()[0],
                                     epilog="Also: new-paper, check-paper, diff (netrepro.cli.main; each with --help).")
    sub = parser.add_subparsers(dest="command", required=True)
    run = sub.add_parser("run", help="run one pipeline step")
    run.add_argument("--rule", default="?", help="name of the Snakemake rule (its params.rule), for the sidecars")
    run.add_argument("--func", required=True, help="package.module:function")
    run.add_argument("--params", default="{}", help="JSON object of parameters")
    run.add_argument("--io", default="{}", help='JSON {"inputs": {...}, "outputs": {...}}')
    run.add_argument("--log", default=None)
    ver = sub.add_parser("verify", help="check results against the checksums of their provenance sidecars")
    ver.add_argument("paths", nargs="*", help="files or directories (default: results/ and figures/)")
    ver.add_argument("--inputs", action="store_true",
                     help="check only the given files that have a sidecar (a rule's inputs)")
    ver.add_argument("--remove-corrupt", action="store_true",
                     help="delete corrupt or unverifiable results so that snakemake rebuilds them")
    ver.add_argument("-q", "--quiet", action="store_true", help="print only problems and the summary")
    args = parser.parse_args(argv)
    if args.command == "verify":
        return verify_main(args.paths, inputs_only=args.inputs, remove_corrupt=args.remove_corrupt,
                           quiet=args.quiet)

    handlers = [logging.StreamHandler(sys.stderr)]
    if args.log:
        Path(args.log).parent.mkdir(parents=True, exist_ok=True)
        handlers.append(logging.FileHandler(args.log, mode="w"))
    logging.basicConfig(level=logging.INFO, handlers=handlers, format="%(asctime)s %(name)s %(levelname)s %(message)s")
    logging.captureWarnings(True)
    io = json.loads(args.io)
    try:
        run_step(args.rule, args.func, json.loads(args.params), io.get("inputs", {}), io.get("outputs", {}))
    except Exception:
        log.exception("rule %s failed", args.rule)
        return 1
    return 0
