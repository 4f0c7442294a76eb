"""Deterministic figure output: Agg backend, fixed style, no date or version stamps.

Colours for every reader (issue 41 item 2): the default colour cycle is the Okabe-Ito palette
(:data:`OKABE_ITO`, :data:`PALETTE`), distinguishable under the common colour vision
deficiencies, and the meanings drawn across the papers have one colour each in :data:`COLOURS`
(a bound, a simulation, the paper's value, ...). Where colour separates meanings, the figures
separate them by marker or line style too; ``tests/test_figure_colours.py`` checks every figure.

matplotlib is imported on first use, not with this module: the paper modules import it, and
the workflow imports every paper module at start-up to validate the configuration.
"""

from __future__ import annotations

from functools import lru_cache

from ..pipeline.io import atomic_path

__all__ = ["OKABE_ITO", "PALETTE", "COLOURS", "palette", "STYLE", "new_figure", "save_figure"]

# Okabe & Ito (2008), "Color Universal Design": eight colours told apart with any colour vision.
OKABE_ITO = {
    "orange": "#E69F00", "sky_blue": "#56B4E9", "bluish_green": "#009E73", "yellow": "#F0E442",
    "blue": "#0072B2", "vermillion": "#D55E00", "reddish_purple": "#CC79A7", "black": "#000000",
}

# The default colour cycle: the Okabe-Ito colours; the first four stay apart (CIEDE2000 >= 17)
# under simulated deuteranopia and protanopia, the later ones need a marker or line style besides
# (vermillion is close to orange, reddish purple to blue); yellow (low contrast on white) and
# black (kept for exact values and reference lines) last.
PALETTE = tuple(OKABE_ITO[c] for c in ("blue", "orange", "bluish_green", "sky_blue", "vermillion",
                                       "reddish_purple", "yellow", "black"))

# One colour per meaning, the same in every paper's figures.
COLOURS = {
    "exact": OKABE_ITO["black"],           # exact values, theorems' curves drawn as the truth
    "simulation": OKABE_ITO["blue"],       # Monte Carlo estimates and sample paths
    "paper": OKABE_ITO["vermillion"],      # values printed in the paper
    "reference": OKABE_ITO["reddish_purple"],  # reference values of other sources
    "upper_bound": OKABE_ITO["vermillion"],
    "lower_bound": OKABE_ITO["blue"],
    "bound": OKABE_ITO["vermillion"],      # a bound (one drawn alone)
    "estimate": OKABE_ITO["bluish_green"],  # an estimator's value
    "threshold": OKABE_ITO["orange"],      # necessary conditions, critical values
    "bounded": OKABE_ITO["blue"],          # stability verdicts
    "unbounded": OKABE_ITO["vermillion"],
    "undecided": "#BBBBBB",
    "neutral": "0.5",                      # guides: grid-like lines, omitted ranges
}


def palette(i: int) -> str:
    """The ``i``-th colour of the default cycle (``"C{i}"`` under the project style), wrapping around.

    Parameters
    ----------
    i : int
        The index into :data:`PALETTE`.

    Returns
    -------
    str
        The colour, ``#rrggbb``.
    """
    return PALETTE[int(i) % len(PALETTE)]


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


def _cycle():
    from cycler import cycler

    return cycler(color=list(PALETTE))


STYLE["axes.prop_cycle"] = _cycle()


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

    Beside the PNG goes its data sidecar ``<name>.data.json`` (:mod:`netrepro.figures.data`):
    what the figure draws, the figure's reference for ``python -m netrepro regression compare``.
    """
    from .data import write_figure_data

    plt = _pyplot()
    with plt.rc_context(STYLE), atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", metadata={"Software": None}, bbox_inches="tight")
    write_figure_data(fig, path)
    plt.close(fig)
