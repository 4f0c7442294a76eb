"""Tests of `markov`: configuration checks, each against an independent computation."""

from __future__ import annotations

import numpy as np
import pytest

from netrepro.errors import ConfigError
from netrepro.papers.markov import checks
from .systems import A1, C1


def test_check_config_rejects_bad_shapes():
    good = {"A": A1.tolist(), "C": C1.tolist(), "Q": np.eye(2).tolist(), "R": [[1.0]], "Sigma0": np.eye(2).tolist()}
    checks.check_config({"examples": {"I": good}})
    with pytest.raises(ConfigError, match="C"):
        checks.check_config({"examples": {"I": dict(good, C=[[1.0, 1.0, 1.0]])}})
    with pytest.raises(ConfigError, match="R"):
        checks.check_config({"examples": {"I": dict(good, R=[[-1.0]])}})
    with pytest.raises(ConfigError, match="observable"):
        checks.check_config({"examples": {"I": dict(good, A=[[1.2, 0.0], [0.0, 1.2]], C=[[1.0, 0.0]])}})

