"""Shared fixtures. Tests never write into the repository's results/ or figures/."""

import os

# one BLAS thread per test worker: pytest -n 2 on 2 cores, small matrices (threads only add contention)
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import numpy as np  # noqa: E402
import pytest


@pytest.fixture
def rng():
    return np.random.default_rng(12345)
