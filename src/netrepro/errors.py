"""The package's exceptions: one base class, so callers can catch every netrepro error at once.

Each subclass also derives from the built-in exception it refines (``ValueError`` for bad
input, ``RuntimeError`` for a failed computation), so existing ``except ValueError`` code
keeps working.
"""

from __future__ import annotations

__all__ = [
    "NetreproError",
    "ConfigError",
    "DependencyError",
    "InputError",
    "CorruptOutputError",
    "LMIError",
    "ModelError",
    "OrphanedJobError",
]


class NetreproError(Exception):
    """Base class of every error raised on purpose by netrepro."""


class ConfigError(NetreproError, ValueError):
    """The configuration (or a data file of a paper) is invalid; the message names key, value and expectation."""


class DependencyError(NetreproError, RuntimeError):
    """A required package is missing, broken or too old; the message says which and how to fix it."""


class InputError(NetreproError, ValueError):
    """A bad argument to a model or engine function; the message names the argument."""


class CorruptOutputError(NetreproError, RuntimeError):
    """A result file does not match the checksum recorded in its sidecar."""


class UnfinishedOutputError(CorruptOutputError):
    """A result file whose sidecar says its job has not finished (running, or interrupted)."""


class LMIError(NetreproError, RuntimeError):
    """An LMI problem could not be set up or solved as asked."""


class ModelError(NetreproError, RuntimeError):
    """A model's quantity does not exist for the given arguments (e.g. a filter below its attenuation level)."""


class OrphanedJobError(NetreproError, RuntimeError):
    """The Snakemake process that started a job is gone: the job stops without writing its outputs."""
