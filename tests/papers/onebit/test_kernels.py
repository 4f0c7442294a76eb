"""The compiled banded 1-bit grid smoother equals the numpy/scipy reference (bit for bit)."""

from __future__ import annotations

import numpy as np
import pytest

from netrepro.errors import InputError
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


def _forward_backward_numpy(TT, T, lik_pos, positive, prior, slot, stop, n_slots):
    """The recursions of ``kernels.band_forward_backward`` in numpy/scipy (the reference)."""
    K, n = positive.shape
    lik = lambda k: np.where(positive[k], lik_pos[:, None], 1.0 - lik_pos[:, None])  # noqa: E731
    post = np.repeat(prior[:, None], n, axis=1)
    stored_post = np.full((n_slots, len(prior), n), np.nan)
    stored_beta = np.full((n_slots, len(prior), n), np.nan)
    last = max([k for k in range(K + 1) if slot[k] >= 0], default=0)
    if slot[0] >= 0:
        stored_post[slot[0]] = post
    for k in range(last):
        p = (TT @ post) * lik(k)
        post = p / p.sum(axis=0)
        if slot[k + 1] >= 0:
            stored_post[slot[k + 1]] = post
    beta = np.ones((len(prior), n))
    for k in range(K, stop, -1):
        beta = T @ (beta * lik(k - 1))
        beta /= beta.sum(axis=0)
        if slot[k - 1] >= 0:
            stored_beta[slot[k - 1]] = beta
    return stored_post, stored_beta


# run counts around the kernel's block of 64 runs (padded blocks, partial vectors), grids of 29 to 271 points.
# Not n = 1: numpy sums a single column pairwise (a contiguous reduction), the kernel in grid order.
@pytest.mark.parametrize("eps,snr_db,n,K", [(1e-1, 10.0, 2, 30), (1e-1, 0.0, 7, 45), (1e-2, -5.0, 63, 80),
                                            (1e-2, 5.0, 64, 60), (1e-1, -10.0, 65, 70), (1e-3, -20.0, 250, 25),
                                            (1e-2, 2.5, 130, 50)])
def test_band_forward_backward_equals_numpy(eps, snr_db, n, K):
    from netrepro.papers.onebit.kernels import band_forward_backward

    s = float(model.sigma_z2_from_snr(snr_db, eps))
    x, T, lik_pos, prior = estimators._grid_model(eps, s, 1.0, 6.0, 1.0, 8.0)
    TT = T.T.tocsr()
    rng = np.random.default_rng(n)
    positive = rng.random((K, n)) < rng.uniform(0.1, 0.9, n)
    for ev in (np.array([0, K // 3, K]), np.array([2, K - 1]), np.array([K])):
        slot = np.full(K + 1, -1, dtype=np.int64)
        slot[ev] = np.arange(len(ev))
        got = np.full((2, len(ev), len(x), n), np.nan)
        band_forward_backward(TT.indptr, TT.indices, TT.data, T.indptr, T.indices, T.data, lik_pos, 1.0 - lik_pos,
                              positive, prior, slot, int(ev[0]), got[0], got[1])
        ref = _forward_backward_numpy(TT, T, lik_pos, positive, prior, slot, int(ev[0]), len(ev))
        np.testing.assert_array_equal(got[0], ref[0])   # tolerance 0
        np.testing.assert_array_equal(got[1], ref[1])
        assert np.isfinite(got[0][slot[ev] >= 0]).all() and np.isfinite(got[1][:-1]).all()


def test_band_forward_backward_rejects_csr_outside_the_grid():
    from netrepro.papers.onebit.kernels import band_forward_backward

    s = float(model.sigma_z2_from_snr(0.0, 1e-1))
    x, T, lik_pos, prior = estimators._grid_model(1e-1, s, 1.0, 6.0, 1.0, 8.0)
    out = np.empty((1, len(x), 3))
    args = [T.indptr, T.indices, T.data, T.indptr, T.indices, T.data, lik_pos, 1.0 - lik_pos,
            np.ones((4, 3), dtype=bool), prior, np.array([-1, -1, -1, -1, 0]), 3, out, out.copy()]
    bad = T.indices.copy()
    bad[5] = len(x)
    with pytest.raises(InputError, match="CSR matrix does not fit a grid"):
        band_forward_backward(*args[:4], bad, *args[5:])
    with pytest.raises(InputError, match="likelihoods need"):
        band_forward_backward(*args[:6], lik_pos[1:], *args[7:])
    with pytest.raises(InputError, match="output arrays do not fit"):
        band_forward_backward(*args[:12], out[:, 1:], out.copy()[:, 1:])
    band_forward_backward(*args)   # the valid call


@pytest.mark.parametrize("eps,snr_db,n,K", [(1e-1, 10.0, 1, 1), (1e-2, -5.0, 37, 300), (1e-3, 0.0, 250, 40),
                                            (np.float64(0.5), 20.0, 3, 7)])
def test_kalman_rts_equals_numpy_loop(eps, snr_db, n, K):
    s = float(model.sigma_z2_from_snr(snr_db, eps))
    _, y, _ = estimators.simulate_block(np.random.default_rng(n), n, K, eps, s, 1.0)
    fast = estimators.kalman_rts(y, eps, s, 1.0)
    ref = estimators._kalman_rts_numpy(y, eps, s, 1.0)
    np.testing.assert_array_equal(fast[0], ref[0])   # same operations, same order: tolerance 0
    np.testing.assert_array_equal(fast[1], ref[1])
    assert fast[0].shape == fast[1].shape == (n, K + 1)


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
