"""Atomic outputs (netrepro.pipeline.io): the mode of what the atomic writer creates (issue 41, item 3)."""

import os
import stat

import pandas as pd
import pytest

from netrepro.pipeline.io import atomic_path, current_umask, new_file_mode, write_json, write_table


@pytest.fixture
def umask():
    """Set the process's umask for one test (``umask(0o022)``), restoring it afterwards."""
    saved = os.umask(0o022)
    os.umask(saved)

    def set_mask(mask):
        os.umask(mask)

    yield set_mask
    os.umask(saved)


def mode(path) -> int:
    return stat.S_IMODE(os.stat(path).st_mode)


@pytest.mark.parametrize(("mask", "expected"), [(0o022, 0o644), (0o077, 0o600), (0o002, 0o664), (0o000, 0o666)])
def test_new_file_mode_is_what_open_gives_a_new_file(mask, expected):
    assert new_file_mode(mask) == expected


@pytest.mark.parametrize("mask", [0o022, 0o077, 0o027])
def test_current_umask_reads_the_process_umask_and_leaves_it(umask, mask):
    umask(mask)
    assert current_umask() == mask
    assert current_umask() == mask  # reading it did not change it


def test_every_output_of_the_atomic_writer_is_0644_under_umask_022(umask, tmp_path):
    umask(0o022)
    with atomic_path(tmp_path / "raw.bin") as tmp:
        tmp.write_bytes(b"x")
    write_table(pd.DataFrame({"a": [1.5]}), tmp_path / "table.csv")
    write_json({"a": 1}, tmp_path / "side.meta.json")
    assert {p.name: oct(mode(p)) for p in tmp_path.iterdir()} == {
        "raw.bin": "0o644", "table.csv": "0o644", "side.meta.json": "0o644"}


def test_a_figure_saved_under_umask_022_is_0644(umask, tmp_path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from netrepro.figures.plotting import save_figure

    umask(0o022)
    fig, ax = plt.subplots()
    ax.plot([0, 1], [0, 1])
    save_figure(fig, tmp_path / "fig1.png")
    assert {p.name: oct(mode(p)) for p in tmp_path.iterdir()} == {"fig1.png": "0o644", "fig1.data.json": "0o644"}


def test_the_mode_follows_the_umask_not_a_constant(umask, tmp_path):
    umask(0o077)
    write_table(pd.DataFrame({"a": [1]}), tmp_path / "private.csv")
    assert mode(tmp_path / "private.csv") == 0o600


def test_a_file_replaced_keeps_the_new_mode(umask, tmp_path):
    # an output rewritten by a rerun gets the mode of a new file, not the old one's
    target = tmp_path / "table.csv"
    target.write_text("old\n")
    os.chmod(target, 0o600)
    umask(0o022)
    write_table(pd.DataFrame({"a": [1]}), target)
    assert mode(target) == 0o644
