"""The git state recorded in every sidecar and shown by the report's run identity."""

import subprocess

import pytest

from netrepro.pipeline.provenance import git_state


def _git(repo, *args):
    subprocess.run(["git", *args], cwd=repo, check=True, capture_output=True)


@pytest.fixture()
def repo(tmp_path):
    (tmp_path / "figures" / "p").mkdir(parents=True)
    (tmp_path / "src").mkdir()
    (tmp_path / "figures" / "p" / "fig1.png").write_bytes(b"png-1")
    (tmp_path / "src" / "step.py").write_text("x = 1\n")
    _git(tmp_path, "init", "-q")
    _git(tmp_path, "add", ".")
    _git(tmp_path, "-c", "user.name=t", "-c", "user.email=t@t", "commit", "-qm", "init")
    return tmp_path


def test_a_rebuilt_figure_does_not_make_the_tree_dirty(repo):
    """The figures are committed and rewritten by every build: the build's own outputs are not a
    change of the sources, so the figure panels and the run identity agree (both clean)."""
    assert git_state(repo)["dirty"] is False
    (repo / "figures" / "p" / "fig1.png").write_bytes(b"png-2")
    assert git_state(repo)["dirty"] is False
    assert git_state(repo / "src")["dirty"] is False  # from a subdirectory, the same paths are excluded
    assert git_state(repo, exclude=())["dirty"] is True


def test_an_edited_source_makes_the_tree_dirty(repo):
    (repo / "src" / "step.py").write_text("x = 2\n")
    state = git_state(repo)
    assert state["dirty"] is True and len(state["commit"]) == 40


def test_outside_git_the_state_is_unknown(tmp_path):
    assert git_state(tmp_path) == {"commit": None, "dirty": None}
