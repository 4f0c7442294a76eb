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


def as_json(obj):
    """A shell-quoted JSON string: the params of a rule, so a config change reruns it."""
    return shlex.quote(json.dumps(obj, sort_keys=True))


def io_json(wildcards, input, output):
    """Named inputs and outputs of the job, as shell-quoted JSON for the runner."""
    return as_json({"inputs": dict(input.items()), "outputs": dict(output.items())})


def src(*modules):
    """Package source files a rule depends on, so that a code change reruns it."""
    return [f"src/netrepro/{m}" for m in modules] + ["src/netrepro/runner.py"]


def step(func):
    """Shell command of a pipeline step: one call into the package."""
    return (
        f"{PYTHON} -m netrepro run --rule {{rule}} --func {func} "
        "--params {params.cfg} --io {params.io} > {log} 2>&1"
    )


def notebook(slug):
    """Shell command executing the paper's papermill notebook into report/<slug>.html."""
    return (
        f"{PYTHON} -m netrepro.reportgen notebook --slug {slug} "
        "--notebook {input.notebook} --html {output.html} > {log} 2>&1"
    )
