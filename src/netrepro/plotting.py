"""Deterministic figure output: Agg backend, fixed style, no date or version stamps."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from .io import atomic_path  # noqa: E402

__all__ = ["STYLE", "new_figure", "save_figure"]

STYLE = {
    "figure.dpi": 100,
    "savefig.dpi": 120,
    "font.size": 10,
    "axes.grid": True,
    "grid.alpha": 0.3,
    "axes.spines.top": False,
    "axes.spines.right": False,
    "legend.frameon": False,
    "svg.hashsalt": "netrepro",
    "path.simplify": False,
}


def new_figure(nrows=1, ncols=1, figsize=(6.4, 4.0), **kw):
    """A figure and axes under the project style."""
    with plt.rc_context(STYLE):
        fig, axes = plt.subplots(nrows, ncols, figsize=figsize, **kw)
    return fig, axes


def save_figure(fig, path) -> None:
    """Save atomically as PNG without software/date metadata, then close the figure."""
    with plt.rc_context(STYLE), atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", metadata={"Software": None}, bbox_inches="tight")
    plt.close(fig)
