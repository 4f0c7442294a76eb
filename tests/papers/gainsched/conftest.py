"""Shared fixtures of the `gainsched` tests: the test configuration, its system, the printed gains."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

from netrepro.papers.gainsched.design import Theorem3
from netrepro.papers.gainsched.model import Gains, gains_from_dict, system_from_config


@pytest.fixture(scope="module")
def cfg():
    with open(Path(__file__).resolve().parents[3] / "config" / "test.yaml") as fh:
        return yaml.safe_load(fh)["gainsched"]


@pytest.fixture(scope="module")
def sys(cfg):
    return system_from_config(cfg["system"])


@pytest.fixture(scope="module")
def paper(cfg, sys):
    return gains_from_dict(cfg["paper_gains"], sys)


@pytest.fixture(scope="module")
def t3(sys):
    sol = Theorem3(sys, bound=100.0).solve()
    assert sol.values, sol.status
    return sol


def random_gains(rng, sys, scale=0.3):
    n, m = sys.n, sys.m
    return Gains(scale * rng.standard_normal((n, n)), scale * rng.standard_normal((n, n)),
                 rng.standard_normal((n, m)), rng.standard_normal((n, m)))
