"""The console of `make report`: the netrepro logger plugin (one line per finished job)."""

import io
import logging
from types import SimpleNamespace

import pytest
from snakemake_interface_logger_plugins.common import LogEvent

import snakemake_logger_plugin_netrepro as plugin


def make_handler(**settings):
    common = SimpleNamespace(stdout=True, dryrun=False, verbose=False, debug_dag=False, quiet=set(),
                             printshellcmds=True, show_failed_logs=True, nocolor=True)
    common.__dict__.update(settings)
    handler = plugin.LogHandler(common, None)
    handler.stream = io.StringIO()
    handler.setFormatter(logging.Formatter("%(message)s"))
    return handler


def record(msg, level=logging.INFO, **extra):
    rec = logging.LogRecord("snakemake", level, __file__, 1, msg, None, None)
    rec.__dict__.update(extra)
    return rec


def feed(handler, *records):
    for rec in records:
        handler.handle(rec)
    return handler.stream.getvalue().splitlines()


def test_one_line_per_finished_job_and_no_command():
    handler = make_handler()
    long_command = "python -m netrepro run --params '" + "x" * 5000 + "'"
    lines = feed(
        handler,
        record("Building DAG of jobs..."),
        record("Job stats:\n...", event=LogEvent.RUN_INFO, stats={"a": 1, "b": 2, "total": 3}),
        record("Select jobs to execute..."),
        record("Execute 2 jobs..."),
        record(" Rule: a, Jobid: 7", event=LogEvent.JOB_INFO, jobid=7, rule_name="a", wildcards={}),
        record(long_command, event=LogEvent.SHELLCMD, cmd=long_command),
        record(" Rule: b, Jobid: 8", event=LogEvent.JOB_INFO, jobid=8, rule_name="b", wildcards={"shard": 1}),
        record("Finished jobid: 8 (Rule: b)", event=LogEvent.JOB_FINISHED, job_id=8),
        record("", event=LogEvent.PROGRESS, done=1, total=3),
        record("Finished jobid: 7 (Rule: a)", event=LogEvent.JOB_FINISHED, job_id=7),
        record("", event=LogEvent.PROGRESS, done=2, total=3),
    )
    assert lines[0] == "3 jobs of 2 rules to run"
    assert len(lines) == 3
    assert lines[1].startswith("[1/3  33%]") and lines[1].endswith("  b (shard=1)")
    assert lines[2].startswith("[2/3  67%]") and lines[2].endswith("  a")
    assert "netrepro run" not in "\n".join(lines)


def test_warnings_and_errors_are_shown_in_full():
    handler = make_handler()
    lines = feed(
        handler,
        record("Config file config/config.yaml is extended by additional config", level=logging.WARNING),
        record("Error in rule a:\n    jobid: 7\n    log: logs/a.log", level=logging.ERROR,
               event=LogEvent.JOB_ERROR),
        record("Select jobs to execute...", level=logging.WARNING),  # a warning is never hidden
    )
    text = "\n".join(lines)
    assert "is extended by additional config" in text
    assert "Error in rule a:" in text and "logs/a.log" in text
    assert "Select jobs to execute..." in text


@pytest.mark.parametrize("setting", ["dryrun", "verbose"])
def test_dry_run_and_verbose_print_everything(setting):
    handler = make_handler(**{setting: True})
    lines = feed(handler, record("Select jobs to execute..."),
                 record("python -m netrepro run", event=LogEvent.SHELLCMD, cmd="python -m netrepro run"))
    assert lines == ["Select jobs to execute...", "python -m netrepro run"]


def test_plugin_is_registered_under_its_name():
    from snakemake_interface_logger_plugins.registry import LoggerPluginRegistry

    registry = LoggerPluginRegistry()
    assert registry.is_installed("netrepro")
    assert registry.get_plugin("netrepro").log_handler is plugin.LogHandler
