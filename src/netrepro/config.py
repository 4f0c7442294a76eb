"""Configuration validation, run before any job starts.

The schema ``workflow/schemas/config.schema.yaml`` describes the top level
and refers to one schema per paper (``<slug>.schema.yaml``). Structural checks
(types, ranges, sizes) come from JSON Schema; checks a schema cannot express
(matrix shapes that agree, positive definite covariances) come from the
paper module's ``check_config(section)`` function, if it defines one.
Every error names the key, the value and what was expected.
"""

from __future__ import annotations

import importlib
from pathlib import Path

import jsonschema
import numpy as np
import yaml
from referencing import Registry, Resource

__all__ = ["ConfigError", "SCHEMA_DIR", "load_schemas", "validate_config", "require_matrix", "require_pd"]

SCHEMA_DIR = Path(__file__).resolve().parents[2] / "workflow" / "schemas"


class ConfigError(ValueError):
    """The configuration is invalid; the message names key, value and expectation."""


def load_schemas(schema_dir: Path = SCHEMA_DIR) -> tuple[dict, Registry]:
    """The top-level schema and a registry resolving ``$ref: <file>.schema.yaml``."""
    resources = []
    top = None
    for path in sorted(Path(schema_dir).glob("*.schema.yaml")):
        doc = yaml.safe_load(path.read_text())
        doc.setdefault("$schema", "https://json-schema.org/draft/2020-12/schema")
        resources.append((path.name, Resource.from_contents(doc)))
        if path.name == "config.schema.yaml":
            top = doc
    if top is None:
        raise FileNotFoundError(f"no config.schema.yaml in {schema_dir}")
    return top, Registry().with_resources(resources)


def _format_error(err: jsonschema.ValidationError) -> str:
    key = ".".join(str(p) for p in err.absolute_path) or "<top level>"
    value = err.instance if not isinstance(err.instance, (dict, list)) or len(str(err.instance)) < 80 else "…"
    expected = err.schema.get("description") or err.message
    return f"config key '{key}' = {value!r} is invalid: {err.message}. Expected: {expected}"


def validate_config(config: dict, schema_dir: Path = SCHEMA_DIR) -> dict:
    """Validate ``config`` (schema, then each paper's ``check_config``); return it unchanged.

    Raises
    ------
    ConfigError
        With every problem found, one per line.
    """
    top, registry = load_schemas(schema_dir)
    validator = jsonschema.Draft202012Validator(top, registry=registry)
    errors = sorted(validator.iter_errors(config), key=lambda e: list(map(str, e.absolute_path)))
    if errors:
        raise ConfigError("invalid configuration:\n  " + "\n  ".join(_format_error(e) for e in errors))
    problems = []
    for slug in config.get("papers", []):
        try:
            module = importlib.import_module(f"netrepro.papers.{slug}")
        except ModuleNotFoundError:
            problems.append(f"config key 'papers' lists {slug!r}, but there is no module netrepro.papers.{slug}")
            continue
        check = getattr(module, "check_config", None)
        if check is not None and slug in config:
            try:
                check(config[slug])
            except ConfigError as exc:
                problems.append(str(exc))
    if problems:
        raise ConfigError("invalid configuration:\n  " + "\n  ".join(problems))
    return config


def require_matrix(key: str, value, shape=None, square=False) -> np.ndarray:
    """A finite 2-D array from ``value``, or a :class:`ConfigError` naming ``key``."""
    try:
        arr = np.atleast_2d(np.asarray(value, dtype=float))
    except (TypeError, ValueError) as exc:
        raise ConfigError(f"config key '{key}' = {value!r} is not a numeric matrix") from exc
    if arr.ndim != 2 or not np.all(np.isfinite(arr)):
        raise ConfigError(f"config key '{key}' = {value!r} must be a finite 2-D matrix")
    if square and arr.shape[0] != arr.shape[1]:
        raise ConfigError(f"config key '{key}' has shape {arr.shape}; expected a square matrix")
    if shape is not None and arr.shape != tuple(shape):
        raise ConfigError(f"config key '{key}' has shape {arr.shape}; expected {tuple(shape)}")
    return arr


def require_pd(key: str, value, semi: bool = False) -> np.ndarray:
    """A symmetric positive (semi)definite matrix, or a :class:`ConfigError` naming ``key``."""
    arr = require_matrix(key, value, square=True)
    if not np.allclose(arr, arr.T):
        raise ConfigError(f"config key '{key}' = {value!r} must be symmetric")
    low = np.linalg.eigvalsh(arr).min()
    if (low < 0) if semi else (low <= 0):
        kind = "positive semidefinite" if semi else "positive definite"
        raise ConfigError(f"config key '{key}' = {value!r} must be {kind} (smallest eigenvalue {low:.3g})")
    return arr
