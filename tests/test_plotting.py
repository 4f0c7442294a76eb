"""The plotting helpers (netrepro.plotting)."""

import hashlib

import pytest

from netrepro.plotting import new_figure, save_figure


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
    # written atomically: no temporary file left beside it
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.png", "b.png"]
