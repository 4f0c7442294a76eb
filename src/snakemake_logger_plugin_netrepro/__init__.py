"""Snakemake logger plugin ``netrepro``: a progress log a person can read.

``snakemake --logger netrepro`` (set in ``workflow/profiles/default/config.yaml``) prints one line
per finished job, ``[12/93  13%]     2.1 s  onebit_estimator_shard (shard=1)``, instead of Snakemake's block per job
(rule, inputs, outputs, resources, reason and, with ``--printshellcmds``, the whole command with
the configuration as JSON). Warnings, errors and failed jobs (with their logs, under
``--show-failed-logs``) are printed in full, as Snakemake prints them. Each job's command stays in
Snakemake's own log file (``.snakemake/log/``), in the job's log (``logs/``) and in the provenance
sidecar of its outputs (``*.meta.json``).

A dry run (``-n``), ``--verbose`` and ``--debug-dag`` fall back to Snakemake's own output.
Discovered by Snakemake's plugin registry through the module name
(``snakemake_logger_plugin_<name>``); installed with the ``netrepro`` package.
"""

from __future__ import annotations

import logging
import re
import sys

from snakemake_interface_logger_plugins.base import LogHandlerBase
from snakemake_interface_logger_plugins.common import LogEvent

__all__ = ["LogHandler", "CHATTER"]

# Snakemake's per-scheduling-round and start-up messages: not shown (the log file keeps them).
CHATTER = re.compile(
    r"^(Select jobs to execute\.\.\.|Execute \d+ jobs\.\.\.|Building DAG of jobs\.\.\.|Using shell: |"
    r"Provided cores: |Rules claiming more threads will be scaled down\.|Conda environments: ignored|"
    r"Singularity containers: ignored|Assuming unrestricted shared filesystem usage\.|"
    r"Provided resources: |Job stats:|Adding .+ \([\d.]+ [KMG]?B\)\.$)"
)
# Events that describe a job being scheduled or started: shown only as the finished line.
_HIDDEN = {LogEvent.JOB_INFO, LogEvent.JOB_STARTED, LogEvent.SHELLCMD, LogEvent.RESOURCES_INFO,
           LogEvent.GROUP_INFO, LogEvent.WORKFLOW_STARTED, LogEvent.RULEGRAPH, LogEvent.DEBUG_DAG}
_FINISHED = re.compile(r"Finished jobid: (?P<jobid>\d+) \(Rule: (?P<rule>[^)]+)\)")


class LogHandler(LogHandlerBase):
    """One line per finished job; everything at WARNING and above in full."""

    def __post_init__(self) -> None:
        settings = self.common_settings
        self.stream = sys.stdout if getattr(settings, "stdout", False) else sys.stderr
        self.passthrough = bool(getattr(settings, "dryrun", False) or getattr(settings, "verbose", False)
                                or getattr(settings, "debug_dag", False))
        self.started: dict[int, tuple[float, str]] = {}
        self.finished: list[tuple[str, float | None]] = []
        self.total = None
        self.width = 1

    # -- the plugin interface
    @property
    def writes_to_stream(self) -> bool:
        return True

    @property
    def writes_to_file(self) -> bool:
        return False

    @property
    def has_filter(self) -> bool:
        return False  # Snakemake's default filter first (--quiet, --printshellcmds, levels)

    @property
    def has_formatter(self) -> bool:
        return False  # Snakemake's default formatter for what is shown in full

    @property
    def needs_rulegraph(self) -> bool:
        return False

    # -- output
    def _write(self, text: str) -> None:
        if text:
            self.stream.write(text.rstrip("\n") + "\n")
            self.stream.flush()

    def emit(self, record: logging.LogRecord) -> None:
        try:
            text = self.render(record)
            if text is not None:
                self._write(text)
        except Exception:  # noqa: BLE001 - a logger must never stop the run
            self.handleError(record)

    def render(self, record: logging.LogRecord) -> str | None:
        """The text shown for ``record``, or None to show nothing."""
        if self.passthrough or record.levelno >= logging.WARNING:
            return self.format(record)
        event = getattr(record, "event", None)
        if event == LogEvent.JOB_INFO and getattr(record, "jobid", None) is not None:
            wildcards = getattr(record, "wildcards", None) or {}
            label = ",".join(f"{k}={v}" for k, v in dict(wildcards).items())
            self.started[int(record.jobid)] = (record.created, f" ({label})" if label else "")
            return None
        if event in _HIDDEN:
            return None
        if event == LogEvent.RUN_INFO:
            stats = getattr(record, "stats", None)
            if isinstance(stats, dict) and stats:
                jobs = {k: int(n) for k, n in stats.items() if k != "total"}
                self.total = int(stats.get("total", sum(jobs.values())))
                self.width = len(str(self.total))
                return f"{self.total} jobs of {len(jobs)} rules to run"
            return self.format(record)
        if event == LogEvent.JOB_FINISHED:
            match = _FINISHED.search(str(record.getMessage()))
            jobid = getattr(record, "job_id", None)
            start, label = self.started.pop(int(jobid), (None, "")) if jobid is not None else (None, "")
            rule = (match["rule"] if match else str(record.getMessage())) + label
            self.finished.append((rule, record.created - start if start is not None else None))
            return None
        if event == LogEvent.PROGRESS:
            done, total = int(record.done), int(record.total)
            self.width = max(self.width, len(str(total)))
            lines = []
            for rule, seconds in self.finished:
                took = f"{seconds:7.1f} s" if seconds is not None else " " * 9
                lines.append(f"[{done:>{self.width}}/{total} {100 * done / max(total, 1):3.0f}%] {took}  {rule}")
            self.finished.clear()
            return "\n".join(lines) or None
        if event is None and CHATTER.match(str(record.getMessage())):
            return None
        return self.format(record)
