"""Tests of netrepro.papers.onebit.estimators: each equation against an independent computation."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from netrepro.papers.onebit import estimators
from netrepro.papers.onebit import model

ROOT = Path(__file__).resolve().parents[3]


def test_grid_filter_without_data_information_keeps_prior_mean():
    r = np.ones((3, 5))
    filt, smooth = estimators.grid_filter_smoother(r, 0.1, 0.2, 1e6)  # huge noise: 1-bit data carry ~no information
    np.testing.assert_allclose(filt, 0.0, atol=1e-5)
    np.testing.assert_allclose(smooth, 0.0, atol=1e-5)


def test_grid_filter_reproduces_kalman_on_unquantized_data():
    eps, s = 1e-2, float(model.sigma_z2_from_snr(0.0, 1e-2))
    rng = np.random.default_rng(11)
    theta, y, r = estimators.simulate_block(rng, 20, 60, eps, s, 1.0)
    filt, smooth = estimators.grid_filter_smoother(y, eps, s, 1.0, 8.0, 2.0, quantized=False)
    kf, rts = estimators.kalman_rts(y, eps, s, 1.0)
    sd = math.sqrt(float(model.stationary_variance(eps, s)))
    assert np.max(np.abs(filt - kf)) < 1e-6 * sd
    assert np.max(np.abs(smooth - rts)) < 1e-6 * sd
