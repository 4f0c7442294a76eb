"""What a figure draws, as data: the figure's data sidecar and its comparison (issue 26).

:func:`describe_figure` walks a matplotlib figure with the artist API and returns, for every
axes (twin axes included, in the figure's order), its title and labels, scales and limits,
ticks' labels, legend entries, and every artist with its data: lines and markers
(``get_xydata``), scatter offsets and sizes (``get_offsets``), filled areas and bands
(``get_paths``), bars and other patches (their vertices), error bars (line collections),
images (their array), and texts. :func:`netrepro.plotting.save_figure` writes it beside the PNG
as ``<name>.data.json`` for every figure of the project, so a figure is checked by what it
shows, not only by its pixels.

:func:`compare_figure_data` compares two such descriptions with the tolerances of the result
tables (:data:`netrepro.regression.RTOL`, :data:`netrepro.regression.ATOL`): strings exactly
(numbers printed inside them with the numeric tolerance), arrays element-wise. Each difference
names the axes, the artist and the largest difference.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

__all__ = ["SUFFIX", "FORMAT", "data_path", "describe_figure", "write_figure_data", "compare_figure_data"]

SUFFIX = ".data.json"
FORMAT = 1


def data_path(png) -> Path:
    """The data sidecar of a figure: ``fig1.png`` -> ``fig1.data.json`` (same folder)."""
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
            "marker": str(line.get_marker()), "visible": bool(line.get_visible())}


def _collection(coll) -> dict:
    from matplotlib.collections import LineCollection, PathCollection, PolyCollection, QuadMesh

    out = {"kind": type(coll).__name__, "label": _label(coll), "visible": bool(coll.get_visible())}
    if isinstance(coll, QuadMesh):
        out["values"] = _array(coll.get_array())
        return out
    if isinstance(coll, PathCollection):  # scatter: positions and sizes
        out["offsets"] = _array(coll.get_offsets())
        out["sizes"] = _array(coll.get_sizes())
        if coll.get_array() is not None:
            out["values"] = _array(coll.get_array())
    elif isinstance(coll, (PolyCollection, LineCollection)):  # bands, fills, error bars, segments
        out["paths"] = [_array(p.vertices) for p in coll.get_paths()]
    else:
        out["paths"] = [_array(p.vertices) for p in coll.get_paths()]
        out["offsets"] = _array(coll.get_offsets())
    out["facecolor"] = _color(coll.get_facecolor())
    out["edgecolor"] = _color(coll.get_edgecolor())
    return out


def _patch(patch) -> dict:
    from matplotlib.patches import Rectangle

    out = {"kind": type(patch).__name__, "label": _label(patch), "facecolor": _color(patch.get_facecolor()),
           "visible": bool(patch.get_visible())}
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


def _axes(ax) -> dict:
    artists = []
    for child in ax.get_children():
        kind = type(child).__name__
        if child in (ax.title, ax._left_title, ax._right_title, ax.patch) or child is ax.legend_:
            continue
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
    """
    sup = fig._suptitle.get_text() if getattr(fig, "_suptitle", None) is not None else ""
    return {"format": FORMAT, "size_inches": _array(fig.get_size_inches()), "suptitle": sup,
            "legends": [_legend(leg) for leg in fig.legends],
            "texts": [_text(t) for t in fig.texts if t.get_text()],
            "axes": [_axes(ax) for ax in fig.axes]}


def write_figure_data(fig, png) -> Path:
    """Write ``describe_figure(fig)`` beside the PNG ``png`` (atomically); returns its path."""
    from .io import atomic_path

    target = data_path(png)
    text = json.dumps(describe_figure(fig), separators=(",", ":"), allow_nan=False)
    with atomic_path(target) as tmp:
        Path(tmp).write_text(text + "\n")
    return target


def _as_float(values) -> np.ndarray:
    """Nested lists of numbers (and "nan"/"inf" strings) as a float array; TypeError/ValueError if not numbers."""
    if isinstance(values, (list, tuple)) and any(isinstance(v, (dict, bool)) or v is None for v in values):
        raise TypeError("not numbers")
    a = np.asarray(values, dtype=object)
    if a.dtype != object or not a.size:
        return a.astype(float)
    flat = [float(v) for v in a.ravel().tolist()]  # "nan"/"inf" parse; other words raise ValueError
    return np.asarray(flat, dtype=float).reshape(a.shape)


def _name(ax_index: int, ax: dict) -> str:
    title = ax.get("title") or ax.get("ylabel") or ""
    return f"axes {ax_index}" + (f" ({title!r})" if title else "")


def _artist_name(i: int, artist: dict) -> str:
    label = artist.get("label") or artist.get("text")
    return f"{artist.get('kind')} {i}" + (f" {label!r}" if label else "")


def _compare_values(where: str, ref, got, rtol: float, atol: float, out: list) -> None:
    """Append a difference of two JSON values (dicts, lists of numbers or of strings, scalars)."""
    from .regression import _texts_agree

    if isinstance(ref, dict) and isinstance(got, dict):
        for key in sorted(set(ref) | set(got)):
            if key not in got or key not in ref:
                out.append(f"{where}: {key} {'missing' if key not in got else 'added'}")
            else:
                _compare_values(f"{where} {key}", ref[key], got[key], rtol, atol, out)
        return
    if isinstance(ref, str) or isinstance(got, str) or ref is None or got is None or isinstance(ref, bool):
        if isinstance(ref, str) and isinstance(got, str) and ref in ("nan", "inf", "-inf") and got == ref:
            return
        if isinstance(ref, str) and isinstance(got, str):
            if not _texts_agree(ref, got, rtol, atol):
                out.append(f"{where}: {got!r}, reference {ref!r}")
        elif ref != got:
            out.append(f"{where}: {got!r}, reference {ref!r}")
        return
    try:
        a, b = _as_float(ref), _as_float(got)
    except (TypeError, ValueError):  # lists of strings (legend entries, tick labels) or of dicts
        if isinstance(ref, list) and isinstance(got, list):
            if len(ref) != len(got):
                out.append(f"{where}: {len(got)} items, reference {len(ref)}: {got!r} vs reference {ref!r}"
                           if all(isinstance(x, str) for x in ref + got) else
                           f"{where}: {len(got)} items, reference {len(ref)}")
                return
            for i, (r, g) in enumerate(zip(ref, got)):
                _compare_values(f"{where}[{i}]", r, g, rtol, atol, out)
        else:
            out.append(f"{where}: {got!r}, reference {ref!r}")
        return
    if a.shape != b.shape:
        out.append(f"{where}: shape {b.shape}, reference {a.shape}")
        return
    ok = np.isclose(a, b, rtol=rtol, atol=atol, equal_nan=True) | (np.isinf(a) & (a == b))
    if not ok.all():
        with np.errstate(invalid="ignore"):
            err = np.where(ok, 0.0, np.abs(a - b))
        err = np.where(np.isnan(err), np.inf, err)
        j = np.unravel_index(int(np.argmax(err)), a.shape)
        rel = err[j] / abs(a[j]) if a[j] not in (0.0,) and np.isfinite(a[j]) else float("inf")
        out.append(f"{where}: {int((~ok).sum())} of {a.size} values differ, largest at {list(map(int, j))}: "
                   f"{b[j]!r} vs reference {a[j]!r} (abs {err[j]:.3g}, rel {rel:.3g})")


def compare_figure_data(reference: dict, result: dict, rtol: float | None = None,
                        atol: float | None = None) -> list[str]:
    """Differences between two figure descriptions (empty when they agree), one string each.

    Each names the axes (index and title) and the artist (kind, index, label) and gives the
    largest difference. Default tolerances: those of the result tables.
    """
    from .regression import ATOL, RTOL

    rtol = RTOL if rtol is None else rtol
    atol = ATOL if atol is None else atol
    out: list[str] = []
    top_ref = {k: v for k, v in reference.items() if k != "axes"}
    top_got = {k: v for k, v in result.items() if k != "axes"}
    _compare_values("figure", top_ref, top_got, rtol, atol, out)
    ra, ga = reference.get("axes", []), result.get("axes", [])
    if len(ra) != len(ga):
        out.append(f"figure: {len(ga)} axes, reference {len(ra)}")
    for k, (rax, gax) in enumerate(zip(ra, ga)):
        where = _name(k, rax)
        props_r = {key: v for key, v in rax.items() if key != "artists"}
        props_g = {key: v for key, v in gax.items() if key != "artists"}
        _compare_values(where, props_r, props_g, rtol, atol, out)
        rart, gart = rax.get("artists", []), gax.get("artists", [])
        if len(rart) != len(gart):
            names_r = [_artist_name(i, a) for i, a in enumerate(rart)]
            names_g = [_artist_name(i, a) for i, a in enumerate(gart)]
            extra = [n for n in names_g if n not in names_r]
            gone = [n for n in names_r if n not in names_g]
            out.append(f"{where}: {len(gart)} artists, reference {len(rart)}"
                       + (f"; new: {', '.join(extra)}" if extra else "")
                       + (f"; gone: {', '.join(gone)}" if gone else ""))
            continue
        for i, (r, g) in enumerate(zip(rart, gart)):
            _compare_values(f"{where} {_artist_name(i, r)}", r, g, rtol, atol, out)
    return out
