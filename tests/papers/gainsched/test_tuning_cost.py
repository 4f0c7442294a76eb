"""The Monte Carlo cost of the tuning (tuning.sum_mse) against its numpy expression, bit for bit: the Nelder-Mead
path depends on every bit of the cost."""

import numpy as np
import pytest

from netrepro.papers.gainsched.tuning import sum_mse


def _reference(e):
    return float((e ** 2).sum(-1).mean(0).sum())


@pytest.mark.parametrize("shape", [(1000, 31, 2), (7, 51, 2), (1, 1, 2), (64, 31, 3), (50, 10, 1)])
@pytest.mark.parametrize("seed", range(4))
def test_sum_mse_bit_identical(shape, seed):
    rng = np.random.default_rng(seed)
    e = rng.standard_normal(shape) * 10.0 ** rng.integers(-8, 9, size=shape)  # wide dynamic range
    assert sum_mse(e) == _reference(e)


def test_sum_mse_non_finite():
    e = np.zeros((5, 3, 2))
    e[1, 2, 0] = np.inf
    assert sum_mse(e) == _reference(e) == np.inf
    e[0, 0, 1] = np.nan
    assert np.isnan(sum_mse(e)) and np.isnan(_reference(e))
