"""Figures for every reader (issue 41 item 2): no meaning carried by a red/green difference alone.

Over the committed data sidecars (``figures/*/*.data.json``, :mod:`netrepro.figures.data`): any two
labelled artists of one panel (a legend entry: an artist's own label, or the label of the bar or
error-bar container it belongs to) must differ in form (marker, line style, kind of artist or
hatch), or their colours must stay apart for readers with deuteranopia and protanopia: CIEDE2000
>= :data:`MIN_DELTA_E` between the two colours as simulated by ``colorspacious`` (``sRGB1+CVD``,
severity 100), each first laid over the white background with its alpha.

CIEDE2000 is written here from its definition (Sharma, Wu and Dalal 2005, "The CIEDE2000
color-difference formula: implementation notes, supplementary test data, and mathematical
observations", Color Res. Appl. 30(1), 21-30) and tested against rows of that paper's Table 1.
"""

from __future__ import annotations

import itertools
import json
import math
from pathlib import Path

import numpy as np
import pytest

colorspacious = pytest.importorskip("colorspacious")

ROOT = Path(__file__).resolve().parents[1]
SIDECARS = sorted((ROOT / "figures").glob("*/*.data.json"))
MIN_DELTA_E = 15.0
CVD_TYPES = ("deuteranomaly", "protanomaly")  # at severity 100: deuteranopia, protanopia


# ----------------------------------------------------------------------------- CIEDE2000
def delta_e_2000(lab1, lab2, k_l: float = 1.0, k_c: float = 1.0, k_h: float = 1.0) -> float:
    """CIEDE2000 colour difference of two CIELab colours (Sharma et al. 2005, eqs. 1-23)."""
    l1, a1, b1 = map(float, lab1)
    l2, a2, b2 = map(float, lab2)
    c1, c2 = math.hypot(a1, b1), math.hypot(a2, b2)
    c_bar7 = ((c1 + c2) / 2) ** 7
    g = 0.5 * (1 - math.sqrt(c_bar7 / (c_bar7 + 25.0 ** 7)))
    a1p, a2p = (1 + g) * a1, (1 + g) * a2
    c1p, c2p = math.hypot(a1p, b1), math.hypot(a2p, b2)
    h1p = math.degrees(math.atan2(b1, a1p)) % 360 if (a1p, b1) != (0.0, 0.0) else 0.0
    h2p = math.degrees(math.atan2(b2, a2p)) % 360 if (a2p, b2) != (0.0, 0.0) else 0.0
    dl = l2 - l1
    dc = c2p - c1p
    if c1p * c2p == 0:
        dh = 0.0
    elif abs(h2p - h1p) <= 180:
        dh = h2p - h1p
    elif h2p - h1p > 180:
        dh = h2p - h1p - 360
    else:
        dh = h2p - h1p + 360
    d_h = 2 * math.sqrt(c1p * c2p) * math.sin(math.radians(dh / 2))
    l_bar = (l1 + l2) / 2
    c_bar = (c1p + c2p) / 2
    if c1p * c2p == 0:
        h_bar = h1p + h2p
    elif abs(h1p - h2p) <= 180:
        h_bar = (h1p + h2p) / 2
    elif h1p + h2p < 360:
        h_bar = (h1p + h2p + 360) / 2
    else:
        h_bar = (h1p + h2p - 360) / 2
    t = (1 - 0.17 * math.cos(math.radians(h_bar - 30)) + 0.24 * math.cos(math.radians(2 * h_bar))
         + 0.32 * math.cos(math.radians(3 * h_bar + 6)) - 0.20 * math.cos(math.radians(4 * h_bar - 63)))
    d_theta = 30 * math.exp(-(((h_bar - 275) / 25) ** 2))
    r_c = 2 * math.sqrt(c_bar ** 7 / (c_bar ** 7 + 25.0 ** 7))
    s_l = 1 + 0.015 * (l_bar - 50) ** 2 / math.sqrt(20 + (l_bar - 50) ** 2)
    s_c = 1 + 0.045 * c_bar
    s_h = 1 + 0.015 * c_bar * t
    r_t = -math.sin(math.radians(2 * d_theta)) * r_c
    return math.sqrt((dl / (k_l * s_l)) ** 2 + (dc / (k_c * s_c)) ** 2 + (d_h / (k_h * s_h)) ** 2
                     + r_t * (dc / (k_c * s_c)) * (d_h / (k_h * s_h)))


# Sharma, Wu and Dalal (2005), Table 1: pairs 1, 4, 7, 11, 13, 17, 19, 25, 31, 34 (kL = kC = kH = 1)
SHARMA_2005 = [
    ((50.0000, 2.6772, -79.7751), (50.0000, 0.0000, -82.7485), 2.0425),
    ((50.0000, -1.3802, -84.2814), (50.0000, 0.0000, -82.7485), 1.0000),
    ((50.0000, 0.0000, 0.0000), (50.0000, -1.0000, 2.0000), 2.3669),
    ((50.0000, 2.4900, -0.0010), (50.0000, -2.4900, 0.0011), 7.2195),
    ((50.0000, -0.0010, 2.4900), (50.0000, 0.0009, -2.4900), 4.8045),
    ((50.0000, 2.5000, 0.0000), (73.0000, 25.0000, -18.0000), 27.1492),
    ((50.0000, 2.5000, 0.0000), (50.0000, 3.1736, 0.5854), 1.0000),
    ((60.2574, -34.0099, 36.2677), (60.4626, -34.1751, 39.4387), 1.2644),
    ((22.7233, 20.0904, -46.6940), (23.0331, 14.9730, -42.5619), 2.0373),
    ((35.0831, -44.1164, 3.7933), (35.0232, -40.0716, 1.5901), 1.8645),
]


@pytest.mark.parametrize("lab1, lab2, expected", SHARMA_2005)
def test_ciede2000_matches_the_published_test_pairs(lab1, lab2, expected):
    assert delta_e_2000(lab1, lab2) == pytest.approx(expected, abs=5e-5)
    assert delta_e_2000(lab2, lab1) == pytest.approx(expected, abs=5e-5)  # symmetric


# ----------------------------------------------------------------------------- the check
def _rgb_on_white(hex_colour: str) -> np.ndarray:
    """``#rrggbb[aa]`` as sRGB in 0..1, laid over white with its alpha (what the reader sees)."""
    h = hex_colour.lstrip("#")
    rgb = np.array([int(h[i:i + 2], 16) for i in (0, 2, 4)], dtype=float) / 255
    alpha = int(h[6:8], 16) / 255 if len(h) == 8 else 1.0
    return alpha * rgb + (1 - alpha) * 1.0


def seen_lab(hex_colour: str, cvd_type: str) -> np.ndarray:
    """CIELab of a colour as a reader with ``cvd_type`` at severity 100 sees it (colorspacious)."""
    cvd = {"name": "sRGB1+CVD", "cvd_type": cvd_type, "severity": 100}
    rgb = np.clip(colorspacious.cspace_convert(_rgb_on_white(hex_colour), cvd, "sRGB1"), 0, 1)
    return colorspacious.cspace_convert(rgb, "sRGB1", "CIELab")


def _colours(artist: dict) -> list[str]:
    if artist["kind"] == "line":
        return [artist["color"]] if artist.get("color") else []
    face = [c for c in (artist.get("facecolor") or "").split(",") if c and not c.endswith("00")]
    if face:
        return face
    return [c for c in (artist.get("edgecolor") or "").split(",") if c and not c.endswith("00")]


def _form(artist: dict) -> tuple:
    """What separates an artist without colour: its kind, line style, marker and hatch."""
    kind = artist["kind"]
    if kind == "line":
        return ("line", artist.get("linestyle"), artist.get("marker"))
    if kind == "PathCollection":
        return ("scatter", artist.get("marker"))
    return (kind, artist.get("hatch"))


def legend_entries(axes: dict) -> dict[str, dict]:
    """``label -> {"forms", "colours"}`` of one panel's labelled, visible artists (containers: their label)."""
    entries: dict[str, dict] = {}
    for artist in axes.get("artists", []):
        label = artist.get("label") or artist.get("container")
        if not label or not artist.get("visible", True) or artist["kind"] == "text" or "values" in artist:
            continue
        entry = entries.setdefault(label, {"forms": set(), "colours": None})
        entry["forms"].add(_form(artist))
        if entry["colours"] is None and _colours(artist):
            entry["colours"] = _colours(artist)  # the entry's first drawn artist gives its colour
    return {k: v for k, v in entries.items() if v["colours"]}


def colour_distance(c1: list[str], c2: list[str]) -> dict[str, float]:
    """The smallest CIEDE2000 between two artists' colours, per simulated colour vision deficiency."""
    return {cvd: min(delta_e_2000(seen_lab(a, cvd), seen_lab(b, cvd)) for a in c1 for b in c2) for cvd in CVD_TYPES}


def confusable_pairs(data: dict) -> list[str]:
    """The pairs of legend entries, per panel, told apart by colour alone and too close under CVD."""
    problems = []
    for k, axes in enumerate(data["axes"]):
        entries = legend_entries(axes)
        for (l1, e1), (l2, e2) in itertools.combinations(sorted(entries.items()), 2):
            if e1["forms"] != e2["forms"]:
                continue
            dist = colour_distance(e1["colours"], e2["colours"])
            worst = min(dist, key=dist.get)
            if dist[worst] < MIN_DELTA_E:
                problems.append(f"axes {k}: {l1!r} {e1['colours']} and {l2!r} {e2['colours']}, same form "
                                f"{sorted(e1['forms'], key=str)}: CIEDE2000 {dist[worst]:.1f} under {worst}")
    return problems


def test_the_check_fails_on_a_red_green_pair_with_identical_markers():
    red_green = {"axes": [{"artists": [
        {"kind": "PathCollection", "label": "bounded", "marker": "s", "facecolor": "#2ca02c8c",
         "edgecolor": "#2ca02c8c", "visible": True},
        {"kind": "PathCollection", "label": "unbounded", "marker": "s", "facecolor": "#d627288c",
         "edgecolor": "#d627288c", "visible": True}]}]}
    problems = confusable_pairs(red_green)
    assert len(problems) == 1 and "'bounded'" in problems[0] and "'unbounded'" in problems[0]
    # the two colours are far apart for a trichromat, close for a deuteranope
    normal = delta_e_2000(*(colorspacious.cspace_convert(_rgb_on_white(c), "sRGB1", "CIELab")
                            for c in ("#2ca02c8c", "#d627288c")))
    assert normal > 30 and colour_distance(["#2ca02c8c"], ["#d627288c"])["deuteranomaly"] < MIN_DELTA_E
    # another marker separates them; so does a line style
    red_green["axes"][0]["artists"][1]["marker"] = "x"
    assert confusable_pairs(red_green) == []
    lines = {"axes": [{"artists": [
        {"kind": "line", "label": "a", "color": "#2ca02cff", "linestyle": "-", "marker": "None"},
        {"kind": "line", "label": "b", "color": "#d62728ff", "linestyle": "-", "marker": "None"}]}]}
    assert len(confusable_pairs(lines)) == 1
    lines["axes"][0]["artists"][1]["linestyle"] = "--"
    assert confusable_pairs(lines) == []


def test_okabe_ito_blue_and_vermillion_stay_apart_where_red_and_green_do_not():
    from netrepro.figures.plotting import COLOURS

    assert min(colour_distance([COLOURS["bounded"]], [COLOURS["unbounded"]]).values()) >= MIN_DELTA_E
    assert min(colour_distance(["#2ca02c"], ["#d62728"]).values()) < MIN_DELTA_E


def test_the_default_colour_cycle_is_okabe_ito():
    from netrepro.figures.plotting import OKABE_ITO, PALETTE, STYLE, new_figure

    assert [c.lower() for c in STYLE["axes.prop_cycle"].by_key()["color"]] == [c.lower() for c in PALETTE]
    assert set(PALETTE) == set(OKABE_ITO.values())
    fig, ax = new_figure()
    line, = ax.plot([0, 1], [0, 1])
    assert line.get_color().lower() == PALETTE[0].lower()


@pytest.mark.parametrize("sidecar", SIDECARS, ids=[f"{p.parent.name}/{p.name[:-len('.data.json')]}" for p in SIDECARS])
def test_every_figure_separates_its_legend_entries_for_colour_blind_readers(sidecar):
    problems = confusable_pairs(json.loads(sidecar.read_text()))
    assert not problems, "\n".join(problems)


def test_the_sidecars_are_checked():
    assert len(SIDECARS) >= 30
