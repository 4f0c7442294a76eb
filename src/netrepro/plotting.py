"""Deterministic figure output: Agg backend, fixed style, no date or version stamps.

matplotlib is imported on first use, not with this module: the paper modules import it, and
the workflow imports every paper module at start-up to validate the configuration.
"""

from __future__ import annotations

from functools import lru_cache

from .io import atomic_path

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


@lru_cache(maxsize=None)
def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def new_figure(nrows=1, ncols=1, figsize=(6.4, 4.0), **kw):
    """A figure and axes under the project style."""
    plt = _pyplot()
    with plt.rc_context(STYLE):
        fig, axes = plt.subplots(nrows, ncols, figsize=figsize, **kw)
    return fig, axes


def save_figure(fig, path) -> None:
    """Save atomically as PNG without software/date metadata, then close the figure.

    Beside the PNG goes its data sidecar ``<name>.data.json`` (:mod:`netrepro.figuredata`):
    what the figure draws, the figure's reference for ``python -m netrepro.regression compare``.
    """
    from .figuredata import write_figure_data

    plt = _pyplot()
    with plt.rc_context(STYLE), atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", metadata={"Software": None}, bbox_inches="tight")
    write_figure_data(fig, path)
    plt.close(fig)
