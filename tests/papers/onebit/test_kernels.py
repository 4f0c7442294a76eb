"""The compiled banded 1-bit grid smoother equals the numpy/scipy reference (bit for bit)."""

from __future__ import annotations

import numpy as np
import pytest

from netrepro.papers.onebit import estimators, model


@pytest.mark.parametrize("eps,snr_db,n,K", [(1e-2, -5.0, 37, 120), (1e-1, 5.0, 8, 40), (1e-3, 0.0, 5, 90)])
def test_banded_kernel_equals_numpy_reference(eps, snr_db, n, K):
    s = float(model.sigma_z2_from_snr(snr_db, eps))
    _, _, r = estimators.simulate_block(np.random.default_rng(3), n, K, eps, s, 1.0)
    for ev in (np.arange(3, K + 1, 7), np.array([0, K // 2, K]), np.array([K - 1])):
        fast = estimators.grid_smoother_at(r, eps, s, 1.0, ev)
        ref = estimators._grid_smoother_at_numpy(r, eps, s, 1.0, ev, 6.0, 1.0, 8.0, True)
        # same operations in the same order: identical (tolerance 0)
        np.testing.assert_array_equal(fast[0], ref[0])
        np.testing.assert_array_equal(fast[1], ref[1])


def test_shared_bootstrap_equals_one_call_per_pair():
    rng = np.random.default_rng(5)
    vals = {k: rng.exponential(1.0, 300) for k in "abcd"}
    pairs = [("a", "b"), ("a", "c"), ("d", "c")]
    got = estimators.paired_ratio_intervals(vals, pairs, 700, 9)
    for (num, den), g in zip(pairs, got):
        assert g == estimators.paired_ratio_interval(vals[num], vals[den], 700, 9)   # exactly


@pytest.mark.parametrize("eps", [1e-3, 1e-1])
def test_smoothing_gain_iterations_equal_numpy_loop(eps):
    from netrepro.papers.onebit import randomwalk

    s = np.asarray(model.sigma_z2_from_snr(np.array([-30.0, -5.0, 0.0, 20.0]), eps), dtype=float)
    for F in (np.array([0.01, 0.3, 0.5, 0.6]), np.ones(4)):
        star = randomwalk.rw_smoothing_gain_fixed_point(F, eps, s)
        fast = randomwalk.rw_smoothing_gain_iterated(F, eps, s, star, 3000, 1e-9)
        ref = randomwalk._rw_smoothing_gain_iterated_numpy(F, eps, s, star, 3000, 1e-9)
        np.testing.assert_array_equal(fast[0], ref[0])   # same operations, same order: tolerance 0
        np.testing.assert_array_equal(fast[1], ref[1])
        assert ref[1].max() > 0
