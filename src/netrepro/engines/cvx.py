"""cvxpy, imported without the scipy.stats import it makes for one atom netrepro never evaluates.

``import cvxpy`` imports every atom; ``cvxpy.atoms.quantum_rel_entr`` runs
``from scipy.stats import entropy`` at import time (for the numeric value of that atom only), and
importing ``scipy.stats`` costs ~0.4 CPU s of cvxpy's ~0.55 s on top of numpy, pandas and
scipy.sparse/linalg (cvxpy 1.9.3, scipy 1.17.1; measured here, median of 3). Every pipeline job
that solves an LMI pays it once, and none of them uses scipy.stats.

:func:`import_cvxpy` imports cvxpy with a stand-in for ``scipy.stats`` in ``sys.modules`` for the
duration of the import: its ``entropy`` is a function that imports the real ``scipy.stats`` and
calls its ``entropy`` on first use, and any other attribute read loads the real module at once and
forwards to it. After the import the stand-in is removed, so a later ``import scipy.stats`` gets
the real module. Nothing in cvxpy is changed: the same modules, canonicalisation and solver
data (only the moment scipy.stats is imported moves, to never when no caller needs it). If
scipy.stats or cvxpy is already imported, this is plain ``import cvxpy``.

Every module of netrepro that needs cvxpy imports it through this module (``from
..engines.cvx import cp``), so the first import in a process is the deferred one.

Every solve goes through :func:`solve_problem`, which counts the solver's statuses for the step's
provenance (:func:`solver_statuses`; the runner writes them into the sidecars and warns when a
solve did not end ``optimal``) and applies the fault-injection cap ``NETREPRO_SOLVER_MAX_ITER``
(an environment variable, for tests only: a crippled solver must make verdicts ``undecided``,
never ``differs``; issue 37).
"""

from __future__ import annotations

import collections
import importlib
import os
import sys
import types

__all__ = ["import_cvxpy", "cp", "SOLVER", "FAULT_MAX_ITER", "solver_options", "solve_problem", "record_status",
           "solver_statuses", "clarabel_settings", "record_decision", "certified_decisions"]

SOLVER = "CLARABEL"
# fault injection (tests only): caps the solver's iterations in every solve of the process
FAULT_MAX_ITER = "NETREPRO_SOLVER_MAX_ITER"
# statuses of the solves of this process (one step per process): read by the runner for the provenance
_STATUSES: collections.Counter = collections.Counter()
# verdicts of the certificates of this process (feasible / infeasible / undecided)
_DECISIONS: collections.Counter = collections.Counter()

_STATS = "scipy.stats"


class _DeferredStats(types.ModuleType):
    """Stand-in for ``scipy.stats`` while cvxpy is imported (see the module docstring)."""

    def __getattr__(self, name):
        if name.startswith("__"):
            raise AttributeError(name)
        return getattr(_real_stats(), name)


def _real_stats():
    """The real ``scipy.stats`` (imported now if needed; a stand-in in ``sys.modules`` is dropped first)."""
    if isinstance(sys.modules.get(_STATS), _DeferredStats):
        del sys.modules[_STATS]
    return importlib.import_module(_STATS)


def _entropy(*args, **kwargs):
    """``scipy.stats.entropy`` (cvxpy's quantum relative entropy atom's numeric value), imported on first call."""
    return _real_stats().entropy(*args, **kwargs)


def import_cvxpy():
    """The ``cvxpy`` module, imported without importing ``scipy.stats`` (see the module docstring).

    Returns
    -------
    module
        ``cvxpy``.
    """
    if "cvxpy" in sys.modules or _STATS in sys.modules:
        return importlib.import_module("cvxpy")
    stand_in = _DeferredStats(_STATS, "Stand-in for scipy.stats while cvxpy is imported (netrepro.engines.cvx).")
    stand_in.entropy = _entropy
    sys.modules[_STATS] = stand_in
    try:
        return importlib.import_module("cvxpy")
    finally:
        if sys.modules.get(_STATS) is stand_in:
            del sys.modules[_STATS]


cp = import_cvxpy()


def _iteration_cap() -> int | None:
    """The injected iteration cap, or None (no cap: the solver's own defaults)."""
    text = os.environ.get(FAULT_MAX_ITER, "").strip()
    if not text:
        return None
    try:
        cap = int(text)
    except ValueError:
        raise ValueError(f"{FAULT_MAX_ITER}={text!r} must be a positive integer") from None
    if cap < 1:
        raise ValueError(f"{FAULT_MAX_ITER}={text!r} must be a positive integer")
    return cap


def solver_options(**extra) -> dict:
    """Keyword arguments of ``Problem.solve``: the project's solver, the injected cap if any, ``extra``.

    Parameters
    ----------
    **extra
        Further options (override the defaults).

    Returns
    -------
    dict
        ``{"solver": SOLVER, ["max_iter": cap], **extra}``.
    """
    options = {"solver": SOLVER}
    cap = _iteration_cap()
    if cap is not None:
        options["max_iter"] = cap
    options.update(extra)
    return options


def record_status(status: str) -> None:
    """Count one solve's status (see :func:`solver_statuses`).

    Parameters
    ----------
    status : str
        The solver's status, e.g. ``optimal``, ``optimal_inaccurate``, ``solver_error``.
    """
    _STATUSES[str(status).split(":")[0]] += 1


def solve_problem(problem, **extra) -> str:
    """Solve a cvxpy problem with :func:`solver_options` and count its status.

    Parameters
    ----------
    problem : cvxpy.Problem
        The problem.
    **extra
        Further options of ``Problem.solve``.

    Returns
    -------
    str
        The problem's status.

    Raises
    ------
    cvxpy.error.SolverError
        As ``Problem.solve`` (counted as ``solver_error`` first).
    """
    try:
        problem.solve(**solver_options(**extra))
    except cp.error.SolverError:
        record_status("solver_error")
        raise
    record_status(problem.status)
    return str(problem.status)


def clarabel_settings(settings):
    """Clarabel settings with the injected iteration cap applied (for direct Clarabel solves).

    Parameters
    ----------
    settings : clarabel.DefaultSettings
        Settings to modify in place.

    Returns
    -------
    clarabel.DefaultSettings
        The same object.
    """
    cap = _iteration_cap()
    if cap is not None:
        settings.max_iter = cap
    return settings


def solver_statuses() -> dict:
    """``{status: count}`` of the solves of this process so far (empty when nothing was solved).

    Returns
    -------
    dict
        Sorted by status.
    """
    return dict(sorted(_STATUSES.items()))


def record_decision(verdict: str) -> None:
    """Count one certified verdict (``feasible``, ``infeasible`` or ``undecided``).

    Parameters
    ----------
    verdict : str
        The certificate's verdict.
    """
    _DECISIONS[str(verdict)] += 1


def certified_decisions() -> dict:
    """``{verdict: count}`` of the certificates of this process so far.

    Returns
    -------
    dict
        Sorted by verdict.
    """
    return dict(sorted(_DECISIONS.items()))
