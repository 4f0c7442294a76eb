import numpy as np
import pytest

from netrepro.engines.channels import (arrival_patterns, gilbert_elliott_arrivals, gilbert_elliott_stationary,
                                       iid_arrivals)


def test_iid_frequency_matches_probability(rng):
    arr = iid_arrivals(rng, 2000, 100, 0.3)
    assert arr.shape == (2000, 100)
    assert abs(arr.mean() - 0.3) < 0.005  # 2e5 draws: sd 0.001


def test_iid_multi_sensor_independent(rng):
    arr = iid_arrivals(rng, 4000, 50, [0.2, 0.7])
    assert arr.shape == (4000, 50, 2)
    assert np.allclose(arr.mean(axis=(0, 1)), [0.2, 0.7], atol=0.005)
    both = (arr[..., 0] & arr[..., 1]).mean()
    assert abs(both - 0.14) < 0.005


def test_gilbert_elliott_transition_frequencies(rng):
    p, q = 0.3, 0.6
    arr = gilbert_elliott_arrivals(rng, 4000, 200, p, q)
    prev, nxt = arr[:, :-1], arr[:, 1:]
    fail = (~nxt & prev).sum() / prev.sum()
    recover = (nxt & ~prev).sum() / (~prev).sum()
    assert abs(fail - p) < 0.005 and abs(recover - q) < 0.005
    assert abs(arr.mean() - gilbert_elliott_stationary(p, q)[0]) < 0.005


def test_gilbert_elliott_stationary_closed_form():
    assert gilbert_elliott_stationary(0.2, 0.6) == pytest.approx((0.75, 0.25))
    with pytest.raises(ValueError, match="p \\+ q = 0"):
        gilbert_elliott_stationary(0.0, 0.0)


def test_gilbert_elliott_iid_special_case(rng):
    # p + q = 1 makes the chain i.i.d. with P(arrival) = q
    arr = gilbert_elliott_arrivals(rng, 4000, 100, 0.4, 0.6)
    prev, nxt = arr[:, :-1], arr[:, 1:]
    assert abs(nxt[prev].mean() - nxt[~prev].mean()) < 0.01


def test_arrival_patterns_probabilities():
    patterns, weights = arrival_patterns([0.3, 0.8])
    assert patterns.tolist() == [[False, False], [False, True], [True, False], [True, True]]
    assert np.allclose(weights, [0.7 * 0.2, 0.7 * 0.8, 0.3 * 0.2, 0.3 * 0.8])
    assert weights.sum() == pytest.approx(1.0)


@pytest.mark.parametrize("bad", [-0.1, 1.5, np.nan])
def test_bad_probability_named(rng, bad):
    with pytest.raises(ValueError, match="prob"):
        iid_arrivals(rng, 2, 2, bad)
