"""Configuration and environment checks, run before any job starts.

The schema ``workflow/schemas/config.schema.yaml`` describes the top level
and refers to one schema per paper (``<slug>.schema.yaml``). Structural checks
(types, ranges, sizes) come from JSON Schema; checks a schema cannot express
(matrix shapes that agree, positive definite covariances) come from the
paper module's ``check_config(section)`` function, if it defines one. Checks
that hold for every paper are made here: the configuration is a mapping,
every paper listed in ``papers`` has its section, no number is NaN or
infinite, and every ``seed`` is a non-negative integer.
Every error names the key, the value and what was expected.

:func:`check_dependencies` verifies, before anything is imported for real,
that the packages the pipeline needs (the ``dependencies`` of the installed
``netrepro`` distribution) are importable and recent enough, so that a
missing solver or package is reported at start-up rather than as a traceback
in the middle of a run.
"""

from __future__ import annotations

import copy
import importlib
import importlib.util
import math
import re
import sys
from importlib import metadata
from pathlib import Path

import numpy as np

from ..errors import ConfigError, DependencyError
from ..locations import PAPERS_DIR, SCHEMA_DIR

__all__ = [
    "ConfigError",
    "DependencyError",
    "SCHEMA_DIR",
    "REQUIRED_PACKAGES",
    "load_schemas",
    "validate_config",
    "coerce_shard_counts",
    "shard_count",
    "check_dependencies",
    "require_matrix",
    "require_pd",
]

# Used when the distribution metadata is unavailable (e.g. running from a source tree).
REQUIRED_PACKAGES = (
    "snakemake>=9", "numpy>=2", "scipy>=1.12", "cvxpy>=1.5", "clarabel>=0.9", "matplotlib>=3.8", "pandas>=2.2",
    "papermill>=2.6", "ipykernel>=6", "nbconvert>=7", "jsonschema>=4.20", "pyyaml>=6", "numba>=0.60",
)
# Distribution name -> import name, where they differ.
IMPORT_NAMES = {"pyyaml": "yaml", "scikit-learn": "sklearn"}
# packages imported (not only found) by the start-up check: the solvers the LMI steps name
# (netrepro.engines.cvx.SOLVER), whose failure would otherwise surface inside the jobs
IMPORTED_AT_START = ("clarabel",)
# What each package is for, to make the message actionable.
PURPOSE = {
    "cvxpy": "LMI feasibility problems",
    "clarabel": "the conic solver of the LMI problems",
    "papermill": "executing the report notebooks",
    "nbconvert": "rendering the report notebooks to HTML",
    "ipykernel": "the kernel of the report notebooks",
    "jsonschema": "validating the configuration",
    "snakemake": "the workflow",
    "numba": "the compiled covariance-recursion kernels",
}




# ----------------------------------------------------------------------------- dependencies
def _requirements() -> list[str]:
    try:
        reqs = metadata.requires("netrepro") or []
    except metadata.PackageNotFoundError:
        reqs = []
    reqs = [r for r in reqs if "extra ==" not in r]
    return reqs or list(REQUIRED_PACKAGES)


def _parse_requirement(text: str):
    """``(distribution name, SpecifierSet or None)`` of a requirement string."""
    try:
        from packaging.requirements import Requirement

        req = Requirement(text)
        return req.name, req.specifier
    except ImportError:  # packaging is nearly always present; degrade to presence checks
        import re

        return re.split(r"[<>=!~;\[ ]", text, maxsplit=1)[0], None


def check_dependencies(requirements=None) -> list[str]:
    """Check that every required package is importable and satisfies its version bound.

    Parameters
    ----------
    requirements : sequence of str, optional
        PEP 508 requirement strings; default: the installed ``netrepro``
        distribution's dependencies (falling back to :data:`REQUIRED_PACKAGES`).

    Returns
    -------
    list of str
        The requirements checked.

    Raises
    ------
    DependencyError
        Naming every missing, unimportable or too old package, what it is
        needed for, and the command that installs it.
    """
    requirements = list(requirements) if requirements is not None else _requirements()
    problems = []
    for text in requirements:
        dist, spec = _parse_requirement(text)
        module = IMPORT_NAMES.get(dist.lower(), dist.lower().replace("-", "_"))
        why = f" (needed for {PURPOSE[dist.lower()]})" if dist.lower() in PURPOSE else ""
        try:
            found = importlib.util.find_spec(module) is not None
        except (ImportError, ValueError):
            found = False
        if not found:
            problems.append(f"required package '{dist}' is missing: cannot import '{module}'{why}; "
                            f"expected {text!r}")
            continue
        if dist.lower() in IMPORTED_AT_START:
            # a solver that is present but cannot load (a broken build, a missing shared library) would
            # otherwise fail inside every LMI job with a traceback; importing it costs ~30 ms
            try:
                importlib.import_module(module)
            except Exception as exc:  # noqa: BLE001 - any import failure is the message
                problems.append(f"required package '{dist}'{why} is installed but cannot be imported: "
                                f"{type(exc).__name__}: {exc}; reinstall it: "
                                f"`{sys.executable} -m pip install --force-reinstall '{text}'`")
                continue
        if spec is None or not str(spec):
            continue
        try:
            version = metadata.version(dist)
        except metadata.PackageNotFoundError:
            continue  # importable but not pip-installed (e.g. vendored): nothing to compare
        if not spec.contains(version, prereleases=True):
            problems.append(f"required package '{dist}' has version {version}{why}; expected {text!r}")
    if problems:
        raise DependencyError(
            f"the Python environment ({sys.executable}) cannot run the pipeline:\n  " + "\n  ".join(problems)
            + "\nFix: run `make` (creates .venv/ with everything), or `pip install -e .` in this environment.")
    return requirements


# ----------------------------------------------------------------------------- schemas
_SCHEMA_CACHE: dict = {}


def _read_schema(path: Path) -> dict:
    """Parse one schema file (cached on its modification time and size: parsing YAML is slow)."""
    import yaml

    stat = path.stat()
    key = (str(path), stat.st_mtime_ns, stat.st_size)
    if key not in _SCHEMA_CACHE:
        loader = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
        try:
            doc = yaml.load(path.read_text(), Loader=loader)  # noqa: S506 (a safe loader)
        except yaml.YAMLError as exc:
            raise ConfigError(f"schema file {path} is not valid YAML: {exc}") from None
        if not isinstance(doc, dict):
            raise ConfigError(f"schema file {path} must hold a mapping, got {type(doc).__name__}")
        _SCHEMA_CACHE[key] = doc
    return _SCHEMA_CACHE[key]


def load_schemas(schema_dir: Path = SCHEMA_DIR):
    """The top-level schema and a registry resolving ``$ref: <file>.schema.yaml``.

    Parameters
    ----------
    schema_dir : pathlib.Path
        The folder of the schemas (by default the package's own, :data:`netrepro.locations.SCHEMA_DIR`:
        ``workflow/schemas`` in a clone, a copy of it in an installed wheel).

    Returns
    -------
    top : dict
        ``config.schema.yaml``, with its ``$schema`` set.
    registry : referencing.Registry
        Every ``*.schema.yaml`` of the folder under its file name, for ``$ref``.

    Raises
    ------
    FileNotFoundError
        When the folder has no ``config.schema.yaml``.
    """
    from referencing import Registry, Resource

    resources = []
    top = None
    for path in sorted(Path(schema_dir).glob("*.schema.yaml")):
        doc = copy.deepcopy(_read_schema(path))
        doc.setdefault("$schema", "https://json-schema.org/draft/2020-12/schema")
        resources.append((path.name, Resource.from_contents(doc)))
        if path.name == "config.schema.yaml":
            top = doc
    if top is None:
        raise FileNotFoundError(f"no config.schema.yaml in {schema_dir}")
    return top, Registry().with_resources(resources)


def _short(value) -> str:
    text = repr(value)
    return text if len(text) <= 80 else text[:77] + "..."


def _format_error(err, describe=None) -> str:
    """One line naming the key, the value and what is expected."""
    path = [str(p) for p in err.absolute_path]
    expected = err.schema.get("description") if isinstance(err.schema, dict) else None
    if not expected and describe is not None:
        expected = describe(err.absolute_path)
    if err.validator == "required":
        # "'x' is a required property": name the missing key itself
        missing = err.message.split("'")[1] if err.message.count("'") >= 2 else "?"
        key = ".".join(path + [missing])
        sub = err.schema.get("properties", {}).get(missing, {}) if isinstance(err.schema, dict) else {}
        what = sub.get("description") if isinstance(sub, dict) else None
        return (f"config key '{key}' is missing (value: none). Expected: {what or 'a value'} "
                f"(required in '{'.'.join(path) or '<top level>'}')")
    if err.validator == "additionalProperties":
        known = sorted((err.schema.get("properties") or {}).keys()) if isinstance(err.schema, dict) else []
        extra = sorted(set(err.instance) - set(known)) if isinstance(err.instance, dict) else []
        lines = []
        for name in extra or ["?"]:
            key = ".".join(path + [name])
            value = err.instance.get(name) if isinstance(err.instance, dict) else None
            if name == "n_shards":
                lines.append(f"config key '{key}' = {_short(value)} is not a known key: shard counts moved to the "
                             "top-level section 'shards:' (one entry per sharded step, e.g. shards: "
                             "{intermittent_monte_carlo: 4}; see config/config.yaml)")
                continue
            lines.append(f"config key '{key}' = {_short(value)} is not a known key (a typo?). "
                         f"Expected one of: {', '.join(known)}")
        return "\n  ".join(lines)
    key = ".".join(path) or "<top level>"
    return (f"config key '{key}' = {_short(err.instance)} is invalid: {err.message}. Expected: {expected or err.message}"
            + _yaml_float_hint(err.instance))


def _yaml_float_hint(value) -> str:
    """The fix for a number YAML 1.1 read as text (``1.0e12``, ``1e-5``): "" for anything else."""
    if not isinstance(value, str):
        return ""
    text = value.strip()
    if not re.fullmatch(r"[-+]?(?:\d+(?:\.\d*)?|\.\d+)[eE][-+]?\d+", text):
        return ""
    mantissa, _, exponent = text.lower().partition("e")
    fixed = f"{mantissa if '.' in mantissa else mantissa + '.0'}e{exponent if exponent[0] in '+-' else '+' + exponent}"
    return (f" (YAML 1.1, which Snakemake reads the configuration with, takes {text} for text: write it as {fixed}, "
            "with a dot and a signed exponent)")


def _describer(top: dict, registry):
    """``path -> description`` of the nearest schema along ``path`` that has one (follows ``$ref``)."""

    def resolve(schema):
        for _ in range(10):
            if isinstance(schema, dict) and "$ref" in schema and not schema["$ref"].startswith("#"):
                schema = registry[schema["$ref"]].contents
            else:
                break
        return schema if isinstance(schema, dict) else {}

    def describe(path):
        schema, found = resolve(top), None
        for part in path:
            if isinstance(part, int):
                schema = resolve(schema.get("items", {}))
            else:
                props = schema.get("properties", {})
                extra = schema.get("additionalProperties")
                schema = resolve(props.get(part, extra if isinstance(extra, dict) else {}))
            found = schema.get("description", found)
        return found

    return describe


def _walk(node, prefix=""):
    """Yield ``(dotted key, value)`` for every leaf of a nested dict/list."""
    if isinstance(node, dict):
        for key, value in node.items():
            yield from _walk(value, f"{prefix}.{key}" if prefix else str(key))
    elif isinstance(node, (list, tuple)):
        for i, value in enumerate(node):
            yield from _walk(value, f"{prefix}[{i}]")
    else:
        yield prefix, node


def _generic_problems(config: dict) -> list[str]:
    """Checks that hold for every paper: finite numbers, integer seeds."""
    problems = []
    for key, value in _walk(config):
        if isinstance(value, float) and not math.isfinite(value):
            problems.append(f"config key '{key}' = {value!r} is invalid: not a finite number. "
                            "Expected: a finite number (NaN and infinity are never valid configuration values)")
        last = key.rsplit(".", 1)[-1].split("[", 1)[0].lower()
        if "seed" in last and value is not None:
            if isinstance(value, bool) or not isinstance(value, int) or value < 0:
                problems.append(f"config key '{key}' = {_short(value)} is invalid: not a seed. "
                                "Expected: a non-negative integer (random seeds feed numpy.random.SeedSequence)")
    return problems


def _schema_requires(schema_dir: Path, slug: str) -> list:
    path = Path(schema_dir) / f"{slug}.schema.yaml"
    return list(_read_schema(path).get("required", [])) if path.is_file() else []


def coerce_shard_counts(config: dict) -> dict:
    """Turn the shard counts given on the command line into integers, in place; return ``config``.

    ``snakemake --config 'shards={step: 8}'`` reads its value with YAML's base loader, which keeps
    every scalar a string ("8"). Only strings of decimal digits are converted: anything else stays
    as given, so that validation names it.

    Parameters
    ----------
    config : dict
        The workflow configuration; its ``shards`` mapping, if any, is updated in place.

    Returns
    -------
    dict
        ``config`` itself.
    """
    shards = config.get("shards") if isinstance(config, dict) else None
    if isinstance(shards, dict):
        for step, count in shards.items():
            if isinstance(count, str) and count.strip().isdigit():
                shards[step] = int(count)
    return config


def shard_count(config: dict, step: str) -> int:
    """Snakemake jobs of the sharded step ``step`` (1 when the configuration does not list it).

    Parameters
    ----------
    config : dict
        The workflow configuration (validated).
    step : str
        A key of its ``shards`` section, e.g. ``"onebit_estimator"``.

    Returns
    -------
    int
        The number of shard jobs, at least 1.
    """
    return int((config.get("shards") or {}).get(step, 1))


def validate_config(config: dict, schema_dir: Path = SCHEMA_DIR) -> dict:
    """Validate ``config`` (schema, generic checks, then each paper's ``check_config``); return it unchanged.

    Parameters
    ----------
    config : dict
        The merged workflow configuration (every ``--configfile`` and ``--config`` applied).
    schema_dir : pathlib.Path
        The folder of the schemas.

    Returns
    -------
    dict
        ``config`` itself.

    Raises
    ------
    ConfigError
        With every problem found, one per line.
    """
    import jsonschema

    if not isinstance(config, dict) or not config:
        raise ConfigError(
            f"invalid configuration: the configuration is {_short(config)}; expected a mapping with at least "
            "the key 'papers' (is the --configfile empty or not YAML?)")
    top, registry = load_schemas(schema_dir)
    validator = jsonschema.Draft202012Validator(top, registry=registry)
    errors = sorted(validator.iter_errors(config), key=lambda e: list(map(str, e.absolute_path)))
    describe = _describer(top, registry)
    problems = [_format_error(e, describe) for e in errors]
    problems += [p for p in _generic_problems(config) if p not in problems]
    papers = config.get("papers") if isinstance(config.get("papers"), list) else []
    for slug in papers:
        if isinstance(slug, str) and slug not in config and _schema_requires(schema_dir, slug):
            problems.append(
                f"config key '{slug}' is missing (value: none): 'papers' lists {slug!r}, so a section '{slug}:' is "
                f"expected, as described by workflow/schemas/{slug}.schema.yaml (copy it from config/config.yaml), "
                f"or remove {slug!r} from 'papers'")
    if problems:
        raise ConfigError("invalid configuration:\n  " + "\n  ".join(problems))
    for slug in papers:
        # a paper package keeps its configuration checks in `checks.py`, light to import at start-up
        is_package = (PAPERS_DIR / str(slug) / "__init__.py").is_file()
        module_name = f"netrepro.papers.{slug}.checks" if is_package else f"netrepro.papers.{slug}"
        try:
            module = importlib.import_module(module_name)
        except ModuleNotFoundError as exc:
            if exc.name in (f"netrepro.papers.{slug}", "netrepro.papers"):
                problems.append(f"config key 'papers' lists {slug!r}, but there is no module netrepro.papers.{slug}")
                continue
            raise DependencyError(
                f"paper {slug!r} needs the package '{exc.name}', which cannot be imported ({exc}). "
                "Fix: run `make` or `pip install -e .`") from None
        check = getattr(module, "check_config", None)
        if check is not None and slug in config:
            try:
                check(config[slug])
            except ConfigError as exc:
                problems.append(str(exc))
            except (KeyError, TypeError, ValueError, IndexError) as exc:
                problems.append(f"config section '{slug}' could not be checked by {module_name}.check_config "
                                f"({type(exc).__name__}: {exc}); expected the keys and types of "
                                f"workflow/schemas/{slug}.schema.yaml")
    if problems:
        raise ConfigError("invalid configuration:\n  " + "\n  ".join(problems))
    return config


# ----------------------------------------------------------------------------- helpers for check_config
def require_matrix(key: str, value, shape=None, square=False) -> np.ndarray:
    """A finite 2-D array from ``value``, or a :class:`ConfigError` naming ``key``.

    Parameters
    ----------
    key : str
        The configuration key, for the message (e.g. ``"gainsched.system.A"``).
    value : object
        The configured value (nested lists, or a scalar, read as a 1 x 1 matrix).
    shape : tuple of int, optional
        The shape required, if any.
    square : bool
        Whether the matrix must be square.

    Returns
    -------
    numpy.ndarray
        The matrix as floats.

    Raises
    ------
    ConfigError
        When the value is not numeric, not finite, not 2-D, or of the wrong shape.
    """
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
    """A symmetric positive (semi)definite matrix, or a :class:`ConfigError` naming ``key``.

    Parameters
    ----------
    key : str
        The configuration key, for the message.
    value : object
        The configured matrix.
    semi : bool
        Accept a smallest eigenvalue of 0 (semidefinite) instead of requiring it positive.

    Returns
    -------
    numpy.ndarray
        The matrix as floats.

    Raises
    ------
    ConfigError
        When it is not a finite square matrix, not symmetric (to numpy's ``allclose``), or not
        positive (semi)definite; the message gives the smallest eigenvalue.
    """
    arr = require_matrix(key, value, square=True)
    if not np.allclose(arr, arr.T):
        raise ConfigError(f"config key '{key}' = {value!r} must be symmetric")
    low = np.linalg.eigvalsh(arr).min()
    if (low < 0) if semi else (low <= 0):
        kind = "positive semidefinite" if semi else "positive definite"
        raise ConfigError(f"config key '{key}' = {value!r} must be {kind} (smallest eigenvalue {low:.3g})")
    return arr
