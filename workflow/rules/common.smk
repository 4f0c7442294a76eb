# Shared helpers for all rules. Before any job runs, the Python environment is checked (every
# required package importable and recent enough) and the configuration is validated.
import json
import os
import shlex
import sys
from pathlib import Path

from snakemake.exceptions import WorkflowError

try:
    from netrepro.pipeline.codedeps import code_inputs
    from netrepro.pipeline.config import (
        check_dependencies,
        coerce_shard_counts,
        shard_count,
        validate_config,
    )
    from netrepro.errors import NetreproError
    from netrepro.pipeline.figurespec import load_figure_specs
    from netrepro.pipeline.stepspec import compose_config, load_step_specs
    from netrepro.pipeline.registry import paper_slugs
    from netrepro.pipeline.venv_paths import interpreter
    from netrepro.pipeline.processes import STARTER_VARIABLE, starter_mark
    from netrepro.judging.paperdata import (
        DATA_FILES,
        LOCK_FILE,
        load_paper_data,
        paper_dir,
        referenced_tables,
    )
except ImportError as exc:
    raise WorkflowError(
        f"cannot import the netrepro package with {sys.executable}: {exc}. "
        "Fix: run `make` (creates .venv/ with everything) and use .venv/bin/snakemake, "
        "or `pip install -e .` in this environment."
    ) from None

try:
    check_dependencies()
    coerce_shard_counts(config)  # `--config 'shards={...}'` arrives as strings
    # the schemas of this workflow copy (not of the installed package's checkout)
    validate_config(config, schema_dir=Path(workflow.current_basedir).parent / "schemas")
    # the claims data files of the papers (issue 15), validated before any job starts
    for _slug in config["papers"]:
        if (paper_dir(_slug) / "claims.yaml").is_file():
            load_paper_data(_slug)
except NetreproError as exc:
    raise WorkflowError(str(exc)) from None

# every job knows the Snakemake that started it (netrepro.pipeline.processes): one whose Snakemake is gone stops
# without writing; an environment variable, not a command-line argument, so no command changes
os.environ[STARTER_VARIABLE] = starter_mark()

# relative to the checkout when the interpreter lies inside it (.venv/bin/python): a moved checkout reruns nothing
PYTHON = interpreter()
# Filled by each paper's .smk: slug -> list of its result tables (shown by its notebook).
PAPER_TABLES = {}
# Filled by figures.smk: slug -> dict(figures=[...], tables=[...], claims=..., errata=...,
# reconstructions=..., notebook=...). The report rule collects from it.
PAPER_OUTPUTS = {}
# Software of every rule, for --use-conda (the default route is the .venv/ that `make` builds).
CONDA_ENV = "../envs/netrepro.yaml"


def enabled(slug):
    return slug in config["papers"]


def pick(section, *keys):
    """The entries of a config section that a step uses: only these trigger its rerun."""
    return {k: section[k] for k in keys if k in section}


def shards(step):
    """Shard indices of the sharded step ``step`` (config ``shards:``; one shard when not listed)."""
    return range(shard_count(config, step))


def as_json(obj):
    """A shell-quoted JSON string: the params of a rule, so a config change reruns it."""
    return shlex.quote(json.dumps(obj, sort_keys=True))


def io_json(wildcards, input, output):
    """The job's named inputs and outputs, as shell-quoted JSON for the runner."""
    return as_json({"inputs": dict(input.items()), "outputs": dict(output.items())})


# Every source file a step runs (filled by code() as the rules are read): the report's source pages
CODE_FILES = set()


def code(func):
    """Source files the step ``func`` runs: its module's import closure in the package (derived)."""
    files = code_inputs(func, root="src")
    CODE_FILES.update(files)
    return files


def step(func="{params.func}"):
    """Shell command of a pipeline step: one call into the package.

    Rules generated in a loop (steps.smk, figures.smk) pass ``params.func``: Snakemake evaluates
    a rule's shell expression again when its job runs, after the loop has moved on, so the
    function must come from the job's own params (which also rerun the rule when it changes);
    hand-written rules may pass the function here. The rule's
    name is its ``params.rule`` (Snakemake formats ``{rule}`` only in shell commands, and
    ``snakemake --lint`` reports that as a variable from outside the rule); the runner records it
    in every output's sidecar, which is where the report reads it. ``tests/test_codedeps.py``
    checks that each rule's ``params.rule`` is its own name.
    """
    # BLAS threads = the job's threads: with -j2 on 2 cores, more only adds contention
    return (
        "OPENBLAS_NUM_THREADS={threads} OMP_NUM_THREADS={threads} "
        f"{PYTHON} -m netrepro run --rule {{params.rule}} --func {func} "
        "--params {params.cfg} --io {params.io} > {log} 2>&1"
    )


def notebook(slug="{params.slug}"):
    """Shell command executing the paper's papermill notebook into report/<slug>.html.

    The notebook reads tables directly, so their checksums are verified first (a truncated or
    edited table stops the rule with a message naming it, instead of being shown silently).
    """
    return (
        f"{PYTHON} -m netrepro verify --inputs {{input}} > {{log}} 2>&1 && "
        f"{PYTHON} -m netrepro report notebook --slug {slug} "
        "--notebook {input.notebook} --html {output.html} >> {log} 2>&1"
    )


def paper_data_files(slug):
    """The data files of a paper's claims layer (claims, errata, reconstructions, findings, the findings' registry)."""
    root = Path("src/netrepro/papers") / slug
    files = {f"{name}_file": str(root / f"{name}.yaml") for name in DATA_FILES}
    if (root / LOCK_FILE).is_file():
        files["registry_file"] = str(root / LOCK_FILE)
    return files


def paper_claim_tables(slug):
    """The result tables a paper's claims read (named in its claims.yaml)."""
    try:
        return referenced_tables(slug)
    except NetreproError as exc:
        raise WorkflowError(str(exc)) from None


def figure_specs(slug):
    """The paper's figure list (src/netrepro/papers/<slug>/figures.yaml), or a clear error."""
    try:
        return load_figure_specs(slug)
    except NetreproError as exc:
        raise WorkflowError(str(exc)) from None


def figure_inputs(spec):
    """Named input tables of a figure, as the outputs of the rules that write them."""
    named = {}
    for name, (rule_name, output) in spec.input_rules().items():
        try:
            named[name] = getattr(getattr(rules, rule_name).output, output)
        except AttributeError:
            raise WorkflowError(
                f"figure {spec.rule}: input {name!r} names {rule_name}.{output}, which is not a rule output"
            ) from None
    return named


def report_inputs(wildcards):
    """Every registered output of every enabled paper, as named inputs of the report rule."""
    named = {}
    for slug, spec in PAPER_OUTPUTS.items():
        named[f"{slug}_figures"] = spec["figures"]
        named[f"{slug}_claims"] = spec["claims"]
        named[f"{slug}_errata"] = spec["errata"]
        named[f"{slug}_reconstructions"] = spec["reconstructions"]
        named[f"{slug}_findings"] = spec["findings"]
        named[f"{slug}_captions"] = spec["captions"]
        named[f"{slug}_figure_list"] = spec["figure_list"]
        named[f"{slug}_notebook"] = spec["notebook"]
    return named


# ----- the compute steps generated from each paper's steps.yaml (workflow/rules/steps.smk)
def step_list(slug):
    """The paper's step list, validated before any job runs, or a clear error."""
    try:
        return load_step_specs(slug, root=Path("."))
    except NetreproError as exc:
        raise WorkflowError(str(exc)) from None


def step_output(slug, ref):
    """``<step>[.<output>]`` of paper ``slug`` as the output of the rule that writes it."""
    name, _, output = ref.partition(".")
    return getattr(getattr(rules, f"{slug}_{name}").output, output or "table")


def step_inputs(paper, spec):
    """Named inputs of a step: the step's code, then its declared inputs, then its shard files."""
    named = {"code": code(spec.func)}
    for name, ref in spec.inputs.items():
        if isinstance(ref, str):
            named[name] = ref if "/" in ref else step_output(paper.slug, ref)
        elif "shards" in ref:
            named[name] = getattr(rules, f"{paper.slug}_{ref['shards']}").input.shards
        elif "each" in ref:
            source = paper.step(ref["each"])
            for kind, path in source.outputs.items():
                for value in paper.wildcards[source.over]:
                    named[f"{kind}_{value}"] = expand(path, **{source.over: value})[0]
        else:
            source = paper.step(ref["step"])
            named[name] = expand(source.outputs[ref["output"]], **{source.over: ref["value"]})[0]
    if spec.shard:
        named["shards"] = expand(list(spec.shard.outputs.values())[0], shard=shards(spec.rule))
    return named


def wrapped(cfg, wrap, extra):
    """The params' configuration: the picked keys (nested under ``wrap`` if set) and ``extra``."""
    return {wrap: cfg, **extra} if wrap else {**cfg, **extra}


def shard_params(section, spec):
    """Params of one shard job: the keys the shard reads, its index and the shard count."""

    def cfg(wildcards):
        extra = {"shard": int(wildcards.shard), "n_shards": len(shards(spec.rule))}
        return as_json(wrapped(compose_config(section, spec.shard.config), spec.shard.wrap, extra))

    return cfg


def over_params(section, spec):
    """Params of a step run per wildcard value: that value, and only its entry of ``narrow``."""

    def cfg(wildcards):
        value = wildcards[spec.over]
        picked = compose_config(section, spec.config)
        if spec.narrow:
            picked[spec.narrow] = pick(section.get(spec.narrow, {}), value)
        return as_json(wrapped(picked, spec.wrap, {spec.over: value}))

    return cfg


# the recorded paper-scale run (issue 31): `python -m netrepro scale-record`; the report's panel
# "Does scale change a verdict?" compares this run's claims with it, where it exists
SCALE_REFERENCE = "tests/reference/paper-scale"
SCALE_RECORDED = Path(SCALE_REFERENCE, "provenance.json").is_file()


def scale_sources(wildcards):
    """The recorded source files that still exist: an edit of one reruns the comparison (staleness)."""
    recorded = json.loads(Path(SCALE_REFERENCE, "provenance.json").read_text())
    paths = {p for files in recorded.get("code", {}).values() for p in files}
    return sorted(p for p in paths if Path(p).is_file())
