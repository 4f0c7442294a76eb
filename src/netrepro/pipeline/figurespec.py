"""The per-paper figure list, from which the workflow generates one rule per figure.

Each paper package holds ``figures.yaml``: a mapping from figure id (``fig1``,
``figS2``, ...) to its plotting function, the tables it reads and the fixed
arguments of the plot::

    fig1:
      plot: figure_bounds              # a function of netrepro.papers.<slug>.figures
      inputs: {bounds: scalar_bounds}  # name -> <rule without the slug prefix>[.<output name>]
      params: {which: stable}          # optional
      layout:                          # which layout choices come from the paper, which are ours
        from_paper: "k from 0 to 60 (caption); linear axes (text)"
        ours: "y range 0 to 2: the axes are lost in extraction"

The generated rule is ``<slug>_<id>``; it writes ``figures/<slug>/<id>.png``. The figure's
caption is ``workflow/report/<slug>/<id>.rst`` (shown by the report, the notebook and
``snakemake --report``); figures.yaml holds no caption of its own.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

import yaml

from ..errors import ConfigError
from .io import load_yaml

__all__ = ["FigureSpec", "load_figure_specs", "figure_list_path"]

_SRC = Path(__file__).resolve().parents[1]  # the netrepro package
_FIGURE_ID = re.compile(r"^fig(S?\d+)$")
_KEYS = {"plot", "inputs", "params", "layout"}
# fields that entries may still carry and that nothing reads (removed once no figures.yaml has them)
_LAYOUT_KEYS = {"from_paper", "ours"}


@dataclass(frozen=True)
class FigureSpec:
    """One figure: its rule name, plotting function, input tables (rule, output) and parameters.

    Attributes
    ----------
    slug : str
        The paper.
    figure_id : str
        ``fig<n>`` (the paper's figure) or ``figS<n>`` (ours).
    plot : str
        The plotting function of ``netrepro.papers.<slug>.figures``.
    inputs : dict
        Input name -> ``<rule without the slug prefix>[.<output name>]``.
    params : dict
        Fixed arguments of the plot.
    layout : dict
        ``from_paper`` and ``ours``: which layout choices are the paper's.
    """

    slug: str
    figure_id: str
    plot: str
    inputs: dict = field(default_factory=dict)
    params: dict = field(default_factory=dict)
    layout: dict = field(default_factory=dict)

    @property
    def rule(self) -> str:
        """The generated rule's name, ``<slug>_<id>``."""
        return f"{self.slug}_{self.figure_id}"

    @property
    def path(self) -> str:
        """The figure file, ``figures/<slug>/<id>.png``."""
        return f"figures/{self.slug}/{self.figure_id}.png"

    @property
    def func(self) -> str:
        """The plotting function as ``module:function``."""
        return f"netrepro.papers.{self.slug}.figures:{self.plot}"

    def input_rules(self) -> dict[str, tuple[str, str]]:
        """The input tables as the outputs of the rules that write them.

        Returns
        -------
        dict
            ``{input name: (rule name, output name)}``.
        """
        resolved = {}
        for name, ref in self.inputs.items():
            rule, _, output = str(ref).partition(".")
            resolved[name] = (f"{self.slug}_{rule}", output or "table")
        return resolved


def figure_list_path(slug: str, src: Path = _SRC) -> Path:
    """The figure list of a paper.

    Parameters
    ----------
    slug : str
        The paper.
    src : Path
        The directory holding the package.

    Returns
    -------
    Path
        ``<src>/papers/<slug>/figures.yaml``.
    """
    return Path(src) / "papers" / slug / "figures.yaml"


def load_figure_specs(slug: str, src: Path = _SRC) -> list[FigureSpec]:
    """The figures of paper ``slug`` in their listed order.

    Parameters
    ----------
    slug : str
        The paper.
    src : Path
        The directory holding the package.

    Returns
    -------
    list of FigureSpec
        One per entry of the figure list.

    Raises
    ------
    ConfigError
        If the list is missing or an entry is malformed; the message names file, figure and field.
    """
    path = figure_list_path(slug, src)
    if not path.is_file():
        raise ConfigError(f"paper {slug!r} has no figure list {path}")
    data = load_yaml(path.read_text()) or {}
    if not isinstance(data, dict):
        raise ConfigError(f"{path}: expected a mapping of figure ids to entries, got {type(data).__name__}")
    specs = []
    for figure_id, entry in data.items():
        where = f"{path}: figure {figure_id!r}"
        if not _FIGURE_ID.match(str(figure_id)):
            raise ConfigError(f"{where}: ids look like fig1 or figS1")
        if not isinstance(entry, dict) or not isinstance(entry.get("plot"), str):
            raise ConfigError(f"{where}: field 'plot' (the plotting function's name) is required")
        unknown = set(entry) - _KEYS
        if unknown:
            raise ConfigError(f"{where}: unknown fields {sorted(unknown)} (allowed: {sorted(_KEYS)})")
        for name in ("inputs", "params", "layout"):
            if not isinstance(entry.get(name, {}), dict):
                raise ConfigError(f"{where}: field {name!r} must be a mapping")
        layout = entry.get("layout", {})
        if set(layout) - _LAYOUT_KEYS or not all(isinstance(v, str) for v in layout.values()):
            raise ConfigError(f"{where}: field 'layout' maps {sorted(_LAYOUT_KEYS)} to text, got {layout!r}")
        specs.append(FigureSpec(slug, str(figure_id), entry["plot"], dict(entry.get("inputs", {})),
                                dict(entry.get("params", {})), dict(layout)))
    return specs
