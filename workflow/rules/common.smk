# Shared helpers for all rules. The configuration is validated here, before any job runs.
import json
import shlex
import sys

from snakemake.exceptions import WorkflowError

from netrepro.config import ConfigError, validate_config

try:
    validate_config(config)
except ConfigError as exc:
    raise WorkflowError(str(exc)) from None

PYTHON = sys.executable
# Filled by each paper's .smk: slug -> dict(figures=[...], tables=[...], claims=..., errata=...,
# reconstructions=..., notebook=...). The report rule collects from it.
PAPER_OUTPUTS = {}


def enabled(slug):
    return slug in config["papers"]


def pick(section, *keys):
    """The entries of a config section that a step uses: only these trigger its rerun."""
    return {k: section[k] for k in keys if k in section}


def as_json(obj):
    """A shell-quoted JSON string: the params of a rule, so a config change reruns it."""
    return shlex.quote(json.dumps(obj, sort_keys=True))


def io_json(wildcards, input, output):
    """Named inputs and outputs of the job, as shell-quoted JSON for the runner."""
    return as_json({"inputs": dict(input.items()), "outputs": dict(output.items())})


def src(*modules):
    """Package source files a rule depends on, so that a code change reruns it."""
    return [f"src/netrepro/{m}" for m in modules] + ["src/netrepro/runner.py"]


def finalize_rules(workflow):
    """Write each rule's own name into its runner command (the `--rule` of the provenance)."""
    for each in workflow.rules:
        if each.shellcmd and RULE_PLACEHOLDER in each.shellcmd:
            each.shellcmd = each.shellcmd.replace(RULE_PLACEHOLDER, each.name)


RULE_PLACEHOLDER = "@RULE@"
# Software of every rule, for --use-conda (the default route is the .venv/ that `make` builds).
CONDA_ENV = "../envs/netrepro.yaml"


def step(func):
    """Shell command of a pipeline step: one call into the package."""
    return (
        f"{PYTHON} -m netrepro run --rule {RULE_PLACEHOLDER} --func {func} "
        "--params {params.cfg} --io {params.io} > {log} 2>&1"
    )


def notebook(slug):
    """Shell command executing the paper's papermill notebook into report/<slug>.html."""
    return (
        f"{PYTHON} -m netrepro.reportgen notebook --slug {slug} "
        "--notebook {input.notebook} --html {output.html} > {log} 2>&1"
    )


def report_inputs(wildcards):
    """Every registered output of every enabled paper, as named inputs of the report rule."""
    named = {}
    for slug, spec in PAPER_OUTPUTS.items():
        named[f"{slug}_figures"] = spec["figures"]
        named[f"{slug}_claims"] = spec["claims"]
        named[f"{slug}_errata"] = spec["errata"]
        named[f"{slug}_reconstructions"] = spec["reconstructions"]
        named[f"{slug}_notebook"] = spec["notebook"]
    return named
