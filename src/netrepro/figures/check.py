"""Figures that are checked: compare every figure with its committed reference (issue 26).

Each figure ``figures/<paper>/<id>.png`` has a data sidecar ``<id>.data.json``
(:mod:`netrepro.figures.data`, written by :func:`netrepro.figures.plotting.save_figure`). Both are
committed; the committed versions are the references. :func:`compare_figures` checks, for
every figure:

1. **what it shows**: the data sidecar against the reference sidecar, with the tolerances of
   the result tables (:data:`netrepro.judging.regression.RTOL`, :data:`netrepro.judging.regression.ATOL`).
   A changed curve, point, band, bar, label, legend entry, limit or scale is a difference
   naming the axes, the artist and the largest difference;
2. **its pixels**: identical bytes pass; otherwise the RMS of the pixel difference
   (``matplotlib.testing.compare.calculate_rms``, the measure of ``compare_images``) must be at
   most :data:`RMS_TOLERANCE`, and the image size must be the same;
3. **the set of figures**: a missing figure, a figure without a reference, or a missing data
   sidecar is a difference.

The references are read from a git revision (``git:HEAD``, the default: what is committed) or
from a folder laid out like ``figures/``. :func:`write_difference_page` writes the HTML page
a person reads: per drifted figure the reference, the new image, their pixel difference and the
data differences; per drifted table its differing cells.

Figures whose pixels legitimately differ between machines (while what they show agrees within
the tolerances) are listed with their reason in ``tests/platform_dependent.yaml`` as
``{figure: <paper>/<id>, check: data, reason: ...}``: for them a pixel difference beyond the
tolerance is reported but does not fail.
"""

from __future__ import annotations

import html
import json
import re
import shlex
import subprocess
import sys
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .data import SUFFIX, data_path
from ..pipeline.io import atomic_path

__all__ = ["RMS_TOLERANCE", "FigureDifference", "Baseline", "open_baseline", "compare_figure_data", "clear_difference_page",
           "png_rms", "compare_figures", "load_figure_rules", "write_difference_page", "figure_jobs",
           "regenerate_figures"]

# Pixel tolerance, on the RMS of the difference of two RGB images (0..255 per channel, over all
# pixels; matplotlib's calculate_rms, as compare_images), fixed from measurements on this
# project's 32 figures (issue 26, Nov 2026; each "edit" a one-line change of markov/figures.py):
#   harmless: the same build on two x86-64 machines (results equal within the table tolerances,
#     last bits differ): gainsched fig1 0.016, fig2 0.0038, figS1 0.0061 (<= 320 pixels, each by
#     one or two grey levels); the same machine twice: 0 (identical bytes, run to run).
#   changes only the pixels show (not in the data sidecar): one marker 10 -> 11 pt (fig2) 1.18;
#     the median's line width 1 -> 1.1 (fig3) 3.1; legend font 6.5 -> 7 pt (fig3) 19.7.
#   changes of what is drawn, for comparison: a dropped legend entry 4.8; the exact curve doubled
#     10 to 33; a log axis made symlog 26 to 39; but one scatter point moved by 1 % 0.0 (sub-pixel)
#     and one band point moved by 1 % 0.017 to 0.059: pixels cannot separate those from the
#     harmless differences, the data sidecar catches them (rtol 1e-6).
#   another freetype hinting (text.hinting "no_hinting"): 7 to 30 and often another image size;
#     the locked matplotlib wheel ships its own freetype, so this does not occur between machines
#     that install the lock, and a change of text rendering is worth a look.
# 0.1 is six times the largest harmless difference and a tenth of the smallest pixel-only change.
RMS_TOLERANCE = 0.1

# A figure's platform rule (tests/platform_dependent.yaml): `finite` compares the numbers of the
# artists it selects (and the limits of the axes it names) by shape and NaN/inf pattern only, as
# the table rule of the values they plot; `pixels` lets the PNG differ beyond the RMS tolerance
# when what the figure shows agrees (data compared in full).
_FIGURE_CHECKS = ("finite", "pixels")


@dataclass
class FigureDifference:
    """A figure that differs from its reference: its name, the reasons, and the images.

    Parameters
    ----------
    name : str
        The figure, ``"<paper>/<id>"``.
    problems : list of str, optional
        The failing differences, one line each (empty: only notes).
    notes : list of str, optional
        Differences reported but not failing (allowed by a platform rule).
    rms : float or None, optional
        The RMS of the pixel difference (:func:`png_rms`); None when not computed or the image
        sizes differ.
    reference_png : bytes or None, optional
        The committed reference PNG; None when there is none.
    result_png : pathlib.Path or None, optional
        The PNG of this build; None when it is missing.
    """

    name: str                     # "<paper>/<id>"
    problems: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)   # reported, not failing (platform rule)
    rms: float | None = None
    reference_png: bytes | None = None
    result_png: Path | None = None


class Baseline:
    """The committed references: a folder laid out like ``figures/``, or a git revision.

    A revision's files are listed at once and read together on first use (one
    ``git cat-file --batch``).

    Parameters
    ----------
    spec : str
        ``"git:REV"`` (``"git:"`` for ``HEAD``) to read the references from that revision of the
        ``figures_dir`` of the surrounding checkout, or a folder laid out like ``figures/``.
    figures_dir : pathlib.Path
        The figures folder of the build (for a revision: the path whose committed files are read).

    Raises
    ------
    ValueError
        When ``spec`` names a revision outside a git checkout or one git cannot list, or a folder
        that does not exist.
    """

    def __init__(self, spec: str, figures_dir: Path):
        self.spec = spec
        self.figures_dir = Path(figures_dir)
        self._git = None
        if spec.startswith("git:"):
            rev = spec[4:] or "HEAD"
            top = subprocess.run(["git", "rev-parse", "--show-toplevel"], cwd=self.figures_dir.parent,
                                 capture_output=True, text=True)
            if top.returncode != 0:
                raise ValueError(f"figure references {spec!r} need a git checkout around {self.figures_dir} "
                                 f"({top.stderr.strip()}); pass --figure-reference DIR instead")
            self._top = Path(top.stdout.strip())
            prefix = self.figures_dir.resolve().relative_to(self._top.resolve()).as_posix()
            listing = subprocess.run(["git", "ls-tree", "-r", "--name-only", rev, "--", prefix + "/"],
                                     cwd=self._top, capture_output=True, text=True)
            if listing.returncode != 0:
                raise ValueError(f"figure references {spec!r}: {listing.stderr.strip()}")
            self._git = (rev, prefix)
            self._files = {p[len(prefix) + 1:] for p in listing.stdout.splitlines()}
        else:
            root = Path(spec)
            if not root.is_dir():
                raise ValueError(f"figure references {spec!r}: not a folder")
            self._root = root
            self._files = {p.relative_to(root).as_posix() for p in root.rglob("*") if p.is_file()}
        self._cache: dict[str, bytes] = {}

    def figures(self) -> set[str]:
        """``<paper>/<id>`` of every reference figure (a PNG or a data sidecar)."""
        names = {f[:-4] for f in self._files if f.endswith(".png")}
        names |= {f[: -len(SUFFIX)] for f in self._files if f.endswith(SUFFIX)}
        return names

    def read(self, rel: str) -> bytes | None:
        if rel not in self._files:
            return None
        if self._git is None:
            return (self._root / rel).read_bytes()
        if not self._cache:
            self._load_all()
        return self._cache.get(rel)

    def _load_all(self) -> None:
        """Read every reference blob with one ``git cat-file --batch`` (seconds, not minutes)."""
        rev, prefix = self._git
        names = sorted(self._files)
        query = "".join(f"{rev}:{prefix}/{n}\n" for n in names).encode()
        out = subprocess.run(["git", "cat-file", "--batch"], cwd=self._top, input=query,
                             capture_output=True, check=True).stdout
        buf = _bytes_io(out)
        for name in names:
            header = buf.readline().split()
            if len(header) < 3 or header[1] == b"missing":
                continue
            self._cache[name] = buf.read(int(header[2]))
            buf.read(1)


def open_baseline(spec: str, figures_dir) -> Baseline:
    """The references named by ``spec`` (``git:REV`` or a folder) for the figures in ``figures_dir``.

    Parameters
    ----------
    spec : str
        ``"git:REV"`` or a folder laid out like ``figures/`` (see :class:`Baseline`).
    figures_dir : str or pathlib.Path
        The figures folder of the build.

    Returns
    -------
    Baseline
        The references.

    Raises
    ------
    ValueError
        When ``spec`` cannot be read (see :class:`Baseline`).
    """
    return Baseline(spec, Path(figures_dir))


def load_figure_rules(path) -> dict[str, list[dict]]:
    """``<paper>/<id> -> [rule, ...]`` for the figure entries of ``tests/platform_dependent.yaml``.

    An entry: ``figure``, ``check`` (``finite`` or ``pixels``), ``reason``; for ``finite``,
    ``artists`` (labels, or ``"<axes>:<artist>"`` indices into the sidecar) and optionally
    ``limits`` (axes indices whose limits follow those artists).

    Parameters
    ----------
    path : str or pathlib.Path or None
        The platform rules file; entries without ``figure`` (table rules) are skipped.

    Returns
    -------
    dict of str to list of dict
        Each figure's rules, in the file's order; empty when ``path`` is None or not a file.

    Raises
    ------
    ValueError
        When a figure entry lacks a valid ``check``, a ``reason``, or (for ``finite``) ``artists``.
    """
    import yaml

    if path is None or not Path(path).is_file():
        return {}
    rules = {}
    for i, rule in enumerate(yaml.safe_load(Path(path).read_text()) or []):
        if "figure" not in rule:
            continue
        if rule.get("check") not in _FIGURE_CHECKS or not str(rule.get("reason", "")).strip() or \
                (rule["check"] == "finite" and not rule.get("artists")):
            raise ValueError(f"{path}: entry {i} (figure {rule.get('figure')}): needs check "
                             f"(one of {', '.join(_FIGURE_CHECKS)}), reason, and artists for finite; "
                             f"got {sorted(rule)}")
        rules.setdefault(rule["figure"], []).append(rule)
    return rules


# ----------------------------------------------------------------------------- what a figure shows
def _as_float(values) -> np.ndarray:
    """Nested lists of numbers (and "nan"/"inf" strings) as a float array; TypeError/ValueError if not numbers."""
    if isinstance(values, (list, tuple)) and any(isinstance(v, (dict, bool)) or v is None for v in values):
        raise TypeError("not numbers")
    a = np.asarray(values, dtype=object)
    if a.dtype != object or not a.size:
        return a.astype(float)
    flat = [float(v) for v in a.ravel().tolist()]  # "nan"/"inf" parse; other words raise ValueError
    return np.asarray(flat, dtype=float).reshape(a.shape)


def _axes_name(index: int, ax: dict) -> str:
    title = ax.get("title") or ax.get("ylabel") or ""
    return f"axes {index}" + (f" ({title!r})" if title else "")


def _artist_name(index: int, artist: dict) -> str:
    label = artist.get("label") or artist.get("text")
    return f"{artist.get('kind')} {index}" + (f" {label!r}" if label else "")


def _compare_values(where: str, ref, got, rtol: float, atol: float, out: list, finite: bool = False) -> None:
    """Append the differences of two JSON values (dicts, lists of numbers or of strings, scalars).

    ``finite``: numbers are compared by shape and NaN/inf pattern only (a platform rule).
    """
    from ..judging.regression import texts_agree

    if isinstance(ref, dict) and isinstance(got, dict):
        for key in sorted(set(ref) | set(got)):
            if key not in got or key not in ref:
                out.append(f"{where}: {key} {'missing' if key not in got else 'added'}")
            else:
                _compare_values(f"{where} {key}", ref[key], got[key], rtol, atol, out, finite)
        return
    if isinstance(ref, (str, bool)) or isinstance(got, (str, bool)) or ref is None or got is None:
        if isinstance(ref, str) and isinstance(got, str):
            if not texts_agree(ref, got, rtol, atol):
                out.append(f"{where}: {got!r}, reference {ref!r}")
        elif ref != got:
            out.append(f"{where}: {got!r}, reference {ref!r}")
        return
    try:
        a, b = _as_float(ref), _as_float(got)
    except (TypeError, ValueError):  # lists of strings (legend entries, tick labels) or of arrays
        if isinstance(ref, list) and isinstance(got, list):
            if len(ref) != len(got):
                words = all(isinstance(x, str) for x in ref + got)
                out.append(f"{where}: {len(got)} items, reference {len(ref)}"
                           + (f"; new: {[x for x in got if x not in ref]}, gone: {[x for x in ref if x not in got]}"
                              if words else ""))
                return
            for i, (r, g) in enumerate(zip(ref, got)):
                _compare_values(f"{where}[{i}]", r, g, rtol, atol, out, finite)
        else:
            out.append(f"{where}: {got!r}, reference {ref!r}")
        return
    if a.shape != b.shape:
        out.append(f"{where}: shape {b.shape}, reference {a.shape}")
        return
    if finite:
        ok = (np.isnan(a) == np.isnan(b)) & (np.isposinf(a) == np.isposinf(b)) & (np.isneginf(a) == np.isneginf(b))
    else:
        ok = np.isclose(a, b, rtol=rtol, atol=atol, equal_nan=True) | (np.isinf(a) & (a == b))
    if not ok.all():
        with np.errstate(invalid="ignore"):
            err = np.where(ok, 0.0, np.abs(a - b))
        err = np.where(np.isnan(err), np.inf, err)
        j = np.unravel_index(int(np.argmax(err)), a.shape)
        rel = err[j] / abs(a[j]) if a[j] != 0 and np.isfinite(a[j]) else float("inf")
        out.append(f"{where}: {int((~ok).sum())} of {a.size} values differ, largest at {list(map(int, j))}: "
                   f"{float(b[j])!r} vs reference {float(a[j])!r} (abs {err[j]:.3g}, rel {rel:.3g})")


def _weak(rules, k: int, i: int, artist: dict) -> bool:
    for rule in rules:
        if rule["check"] != "finite":
            continue
        sel = [str(x) for x in rule.get("artists", [])]
        if f"{k}:{i}" in sel or (artist.get("label") and artist["label"] in sel):
            return True
    return False


def compare_figure_data(reference: dict, result: dict, rtol: float | None = None,
                        atol: float | None = None, rules=()) -> list[str]:
    """Differences between two figure descriptions (empty when they agree), one string each.

    Each names the axes (index and title), the artist (kind, index, label) and the largest
    difference. Default tolerances: those of the result tables. ``rules``: this figure's
    platform rules (:func:`load_figure_rules`).

    Parameters
    ----------
    reference : dict
        The committed figure description (a data sidecar, :func:`netrepro.figures.data.describe_figure`).
    result : dict
        The description of this build's figure.
    rtol : float, optional
        Relative tolerance of numbers; :data:`netrepro.judging.regression.RTOL` when None.
    atol : float, optional
        Absolute tolerance of numbers; :data:`netrepro.judging.regression.ATOL` when None.
    rules : sequence of dict, default ()
        This figure's platform rules: a ``finite`` rule compares its artists (and the limits of the
        axes it names) by shape and NaN/inf pattern only.

    Returns
    -------
    list of str
        One line per difference; empty when the figures agree.
    """
    from ..judging.regression import ATOL, RTOL

    rtol = RTOL if rtol is None else rtol
    atol = ATOL if atol is None else atol
    out: list[str] = []
    _compare_values("figure", {k: v for k, v in reference.items() if k != "axes"},
                    {k: v for k, v in result.items() if k != "axes"}, rtol, atol, out)
    ra, ga = reference.get("axes", []), result.get("axes", [])
    if len(ra) != len(ga):
        out.append(f"figure: {len(ga)} axes, reference {len(ra)}")
    for k, (rax, gax) in enumerate(zip(ra, ga)):
        where = _axes_name(k, rax)
        limits = {int(x) for rule in rules if rule["check"] == "finite" for x in rule.get("limits", [])}
        for key in ("xlim", "ylim"):
            if key in rax and key in gax:
                _compare_values(f"{where} {key}", rax[key], gax[key], rtol, atol, out, finite=k in limits)
        _compare_values(where, {key: v for key, v in rax.items() if key not in ("artists", "xlim", "ylim")},
                        {key: v for key, v in gax.items() if key not in ("artists", "xlim", "ylim")}, rtol, atol, out)
        rart, gart = rax.get("artists", []), gax.get("artists", [])
        if len(rart) != len(gart):
            names_r = [_artist_name(i, a) for i, a in enumerate(rart)]
            names_g = [_artist_name(i, a) for i, a in enumerate(gart)]
            labels_r = {a.get("label") for a in rart if a.get("label")}
            labels_g = {a.get("label") for a in gart if a.get("label")}
            out.append(f"{where}: {len(gart)} artists, reference {len(rart)}"
                       + (f"; new labels: {sorted(labels_g - labels_r)}" if labels_g - labels_r else "")
                       + (f"; gone labels: {sorted(labels_r - labels_g)}" if labels_r - labels_g else "")
                       + f" (reference: {', '.join(names_r)})")
            continue
        for i, (r, g) in enumerate(zip(rart, gart)):
            _compare_values(f"{where} {_artist_name(i, r)}", r, g, rtol, atol, out, finite=_weak(rules, k, i, r))
    return out


# ----------------------------------------------------------------------------- pixels
def _bytes_io(data: bytes):
    """A binary stream of ``data`` (the standard library's ``io``, imported here: module-level
    ``import io`` next to ``from .io import`` hides ``netrepro.pipeline.io`` from modulefinder, see tests/test_codedeps.py)."""
    import io

    return io.BytesIO(data)


def _rgb(data: bytes) -> np.ndarray:
    from PIL import Image

    return np.asarray(Image.open(_bytes_io(data)).convert("RGB")).astype(np.int16)


def png_rms(reference: bytes, result: bytes) -> float | None:
    """RMS of the pixel difference (``calculate_rms``, as ``compare_images``); None if sizes differ.

    Parameters
    ----------
    reference : bytes
        The reference PNG file's contents.
    result : bytes
        The PNG file's contents of this build.

    Returns
    -------
    float or None
        The RMS of the RGB difference (0.0 for identical bytes); None when the image sizes differ.
    """
    from matplotlib.testing.compare import calculate_rms

    if reference == result:
        return 0.0
    a, b = _rgb(reference), _rgb(result)
    if a.shape != b.shape:
        return None
    return float(calculate_rms(a, b))


def _image_size(data: bytes) -> tuple[int, int]:
    from PIL import Image

    return Image.open(_bytes_io(data)).size


# ----------------------------------------------------------------------------- all figures
def compare_figures(baseline: Baseline, figures_dir, rules: dict | None = None, rtol: float | None = None,
                    atol: float | None = None, rms_tolerance: float = RMS_TOLERANCE
                    ) -> tuple[int, list[FigureDifference]]:
    """Compare every figure of ``figures_dir`` with ``baseline``; returns (number compared, differences).

    A difference with an empty ``problems`` list carries only notes (allowed by a platform rule).

    Parameters
    ----------
    baseline : Baseline
        The committed references.
    figures_dir : str or pathlib.Path
        The figures of this build (``<paper>/<id>.png`` and their data sidecars).
    rules : dict of str to list of dict, optional
        The platform rules of :func:`load_figure_rules`; none when None.
    rtol : float, optional
        Relative tolerance of the figures' data (:func:`compare_figure_data`).
    atol : float, optional
        Absolute tolerance of the figures' data (:func:`compare_figure_data`).
    rms_tolerance : float, default RMS_TOLERANCE
        The largest pixel RMS difference that passes without a ``pixels`` rule.

    Returns
    -------
    n_compared : int
        How many figures were compared (those of the references and of this build).
    differences : list of FigureDifference
        The figures with a problem or a note.

    Raises
    ------
    ValueError
        When the platform rules name a figure that has no reference.
    """
    figures_dir = Path(figures_dir)
    rules = rules or {}
    unknown = sorted(set(rules) - baseline.figures())
    if unknown:
        raise ValueError(f"platform rules name figures without a reference: {', '.join(unknown)}")
    built = {p.relative_to(figures_dir).as_posix()[:-4] for p in figures_dir.glob("*/*.png")}
    built |= {p.relative_to(figures_dir).as_posix()[: -len(SUFFIX)] for p in figures_dir.glob(f"*/*{SUFFIX}")}
    diffs = []
    names = sorted(baseline.figures() | built)
    for name in names:
        d = FigureDifference(name)
        png, sidecar = figures_dir / f"{name}.png", data_path(figures_dir / f"{name}.png")
        ref_png, ref_data = baseline.read(f"{name}.png"), baseline.read(f"{name}{SUFFIX}")
        d.reference_png = ref_png
        d.result_png = png if png.is_file() else None
        if name not in baseline.figures():
            d.problems.append(f"figures/{name}.png: no reference (a new figure: its committed files are its "
                              f"reference: commit figures/{name}.png and figures/{name}{SUFFIX})")
        elif not png.is_file():
            d.problems.append(f"figures/{name}.png: missing (the reference has it)")
        else:
            if ref_data is None:
                d.problems.append(f"figures/{name}{SUFFIX}: the reference has no data sidecar")
            elif not sidecar.is_file():
                d.problems.append(f"figures/{name}{SUFFIX}: missing; `make repair` rebuilds it (or "
                                  f"`snakemake --forcerun {name.replace('/', '_')}`)")
            else:
                try:
                    drawn = json.loads(sidecar.read_text())
                except ValueError as exc:
                    d.problems.append(f"figures/{name}{SUFFIX}: not readable JSON ({exc}; truncated?); "
                                      f"`make repair` rebuilds it (or `snakemake --forcerun {name.replace('/', '_')}`)")
                else:
                    d.problems.extend(f"figures/{name}: {p}" for p in compare_figure_data(
                        json.loads(ref_data), drawn, rtol, atol, rules.get(name, ())))
            if ref_png is None:
                d.problems.append(f"figures/{name}.png: the reference has no PNG")
            else:
                got = png.read_bytes()
                d.rms = png_rms(ref_png, got)
                if d.rms is None:
                    d.problems.append(f"figures/{name}.png: image size {_image_size(got)}, reference "
                                      f"{_image_size(ref_png)}")
                elif d.rms > rms_tolerance:
                    msg = (f"figures/{name}.png: pixels differ, RMS {d.rms:.3g} > tolerance {rms_tolerance}")
                    allowed = [r for r in rules.get(name, ()) if r["check"] == "pixels"]
                    if allowed and not d.problems:
                        d.notes.append(f"{msg}; allowed, what it shows agrees ({allowed[0]['reason'].strip()})")
                    else:
                        d.problems.append(msg)
        if d.problems or d.notes:
            diffs.append(d)
    return len(names), diffs


# ----------------------------------------------------------------------------- the difference page
_CSS = """body{font-family:sans-serif;margin:1.5em;max-width:1400px}
h2{border-top:1px solid #ccc;padding-top:.6em}table{border-collapse:collapse;font-size:90%}
td,th{border:1px solid #ccc;padding:2px 6px;text-align:left;vertical-align:top}
.imgs{display:flex;gap:1em;flex-wrap:wrap}.imgs figure{margin:0}.imgs img{max-width:440px;border:1px solid #ddd}
.fail{color:#b00}.note{color:#666}"""


def _safe(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]", "_", name)


_PAGE_IMAGE = re.compile(r".+_(reference|result|difference)\.png$")


def clear_difference_page(out_dir) -> None:
    """Remove a difference page written earlier in ``out_dir``: its ``index.html`` and its images only.

    Nothing else in the folder is touched, whatever folder it is (``--html`` may name any path).

    Parameters
    ----------
    out_dir : str or pathlib.Path
        The page's folder; only ``index.html`` and ``*_reference.png``, ``*_result.png``,
        ``*_difference.png`` files in it are removed.
    """
    out = Path(out_dir)
    for path in [out / "index.html", *out.glob("*.png")]:
        if path.is_file() and (path.name == "index.html" or _PAGE_IMAGE.fullmatch(path.name)):
            path.unlink()


def write_difference_page(out_dir, figures: list[FigureDifference], tables: list[dict],
                          other: list[str] = (), compared: list[FigureDifference] = (),
                          tables_compared: int | None = None) -> Path:
    """Write ``out_dir/index.html`` (and its images) showing every difference; returns its path.

    ``tables``: ``{"table": path, "problems": [...], "cells": [(row, column, result, reference), ...]}``.

    Parameters
    ----------
    out_dir : str or pathlib.Path
        The page's folder (created when missing); an earlier page in it is removed first
        (:func:`clear_difference_page`).
    figures : list of FigureDifference
        The differing figures; each gets a section with its problems, notes, the reference and
        result images and, when the pixels differ, the amplified difference image.
    tables : list of dict
        The differing tables, in the form above.
    other : sequence of str, default ()
        Further problems, shown as lines at the top of the page.
    compared : list of FigureDifference, default ()
        Every figure compared: listed with its pixel difference and status, so a passing check
        also leaves its evidence.
    tables_compared : int, optional
        How many tables were compared (said in the summary line).

    Returns
    -------
    pathlib.Path
        The page, ``out_dir/index.html``.
    """
    from matplotlib.testing.compare import save_diff_image

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    clear_difference_page(out)
    failing = [d for d in figures if d.problems]
    from ..report.csp import csp_meta  # the difference page runs nothing either (issue 38)

    parts = [f"<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>{csp_meta()}<link rel='icon' href='data:,'>"
             f"<title>Regeneration differences</title><style>{_CSS}</style></head><body>",
             "<h1>Regeneration differences</h1>",
             f"<p id='summary'>{len(failing)} figure(s) and {len(tables)} table(s) differ from their "
             "references. An intended change: <code>make update-references</code>, then commit.</p>"
             if failing or tables else
             f"<p id='summary' class='pass'>No difference: {len(compared)} figure(s)"
             + (f" and {tables_compared} table(s)" if tables_compared is not None else "")
             + " compared with their references.</p>"]
    for line in other:
        parts.append(f"<p class='fail'>{html.escape(line)}</p>")
    for d in figures:
        key = _safe(d.name)
        parts.append(f"<section class='figure' id='fig-{key}'><h2>Figure {html.escape(d.name)}</h2>")
        if d.rms is not None:
            parts.append(f"<p>pixel RMS difference {d.rms:.4g} (tolerance {RMS_TOLERANCE})</p>")
        parts.append("<ul>" + "".join(f"<li class='fail'>{html.escape(p)}</li>" for p in d.problems)
                     + "".join(f"<li class='note'>{html.escape(p)}</li>" for p in d.notes) + "</ul>")
        imgs = []
        ref_file = got_file = None
        if d.reference_png is not None:
            ref_file = out / f"{key}_reference.png"
            ref_file.write_bytes(d.reference_png)
            imgs.append(("reference (committed)", ref_file.name))
        if d.result_png is not None and d.result_png.is_file():
            got_file = out / f"{key}_result.png"
            got_file.write_bytes(d.result_png.read_bytes())
            imgs.append(("this build", got_file.name))
        if ref_file and got_file and d.rms is not None and d.rms > 0:
            diff_file = out / f"{key}_difference.png"
            save_diff_image(str(ref_file), str(got_file), str(diff_file))
            imgs.append(("pixel difference (amplified)", diff_file.name))
        parts.append("<div class='imgs'>" + "".join(
            f"<figure><img src='{src}' alt='{html.escape(d.name)}: {cap}'><figcaption>{cap}</figcaption></figure>"
            for cap, src in imgs) + "</div></section>")
    for t in tables:
        parts.append(f"<section class='table'><h2>Table {html.escape(str(t['table']))}</h2><ul>"
                     + "".join(f"<li class='fail'>{html.escape(p)}</li>" for p in t["problems"]) + "</ul>")
        if t.get("cells"):
            parts.append("<table><tr><th>row</th><th>column</th><th>this build</th><th>reference</th></tr>"
                         + "".join(f"<tr><td>{r}</td><td>{html.escape(str(c))}</td><td>{html.escape(str(g))}</td>"
                                   f"<td>{html.escape(str(v))}</td></tr>" for r, c, g, v in t["cells"])
                         + "</table>")
        parts.append("</section>")
    if compared:
        parts.append("<section id='compared'><h2>Every figure compared</h2><table><tr><th>figure</th><th>status</th>"
                     "<th>pixel RMS</th></tr>" + "".join(
                         f"<tr><td>{html.escape(d.name)}</td><td>{'differs' if d.problems else 'same'}</td>"
                         f"<td>{'' if d.rms is None else f'{d.rms:.3g}'}</td></tr>" for d in compared)
                     + "</table></section>")
    parts.append("</body></html>")
    page = out / "index.html"
    with atomic_path(page) as tmp:
        tmp.write_text("\n".join(parts))
    return page


# ----------------------------------------------------------------------------- regenerating figures
_RUN = re.compile(r"-m netrepro run (--rule .*)$")


def figure_jobs(root=".", targets=None) -> dict[str, dict]:
    """``<paper>/<id> -> {"func", "params", "inputs"}`` of every figure rule, from Snakemake's dry run.

    The inputs are the result tables the figure reads (paths relative to ``root``), as the
    generated rule passes them (``workflow/rules/figures.smk``).

    Parameters
    ----------
    root : str or pathlib.Path, default "."
        The repository's root, where Snakemake is run.
    targets : list of str, optional
        The figure files to ask for; when None, every ``figures/*/*.png`` tracked by git or present.

    Returns
    -------
    dict of str to dict
        Each figure's function (``"module:function"``), its parameters and its input tables
        (the ``code`` inputs left out).

    Raises
    ------
    RuntimeError
        When the dry run shows no figure job.
    """
    root = Path(root)
    if targets is None:
        listing = subprocess.run(["git", "ls-files", "figures/*/*.png"], cwd=root, capture_output=True, text=True)
        targets = sorted(set(listing.stdout.split()) | {p.relative_to(root).as_posix()
                                                        for p in root.glob("figures/*/*.png")})
    cmd = [sys.executable, "-m", "snakemake", "-n", "-p", "--forceall", *targets]
    proc = subprocess.run(cmd, cwd=root, capture_output=True, text=True)
    jobs = {}
    for line in proc.stdout.splitlines():
        m = _RUN.search(line)
        if not m or ".figures:" not in line:
            continue
        args = shlex.split(m.group(1))
        spec = dict(zip(args[::2], args[1::2]))
        io_ = json.loads(spec["--io"])
        figure = io_["outputs"]["figure"]
        jobs[figure[len("figures/"):-4]] = {"func": spec["--func"], "params": json.loads(spec["--params"]),
                                            "inputs": {k: v for k, v in io_["inputs"].items() if k != "code"}}
    if not jobs:
        raise RuntimeError(f"no figure job in the dry run of {root}:\n{proc.stdout[-2000:]}\n{proc.stderr[-2000:]}")
    return jobs


def regenerate_figures(jobs: dict[str, dict], out_dir, tables_dir=None, names=None, module=None) -> list[str]:
    """Draw figures in this process into ``out_dir`` (``<paper>/<id>.png`` and its data sidecar).

    ``tables_dir`` replaces the ``results/`` folder of the inputs (e.g. ``tests/reference``);
    ``module`` (paper -> module) replaces a paper's ``figures`` module (a scratch copy).
    Returns the names drawn.

    Parameters
    ----------
    jobs : dict of str to dict
        The figure jobs of :func:`figure_jobs`.
    out_dir : str or pathlib.Path
        The folder the figures are drawn into.
    tables_dir : str or pathlib.Path, optional
        A folder that replaces ``results/`` in the input paths; the inputs as they are when None.
    names : collection of str, optional
        Only these figures (``<paper>/<id>``); every job when None.
    module : dict of str to module, optional
        ``{paper: module}`` drawing that paper's figures instead of the module the job names.

    Returns
    -------
    list of str
        The names of the figures drawn, sorted.
    """
    import importlib

    drawn = []
    for name, job in sorted(jobs.items()):
        if names is not None and name not in names:
            continue
        mod_name, func_name = job["func"].split(":")
        paper = name.split("/")[0]
        mod = (module or {}).get(paper) or importlib.import_module(mod_name)
        inputs = {k: (str(Path(tables_dir) / Path(v).relative_to("results")) if tables_dir else v)
                  for k, v in job["inputs"].items()}
        target = Path(out_dir) / f"{name}.png"
        getattr(mod, func_name)(job["params"], inputs, {"figure": str(target)})
        drawn.append(name)
    return drawn
