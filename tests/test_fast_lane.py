"""The guard that keeps Snakemake out of ``make test-fast`` (tests/conftest.py) recognises its commands."""

import subprocess
import sys

import pytest

from .conftest import runs_snakemake


@pytest.mark.parametrize("command", [
    [sys.executable, "-m", "snakemake", "-n", "report"],
    ["snakemake", "--lint"],
    "/work/x/.venv/bin/snakemake report --profile p",
])
def test_snakemake_commands_are_recognised(command):
    assert runs_snakemake(command)


@pytest.mark.parametrize("command", [
    ["make", "-n", "report"],  # make prints the snakemake line without starting it
    [sys.executable, "-m", "netrepro", "run", "--rule", "snakemake_like"],
    "git ls-files figures",
])
def test_other_commands_are_not(command):
    assert not runs_snakemake(command)


def test_a_fast_test_that_starts_snakemake_fails():
    with pytest.raises(AssertionError, match="starts Snakemake but is not marked slow"):
        subprocess.run([sys.executable, "-m", "snakemake", "--version"], capture_output=True)
