"""The per-paper step list, from which the workflow generates one rule per compute step.

Each paper package holds ``steps.yaml`` beside ``figures.yaml``: the paper's compute steps, each
declared once (issue 39). The workflow (``workflow/rules/steps.smk``) generates the rules from it,
``check-paper`` and the scaffold read it as data, without importing the paper::

    key_groups:                       # key lists several steps read (written $<group> in config)
      scenario: [scenarios, filter, noise]
    wildcards:                        # values of a step's wildcard (a step with `over:`)
      scenario: [fig2, fig3]
    tables: [design.gains, stability] # the paper's result tables, in the notebook's order
    steps:
      design:                         # the rule <slug>_design
        func: steps:design_step       # <module of netrepro.papers.<slug>>:<function>
        outputs: {gains: results/<slug>/gains.csv}
        config: [system, lmi]         # the keys of the paper's section the step reads
        inputs: {claims: src/netrepro/papers/<slug>/claims.yaml}   # or <step>[.<output>]
        threads: 1
        resources: {mem_mb: 2000, runtime: 5}
        local: false
        shard:                        # a sharded step: <slug>_<name>_shard runs per shard,
          func: steps:x_shard_step    # this step merges the shard outputs (input `shards`)
          outputs: {table: "results/<slug>/shards/x_{shard}.csv"}
          config: [system]
          wrap: cfg                   # the params nest the picked keys under "cfg" (else flat)

``config`` is a list of keys (``$<group>`` names a key group), read as ``pick(section, *keys)``,
or a mapping: ``{from: <entry>, keys: [...], merge: [<entry>, ...]}`` picks the keys of one entry
of the section and merges into them whole entries (or picks ``{from: <entry>, keys: [...]}``); ``{fields: {<name>: {from: <entry>, keys: [...]}}}``
nests such picks (without ``keys``: the whole entry). A step with ``over: <wildcard>`` runs once
per value of ``wildcards.<wildcard>``; its params are ``{<wildcard>: value, "cfg": ...}`` where
``narrow: <key>`` keeps only the value's entry of that key.

Inputs name another step's output (``design.gains``; ``design`` alone means its ``table``), a
fixed file (a path), ``{shards: <step>}`` (the shard files of a sharded step),
``{step: <step>, output: <name>, value: <wildcard value>}`` (one output of a step with ``over``), or
``{each: <step>}`` (every output of a step with ``over`` for every value, named
``<output>_<value>``). A step may name only steps declared above it.

Why a YAML file and not a decorator next to the function: ``check-paper``, the scaffold and the
schema read it without importing the paper (importing a paper's steps pulls numba and its
kernels), and the rule list stays one readable file per paper, like ``figures.yaml``.
"""

from __future__ import annotations

import functools
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..errors import ConfigError
from .codedeps import top_level_names
from .io import load_yaml

__all__ = ["StepSpec", "ShardSpec", "PaperSteps", "load_step_specs", "step_list_path", "compose_config",
           "config_keys"]

_SRC = Path(__file__).resolve().parents[1]  # the netrepro package (this module is in its pipeline/)
_NAME = re.compile(r"^[a-z][a-z0-9_]*$")
_FUNC = re.compile(r"^([a-z_][a-z0-9_]*):([A-Za-z_][A-Za-z0-9_]*)$")


@dataclass(frozen=True)
class ShardSpec:
    """The per-shard half of a sharded step: rule ``<slug>_<name>_shard``.

    Attributes
    ----------
    func : str
        ``module:function`` as passed to the runner.
    outputs : dict
        The one named output, with ``{shard}`` in its path.
    config : Any
        What of the paper's section the shard reads (see the module docstring).
    wrap : str or None
        Nest the picked keys under this name in the params (else merged flat).
    threads : int or None
        The shard rule's threads (None: Snakemake's default, 1).
    resources : dict
        The shard rule's resources (``mem_mb``, ``runtime`` in minutes).
    """

    func: str
    outputs: dict
    config: Any
    wrap: str | None = None
    threads: int | None = None
    resources: dict = field(default_factory=dict)


@dataclass(frozen=True)
class StepSpec:
    """One compute step: its rule, function, inputs, outputs and the configuration it reads.

    Attributes
    ----------
    slug : str
        The paper.
    name : str
        The step; the rule is ``<slug>_<name>``.
    func : str
        The step function as ``netrepro.papers.<slug>.<module>:<function>``.
    outputs : dict
        Output name -> path.
    inputs : dict
        Input name -> reference (see the module docstring), in declared order.
    config : Any
        What of the paper's section the step reads.
    threads, resources, local
        The rule's threads (None: Snakemake's default), resources and ``localrule``.
    shard : ShardSpec or None
        The per-shard rule of a sharded step.
    over : str or None
        The wildcard the step runs over (its values: :attr:`PaperSteps.wildcards`).
    narrow : str or None
        With ``over``: the key of the section narrowed to the wildcard value's entry.
    wrap : str or None
        Nest the picked keys under this name in the params.
    """

    slug: str
    name: str
    func: str
    outputs: dict
    inputs: dict = field(default_factory=dict)
    config: Any = field(default_factory=list)
    threads: int | None = None
    resources: dict = field(default_factory=dict)
    local: bool = False
    shard: ShardSpec | None = None
    over: str | None = None
    narrow: str | None = None
    wrap: str | None = None

    @property
    def rule(self) -> str:
        """The generated rule's name, ``<slug>_<name>``."""
        return f"{self.slug}_{self.name}"

    @property
    def log(self) -> str:
        """The rule's log file."""
        suffix = f"_{{{self.over}}}" if self.over else ""
        return f"logs/{self.slug}/{self.name}{suffix}.log"

    @property
    def shard_rule(self) -> str:
        """The per-shard rule's name, ``<slug>_<name>_shard``."""
        return f"{self.rule}_shard"

    @property
    def shard_log(self) -> str:
        """The per-shard rule's log file."""
        return f"logs/{self.slug}/{self.name}_{{shard}}.log"


@dataclass(frozen=True)
class PaperSteps:
    """A paper's step list: the steps in declared order, key groups, wildcard values, tables.

    Attributes
    ----------
    slug : str
        The paper.
    path : Path
        Its ``steps.yaml``.
    steps : list of StepSpec
        The steps, in declared order (a step names only steps above it).
    key_groups : dict
        Group name -> the configuration keys it stands for (``$<group>`` in a ``config``).
    wildcards : dict
        Wildcard name -> its values (for the steps with ``over``).
    tables : list of str
        The paper's result tables, ``<step>[.<output>]``, in the notebook's order.
    """

    slug: str
    path: Path
    steps: list
    key_groups: dict = field(default_factory=dict)
    wildcards: dict = field(default_factory=dict)
    tables: list = field(default_factory=list)

    def step(self, name: str) -> StepSpec:
        """The step called ``name``.

        Parameters
        ----------
        name : str
            The step's name (its rule without the slug prefix).

        Returns
        -------
        StepSpec
            The declaration.
        """
        for spec in self.steps:
            if spec.name == name:
                return spec
        raise KeyError(name)


def step_list_path(slug: str, src: Path = _SRC) -> Path:
    """The step list of a paper, ``<src>/papers/<slug>/steps.yaml``.

    Parameters
    ----------
    slug : str
        The paper.
    src : Path
        The directory holding the package.

    Returns
    -------
    Path
        The file (it may not exist).
    """
    return Path(src) / "papers" / slug / "steps.yaml"


@functools.lru_cache(maxsize=None)
def _schema(src: Path) -> dict:
    for where in (Path(src) / "schemas", Path(src).parents[1] / "workflow/schemas"):
        path = where / "steps.schema.yaml"
        if path.is_file():
            return load_yaml(path.read_text())
    raise ConfigError(f"no steps.schema.yaml under {Path(src) / 'schemas'}")


def _expand_keys(keys, groups: dict, where: str) -> list:
    out = []
    for key in keys:
        if isinstance(key, str) and key.startswith("$"):
            if key[1:] not in groups:
                raise ConfigError(f"{where}: key group {key!r} is not declared under key_groups "
                                  f"(declared: {sorted(groups)})")
            out += list(groups[key[1:]])
        else:
            out.append(key)
    return out


def _resolve_config(config, groups: dict, where: str):
    """``config`` with every ``$<group>`` replaced by its keys."""
    if isinstance(config, list):
        return _expand_keys(config, groups, where)
    config = dict(config)
    if "keys" in config:
        config["keys"] = _expand_keys(config["keys"], groups, where)
    if "fields" in config:
        config["fields"] = {name: _resolve_config(part, groups, f"{where}: field {name!r}")
                            for name, part in config["fields"].items()}
    if "merge" in config:
        config["merge"] = [part if isinstance(part, str) else _resolve_config(part, groups, where)
                           for part in config["merge"]]
    return config


def _pick(section: dict, keys) -> dict:
    return {k: section[k] for k in keys if k in section}


def compose_config(section: dict, config) -> dict:
    """The entries of the paper's configuration section that a step reads.

    Parameters
    ----------
    section : dict
        The paper's configuration section.
    config : list or dict
        The step's resolved ``config`` declaration (key groups expanded).

    Returns
    -------
    dict
        The step's configuration (the params' JSON): only these entries trigger its rerun.
    """
    if isinstance(config, list):
        return _pick(section, config)
    if "fields" in config:
        return {name: compose_config(section, part) for name, part in config["fields"].items()}
    entry = section.get(config["from"], {}) if "from" in config else section
    out = _pick(entry, config["keys"]) if "keys" in config else dict(entry)
    for part in config.get("merge", []):
        out.update(section.get(part, {}) if isinstance(part, str) else compose_config(section, part))
    return out


def config_keys(config) -> list[tuple[tuple, str]]:
    """The configuration keys a resolved ``config`` declaration reads, as ``(path, key)`` pairs.

    ``path`` is the entry of the section the key belongs to (``()`` for the section itself).

    Parameters
    ----------
    config : list or dict
        The step's resolved ``config`` declaration.

    Returns
    -------
    list of tuple
        ``(path, key)`` for every key read; a whole entry is ``((), <entry>)``.
    """
    if isinstance(config, list):
        return [((), k) for k in config]
    if "fields" in config:
        return [pair for part in config["fields"].values() for pair in config_keys(part)]
    out = []
    if "from" in config:
        out.append(((), config["from"]))
        out += [((config["from"],), k) for k in config.get("keys", [])]
    for part in config.get("merge", []):
        out += [((), part)] if isinstance(part, str) else config_keys(part)
    return out


def _functions(src: Path, slug: str, module: str) -> set:
    """The top-level names of a step module, from codedeps' cached summary (parsed only when it changed)."""
    return top_level_names(f"netrepro.papers.{slug}.{module}", Path(src).parent)


def _func(slug: str, text: str, src: Path, where: str, cache: dict) -> str:
    m = _FUNC.match(str(text))
    if not m:
        raise ConfigError(f"{where}: func {text!r} is not <module>:<function> (a module of netrepro.papers.{slug})")
    module, name = m.groups()
    path = Path(src) / "papers" / slug / f"{module}.py"
    if not path.is_file():
        raise ConfigError(f"{where}: func {text!r}: no module {path}")
    if path not in cache:
        cache[path] = _functions(src, slug, module)
    if name not in cache[path]:
        raise ConfigError(f"{where}: func {text!r}: {path} defines no function {name!r}")
    return f"netrepro.papers.{slug}.{module}:{name}"


def _check_input(ref, known: dict, wildcards: dict, where: str, root: Path) -> None:
    """A reference names a declared step above this one, and an output of it."""
    def output_of(step: str, output: str, what: str):
        if step not in known:
            raise ConfigError(f"{where}: input {what} names step {step!r}, which is not declared above it "
                              f"(declared above: {sorted(known)})")
        if output not in known[step].outputs:
            raise ConfigError(f"{where}: input {what} names {step}.{output}, but step {step!r} has the "
                              f"outputs {sorted(known[step].outputs)}")
        return known[step]

    name, value = ref
    if isinstance(value, str):
        if "/" in value:
            if root is not None and not (root / value).is_file():
                raise ConfigError(f"{where}: input {name!r} names the file {value}, which does not exist")
            return
        step, _, output = value.partition(".")
        spec = output_of(step, output or "table", repr(name))
        if spec.over:
            raise ConfigError(f"{where}: input {name!r}: step {step!r} runs over {spec.over}; name one value "
                              "({step: ..., output: ..., value: ...}) or all ({each: ...})")
    elif "shards" in value:
        if value["shards"] not in known or known[value["shards"]].shard is None:
            raise ConfigError(f"{where}: input {name!r} names the shards of {value['shards']!r}, which is not a "
                              "sharded step declared above")
    elif "each" in value:
        if value["each"] not in known or not known[value["each"]].over:
            raise ConfigError(f"{where}: input {name!r}: {value['each']!r} is not a step with `over` declared above")
    else:
        spec = output_of(value["step"], value["output"], repr(name))
        if not spec.over or value["value"] not in wildcards.get(spec.over, []):
            raise ConfigError(f"{where}: input {name!r}: {value['value']!r} is not a value of the wildcard "
                              f"{spec.over!r} of step {value['step']!r}")


def load_step_specs(slug: str, src: Path = _SRC, root: Path | None = None) -> PaperSteps:
    """The compute steps of paper ``slug``, validated, in declared order.

    Parameters
    ----------
    slug : str
        The paper.
    src : Path
        The directory holding the package.
    root : Path, optional
        The repository's root: fixed input files are checked to exist under it.

    Returns
    -------
    PaperSteps
        The steps, key groups, wildcard values and result tables.

    Raises
    ------
    ConfigError
        If the list is missing or malformed; the message names the file, the step and the field.
    """
    import jsonschema

    path = step_list_path(slug, src)
    if not path.is_file():
        raise ConfigError(f"paper {slug!r} has no step list {path}")
    data = load_yaml(path.read_text()) or {}
    validator = jsonschema.Draft202012Validator(_schema(src))
    errors = sorted(validator.iter_errors(data), key=lambda e: list(e.absolute_path))
    if errors:
        err = errors[0]
        at = list(err.absolute_path)
        where = f"step {at[1]!r}" if len(at) > 1 and at[0] == "steps" else "/".join(map(str, at)) or "top level"
        field_path = ".".join(map(str, at[2:])) if len(at) > 2 and at[0] == "steps" else ""
        raise ConfigError(f"{path}: {where}{f', field {field_path}' if field_path else ''}: {err.message}")
    groups = data.get("key_groups", {})
    wildcards = data.get("wildcards", {})
    known, outputs, cache = {}, {}, {}
    for name, entry in data["steps"].items():
        where = f"{path}: step {name!r}"
        if not _NAME.match(name):
            raise ConfigError(f"{where}: step names are lower_case")
        if entry.get("over") and entry["over"] not in wildcards:
            raise ConfigError(f"{where}: over {entry['over']!r} is not declared under wildcards")
        shard = None
        if "shard" in entry:
            part = entry["shard"]
            if len(part["outputs"]) != 1:
                raise ConfigError(f"{where}: field shard.outputs: a shard writes one named output")
            if not all("{shard}" in p for p in part["outputs"].values()):
                raise ConfigError(f"{where}: field shard.outputs: the path must hold {{shard}}")
            shard = ShardSpec(_func(slug, part["func"], src, f"{where}: field shard", cache), dict(part["outputs"]),
                              _resolve_config(part.get("config", []), groups, f"{where}: field shard.config"),
                              part.get("wrap"), part.get("threads"), dict(part.get("resources", {})))
        spec = StepSpec(slug, name, _func(slug, entry["func"], src, where, cache), dict(entry["outputs"]),
                        dict(entry.get("inputs", {})), _resolve_config(entry.get("config", []), groups,
                                                                       f"{where}: field config"),
                        entry.get("threads"), dict(entry.get("resources", {})), bool(entry.get("local", False)),
                        shard, entry.get("over"), entry.get("narrow"), entry.get("wrap"))
        for ref in spec.inputs.items():
            _check_input(ref, known, wildcards, where, root)
        paths = list(spec.outputs.items()) + (list(shard.outputs.items()) if shard else [])
        for output, file in paths:
            if file in outputs:
                raise ConfigError(f"{where}: output {output!r} ({file}) is already an output of step {outputs[file]!r}")
            outputs[file] = name
        if name in known:
            raise ConfigError(f"{where}: declared twice")
        known[name] = spec
    for ref in data.get("tables", []):
        step, _, output = str(ref).partition(".")
        if step not in known or (output or "table") not in known[step].outputs:
            raise ConfigError(f"{path}: tables: {ref!r} is not an output of a declared step")
    return PaperSteps(slug, path, list(known.values()), dict(groups), dict(wildcards), list(data.get("tables", [])))
