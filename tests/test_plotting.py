"""The plotting helpers (netrepro.figures.plotting) and the figure data sidecar (netrepro.figures.data)."""

import hashlib
import json

import numpy as np

from netrepro.figures.check import compare_figure_data
from netrepro.figures.data import describe_figure
from netrepro.figures.plotting import new_figure, save_figure


def _draw(path):
    fig, ax = new_figure()
    ax.plot([0, 1, 2], [1, 0, 2], label="x")
    ax.legend()
    save_figure(fig, path)
    return hashlib.sha256(path.read_bytes()).hexdigest()


def test_figures_are_deterministic_png_without_date_or_software_stamps(tmp_path):
    first, second = _draw(tmp_path / "a.png"), _draw(tmp_path / "b.png")
    data = (tmp_path / "a.png").read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    assert first == second
    assert b"Software" not in data and b"matplotlib" not in data.lower()
    # written atomically beside its data sidecar: no temporary file left
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.data.json", "a.png", "b.data.json", "b.png"]
    assert (tmp_path / "a.data.json").read_bytes() == (tmp_path / "b.data.json").read_bytes()
    line = json.loads((tmp_path / "a.data.json").read_text())["axes"][0]["artists"][0]
    assert line["kind"] == "line" and line["label"] == "x" and line["xy"] == [[0, 1], [1, 0], [2, 2]]


def _every_kind():
    """A figure with one artist of each kind the sidecar records, and the data it was drawn from."""
    fig, (ax, ax2) = new_figure(1, 2)
    x = np.linspace(0.0, 1.0, 5)
    ax.plot(x, x**2, "o-", label="curve")
    ax.scatter(x, 1 - x, s=[5, 6, 7, 8, 9], label="points")
    ax.fill_between(x, x - 0.1, x + 0.1, alpha=0.3, label="band")
    ax.errorbar(x, x, yerr=0.05, fmt="none", label="errors")
    ax.text(0.5, 0.5, "note 1.25")
    ax.set_yscale("symlog")
    ax.set_xlim(-0.5, 1.5)
    ax.set_title("left")
    ax.legend()
    ax2.bar([1, 2, 3], [3.0, 1.0, 2.0], label="bars")
    ax2.imshow(np.arange(6.0).reshape(2, 3), extent=(0, 3, 0, 2))
    twin = ax2.twinx()
    twin.plot([0, 3], [10, 20], label="twin")
    fig.suptitle("all kinds")
    return fig, x


def test_the_sidecar_records_every_kind_of_artist_with_its_data():
    fig, x = _every_kind()
    d = describe_figure(fig)
    left, right, twin = d["axes"]
    assert d["suptitle"] == "all kinds" and left["title"] == "left"
    assert left["yscale"] == "symlog" and left["xlim"] == [-0.5, 1.5]
    assert left["legend"]["entries"] == ["curve", "points", "band", "errors"]
    by_label = {a.get("label"): a for a in left["artists"]}
    np.testing.assert_allclose(by_label["curve"]["xy"], np.c_[x, x**2])
    np.testing.assert_allclose(by_label["points"]["offsets"], np.c_[x, 1 - x])
    assert by_label["points"]["sizes"] == [5, 6, 7, 8, 9]
    band = np.array(by_label["band"]["paths"][0])
    assert np.isclose(band[:, 1].max(), 1.1) and np.isclose(band[:, 1].min(), -0.1)
    assert any(a["kind"] == "LineCollection" for a in left["artists"])  # the error bars
    assert any(a.get("text") == "note 1.25" for a in left["artists"])
    bars = [a for a in right["artists"] if a["kind"] == "Rectangle" and a["xywh"][3] > 0]
    assert sorted(b["xywh"][3] for b in bars) == [1.0, 2.0, 3.0]
    image = [a for a in right["artists"] if a["kind"] == "image"][0]
    assert image["array"] == [[0, 1, 2], [3, 4, 5]]
    assert twin["twin_of"] == [1] and twin["artists"][0]["label"] == "twin"
    json.dumps(d, allow_nan=False)  # valid JSON


def test_the_comparison_names_axes_artist_and_largest_difference():
    fig, _ = _every_kind()
    ref = describe_figure(fig)
    assert compare_figure_data(ref, json.loads(json.dumps(ref))) == []
    got = json.loads(json.dumps(ref))
    got["axes"][0]["artists"][0]["xy"][3][1] *= 1.01
    problems = compare_figure_data(ref, got)
    assert len(problems) == 1 and "axes 0 ('left') line 0 'curve' xy" in problems[0]
    assert "rel 0.01" in problems[0] and "largest at [3, 1]" in problems[0]
    got = json.loads(json.dumps(ref))
    got["axes"][0]["artists"][0]["xy"][3][1] *= 1 + 5e-7  # within the tables' rtol 1e-6
    assert compare_figure_data(ref, got) == []
    got["axes"][0]["legend"]["entries"].pop()
    assert "legend entries: 3 items, reference 4" in compare_figure_data(ref, got)[0]
