"""The one entry point that Snakemake rules call.

``python -m netrepro run --rule RULE --func module:function --params JSON --io JSON``

The step function has the signature ``fn(params, inputs, outputs)`` where
``inputs`` and ``outputs`` map names to :class:`pathlib.Path`. It returns a
dict: values that are :class:`pandas.DataFrame` under an output's name are
written (atomically) by the runner; a ``"provenance"`` entry adds to the
sidecar. Files the function writes itself (figures) must be written through
:func:`netrepro.io.atomic_path`. Every output then gets a provenance sidecar.
Inputs that carry a sidecar are checked against their checksum first.
"""

from __future__ import annotations

import argparse
import importlib
import inspect
import json
import logging
import sys
import time
from pathlib import Path

import pandas as pd

from .io import write_table
from .provenance import StepRecord, sidecar_path, verify_output, write_sidecar

__all__ = ["resolve", "run_step", "main"]

log = logging.getLogger("netrepro")


def resolve(spec: str):
    """Import ``package.module:function`` and return the function."""
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
    for path in _flatten(inputs).values():
        if sidecar_path(path).is_file():
            verify_output(path)


def run_step(rule: str, func_spec: str, params: dict, inputs: dict, outputs: dict) -> None:
    """Run one step and write its outputs and their provenance sidecars."""
    func = resolve(func_spec)
    inputs = {k: _as_paths(v) for k, v in inputs.items()}
    outputs = {k: Path(v) for k, v in outputs.items()}
    _check_inputs(inputs)
    for path in outputs.values():
        path.parent.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    result = func(params, inputs, outputs) or {}
    elapsed = time.perf_counter() - start
    extra = result.pop("provenance", {}) if isinstance(result, dict) else {}
    for name, value in result.items():
        if name not in outputs:
            raise KeyError(f"{func_spec} returned table {name!r}, which is not an output of rule {rule}")
        if not isinstance(value, pd.DataFrame):
            raise TypeError(f"{func_spec} returned {type(value).__name__} for {name!r}; expected a DataFrame")
        write_table(value, outputs[name])
    source_file = inspect.getsourcefile(func) or "?"
    try:
        source_file = str(Path(source_file).resolve().relative_to(Path.cwd().resolve()))
    except ValueError:
        pass
    record = StepRecord(
        rule=rule,
        function=func_spec,
        source_file=source_file,
        source_line=inspect.getsourcelines(func)[1],
        params=params,
        inputs={k: str(v) for k, v in _flatten(inputs).items()},
        wall_time_s=elapsed,
        extra=extra,
    )
    for name, path in outputs.items():
        if not path.exists():
            raise FileNotFoundError(f"{func_spec} did not write output {name!r} ({path})")
        if path.is_file() and not path.name.endswith(".meta.json"):
            write_sidecar(path, record)
    log.info("rule %s: %s done in %.2f s", rule, func_spec, elapsed)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m netrepro", description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    run = sub.add_parser("run", help="run one pipeline step")
    run.add_argument("--rule", required=True)
    run.add_argument("--func", required=True, help="package.module:function")
    run.add_argument("--params", default="{}", help="JSON object of parameters")
    run.add_argument("--io", default="{}", help='JSON {"inputs": {...}, "outputs": {...}}')
    run.add_argument("--log", default=None)
    args = parser.parse_args(argv)

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
