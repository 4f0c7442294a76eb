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
"""

from __future__ import annotations

import importlib
import sys
import types

__all__ = ["import_cvxpy", "cp"]

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
