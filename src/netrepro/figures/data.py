"""What a figure draws, as data: the figure's data sidecar and its comparison (issue 26).

:func:`describe_figure` walks a matplotlib figure with the artist API and returns, for every
axes (twin axes included, in the figure's order), its title and labels, scales and limits,
ticks' labels, legend entries, and every artist with its data: lines and markers
(``get_xydata``), scatter offsets, sizes and marker (``get_offsets``), filled areas and bands
(``get_paths``), bars and other patches (their vertices and hatch), error bars (line
collections), images (their array), and texts; with their colours, line styles and markers, and
for the artists of a labelled bar or error-bar container that label (``container``), so a test
can check what tells the legend entries apart (``tests/test_figure_colours.py``). :func:`netrepro.figures.plotting.save_figure` writes it beside the PNG
as ``<name>.data.json`` for every figure of the project, so a figure is checked by what it
shows, not only by its pixels.

The comparison lives in :mod:`netrepro.figures.check`. This module imports nothing of the
project but :mod:`netrepro.pipeline.io`: it is a code dependency of every figure rule, so an edit to the
comparison must not rerun the figures.
"""

from __future__ import annotations

import json
from functools import lru_cache
from pathlib import Path

import numpy as np

from ..pipeline.io import atomic_path

__all__ = ["SUFFIX", "FORMAT", "data_path", "describe_figure", "write_figure_data"]

SUFFIX = ".data.json"
FORMAT = 1


def data_path(png) -> Path:
    """The data sidecar of a figure: ``fig1.png`` -> ``fig1.data.json`` (same folder).

    Parameters
    ----------
    png : str or pathlib.Path
        The figure's PNG file.

    Returns
    -------
    pathlib.Path
        The sidecar's path, beside the PNG.
    """
    png = Path(png)
    return png.with_name(png.stem + SUFFIX)


def _array(values) -> list:
    """A float array as nested lists (NaN/inf kept as strings JSON can hold; masked -> NaN)."""
    a = np.ma.filled(np.ma.asarray(values, dtype=float), np.nan)
    a = np.asarray(a, dtype=float)
    if a.size and not np.isfinite(a).all():
        return _nonfinite(a)
    return a.tolist()


def _nonfinite(a: np.ndarray) -> list:
    """Nested lists with NaN/inf written as the strings "nan", "inf", "-inf" (valid JSON)."""
    out = a.astype(object)
    out[np.isnan(a)] = "nan"
    out[np.isposinf(a)] = "inf"
    out[np.isneginf(a)] = "-inf"
    return out.tolist()


def _color(c) -> str | None:
    """A colour (or the distinct colours of an array of them) as ``#rrggbbaa``, sorted and joined."""
    from matplotlib.colors import to_hex, to_rgba_array

    try:
        arr = to_rgba_array(c)
    except (TypeError, ValueError):
        return None
    if len(arr) == 0:
        return None
    return ",".join(sorted({to_hex(row, keep_alpha=True) for row in arr}))


def _label(artist) -> str | None:
    label = artist.get_label()
    return None if label is None or str(label).startswith("_") else str(label)


def _text(t) -> dict:
    return {"text": t.get_text(), "xy": _array(t.get_position())}


def _line(line) -> dict:
    return {"kind": "line", "label": _label(line), "xy": _array(line.get_xydata()),
            "color": _color(line.get_color()), "linestyle": str(line.get_linestyle()),
            "marker": str(line.get_marker()), "linewidth": float(line.get_linewidth()),
            "markersize": float(line.get_markersize()), "visible": bool(line.get_visible())}


@lru_cache(maxsize=None)
def _marker_paths() -> tuple:
    """``(name, vertices, codes)`` of every marker matplotlib names, as ``scatter`` draws it."""
    from matplotlib.markers import MarkerStyle

    out = []
    for name in MarkerStyle.markers:
        if name in ("", " ", "None", "none", None):
            continue
        style = MarkerStyle(name)
        path = style.get_path().transformed(style.get_transform())
        out.append((str(name), np.asarray(path.vertices, dtype=float),
                    None if path.codes is None else tuple(path.codes)))
    return tuple(out)


def _scatter_marker(coll) -> str | None:
    """The marker a scatter draws (matplotlib's name for it), or None when it is not a named marker."""
    paths = coll.get_paths()
    if len(paths) != 1:
        return None
    vertices = np.asarray(paths[0].vertices, dtype=float)
    codes = None if paths[0].codes is None else tuple(paths[0].codes)
    for name, v, c in _marker_paths():
        if v.shape == vertices.shape and c == codes and np.allclose(v, vertices, atol=1e-9):
            return name
    return None


def _collection(coll) -> dict:
    from matplotlib.collections import LineCollection, PathCollection, PolyCollection, QuadMesh

    out = {"kind": type(coll).__name__, "label": _label(coll), "visible": bool(coll.get_visible())}
    if isinstance(coll, QuadMesh):
        out["values"] = _array(coll.get_array())
        return out
    if isinstance(coll, PathCollection):  # scatter: positions and sizes
        out["offsets"] = _array(coll.get_offsets())
        out["sizes"] = _array(coll.get_sizes())
        out["marker"] = _scatter_marker(coll)
        if coll.get_array() is not None:
            out["values"] = _array(coll.get_array())
    elif isinstance(coll, (PolyCollection, LineCollection)):  # bands, fills, error bars, segments
        out["paths"] = [_array(p.vertices) for p in coll.get_paths()]
    else:
        out["paths"] = [_array(p.vertices) for p in coll.get_paths()]
        out["offsets"] = _array(coll.get_offsets())
    out["facecolor"] = _color(coll.get_facecolor())
    out["edgecolor"] = _color(coll.get_edgecolor())
    out["hatch"] = None if coll.get_hatch() is None else str(coll.get_hatch())
    return out


def _patch(patch) -> dict:
    from matplotlib.patches import Rectangle

    out = {"kind": type(patch).__name__, "label": _label(patch), "facecolor": _color(patch.get_facecolor()),
           "hatch": None if patch.get_hatch() is None else str(patch.get_hatch()), "visible": bool(patch.get_visible())}
    if isinstance(patch, Rectangle):  # bars, axvspan in data coordinates
        out["xywh"] = _array([patch.get_x(), patch.get_y(), patch.get_width(), patch.get_height()])
    else:
        out["vertices"] = _array(patch.get_path().vertices if patch.get_transform() is None
                                 else patch.get_path().transformed(patch.get_patch_transform()).vertices)
    return out


def _image(im) -> dict:
    return {"kind": "image", "label": _label(im), "array": _array(im.get_array()),
            "extent": _array(im.get_extent()), "cmap": im.get_cmap().name, "clim": _array(im.get_clim())}


def _legend(legend) -> dict | None:
    if legend is None:
        return None
    return {"title": legend.get_title().get_text(), "entries": [t.get_text() for t in legend.get_texts()],
            "visible": bool(legend.get_visible())}


def _container_labels(ax) -> dict:
    """``id(artist) -> label`` of the containers (bars, error bars, stems) whose artists carry no label."""
    out = {}
    for container in ax.containers:
        label = _label(container)
        if label is None:
            continue
        stack = list(container)
        while stack:
            item = stack.pop()
            if item is None:
                continue
            if isinstance(item, (list, tuple)):
                stack.extend(item)
            else:
                out[id(item)] = label
    return out


def _axes(ax) -> dict:
    artists = []
    containers = _container_labels(ax)
    for child in ax.get_children():
        kind = type(child).__name__
        if child in (ax.title, ax._left_title, ax._right_title, ax.patch) or child is ax.legend_:
            continue
        start = len(artists)
        if hasattr(child, "get_xydata") and kind == "Line2D":
            artists.append(_line(child))
        elif hasattr(child, "get_paths") and hasattr(child, "get_offsets"):
            artists.append(_collection(child))
        elif kind == "AxesImage":
            artists.append(_image(child))
        elif hasattr(child, "get_path") and kind not in ("Spine",) and child.axes is ax and \
                hasattr(child, "get_facecolor") and kind != "Annotation":
            artists.append(_patch(child))
        elif kind in ("Text", "Annotation") and child.get_text():
            artists.append({"kind": "text", **_text(child)})
        if len(artists) > start and id(child) in containers and artists[-1].get("label") is None:
            artists[-1]["container"] = containers[id(child)]  # the legend entry it belongs to
    twins = [i for i, other in enumerate(ax.figure.axes)
             if other is not ax and (ax.get_shared_x_axes().joined(ax, other) or
                                     ax.get_shared_y_axes().joined(ax, other)) and
             other.get_position().bounds == ax.get_position().bounds]
    return {
        "title": " | ".join(t for t in (ax._left_title.get_text(), ax.title.get_text(),
                                         ax._right_title.get_text()) if t),
        "xlabel": ax.get_xlabel(), "ylabel": ax.get_ylabel(),
        "xscale": ax.get_xscale(), "yscale": ax.get_yscale(),
        "xlim": _array(ax.get_xlim()), "ylim": _array(ax.get_ylim()),
        "xticklabels": [t.get_text() for t in ax.get_xticklabels()],
        "yticklabels": [t.get_text() for t in ax.get_yticklabels()],
        "twin_of": twins, "visible": bool(ax.get_visible()),
        "legend": _legend(ax.get_legend()),
        "artists": artists,
    }


def describe_figure(fig) -> dict:
    """What ``fig`` draws, as JSON-ready data (call after drawing, e.g. after ``savefig``).

    Returns ``{"format", "suptitle", "legends", "axes": [...]}`` with one entry per axes of
    ``fig.axes`` (twin axes and colour bars are axes too); see the module docstring.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The drawn figure.

    Returns
    -------
    dict
        ``format``, ``size_inches``, ``suptitle``, ``legends``, ``texts`` and ``axes`` (one
        description per axes: limits, labels, ticks, legend and artists).
    """
    sup = fig._suptitle.get_text() if getattr(fig, "_suptitle", None) is not None else ""
    return {"format": FORMAT, "size_inches": _array(fig.get_size_inches()), "suptitle": sup,
            "legends": [_legend(leg) for leg in fig.legends],
            "texts": [_text(t) for t in fig.texts if t.get_text()],
            "axes": [_axes(ax) for ax in fig.axes]}


def write_figure_data(fig, png) -> Path:
    """Write ``describe_figure(fig)`` beside the PNG ``png`` (atomically); returns its path.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The drawn figure.
    png : str or pathlib.Path
        The figure's PNG file; the sidecar is :func:`data_path` of it.

    Returns
    -------
    pathlib.Path
        The data sidecar written.
    """
    target = data_path(png)
    text = json.dumps(describe_figure(fig), separators=(",", ":"), allow_nan=False)
    with atomic_path(target) as tmp:
        Path(tmp).write_text(text + "\n")
    return target
