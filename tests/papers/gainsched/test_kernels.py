"""The compiled Monte Carlo kernel of gainsched (kernels.simulate_kernel via model.simulate_draws) against simulate."""

import numpy as np
import pytest

from netrepro.papers.gainsched.model import (Gains, GainschedError, System, draw_noise, p_schedule, simulate,
                                             simulate_draws)


def _sys():
    return System(np.array([[0.43, 0.0], [0.15, 0.36]]), np.array([[0.1, 0.04], [0.0, 0.08]]),
                  np.array([[0.38, 0.46]]), np.array([[0.3, 0.03], [0.05, 0.38]]), np.diag([0.51, 0.621]),
                  np.diag([0.46, 0.37]), np.diag([2.81, 2.95]), 1.0, 0.4, 0.8)


@pytest.mark.parametrize("kind", ["sine_mid", "lower", "upper"])
@pytest.mark.parametrize("with_gains", [True, False])
def test_kernel_matches_numpy_reference(kind, with_gains):
    sys = _sys()
    rng = np.random.default_rng(5)
    gains = Gains(0.3 * rng.standard_normal((2, 2)), 0.3 * rng.standard_normal((2, 2)),
                  rng.standard_normal((2, 1)), rng.standard_normal((2, 1))) if with_gains else None
    p_seq = p_schedule(np.arange(30), sys.p1, sys.p2, 1.0)
    x0 = rng.standard_normal((200, 2))
    ref = simulate(sys, gains, p_seq, x0, np.random.default_rng(11), kind, xf0=[0.2, -0.1])
    got = simulate_draws(sys, gains, p_seq, x0, draw_noise(np.random.default_rng(11), 30, 200), kind, xf0=[0.2, -0.1])
    assert got.shape == ref.shape
    # same recursion and rounding order: bit-identical on the reference platform; a few ulps allowed elsewhere
    np.testing.assert_allclose(got, ref, rtol=1e-12, atol=1e-14)


def test_kernel_rejects_bad_input():
    sys = _sys()
    p_seq = p_schedule(np.arange(5), sys.p1, sys.p2, 1.0)
    draws = draw_noise(np.random.default_rng(0), 5, 3)
    with pytest.raises(GainschedError, match="nonlinearity kind must be"):
        simulate_draws(sys, None, p_seq, np.zeros((3, 2)), draws, "cubic")
    with pytest.raises(GainschedError, match=r"draws must have shape \(5, 4\)"):
        simulate_draws(sys, None, p_seq, np.zeros((4, 2)), draws)


@pytest.mark.parametrize("kind", ["sine_mid", "lower", "upper"])
@pytest.mark.parametrize("with_gains,runs,seed", [(True, 7, 1), (True, 64, 2), (False, 33, 3), (True, 1000, 4)])
def test_kernel_bit_identical_with_numpy_reference(kind, with_gains, runs, seed):
    # the tuning's Nelder-Mead path depends on every bit of the cost: the kernel must equal simulate exactly
    sys = _sys()
    rng = np.random.default_rng(seed)
    gains = Gains(0.3 * rng.standard_normal((2, 2)), 0.3 * rng.standard_normal((2, 2)),
                  rng.standard_normal((2, 1)), rng.standard_normal((2, 1))) if with_gains else None
    p_seq = p_schedule(np.arange(30), sys.p1, sys.p2, 1.0)
    x0 = 2.0 * rng.standard_normal((runs, 2))
    ref = simulate(sys, gains, p_seq, x0, np.random.default_rng(seed + 10), kind, xf0=[0.2, -0.1])
    got = simulate_draws(sys, gains, p_seq, x0, draw_noise(np.random.default_rng(seed + 10), 30, runs), kind,
                         xf0=[0.2, -0.1])
    np.testing.assert_array_equal(got, ref)


@pytest.mark.parametrize("kind", [0, 1, 2])
@pytest.mark.parametrize("has_gains", [True, False])
def test_kernel_2x1_equals_the_generic_kernel(kind, has_gains):
    """The written-out kernel of the paper's shapes (2 states, 1 output, 2 channels) against the generic
    loop, bit for bit, with random plants, gains, initial states and draws (including large states)."""
    from netrepro.papers.gainsched.kernels import simulate_kernel, simulate_kernel_2x1

    rng = np.random.default_rng(40 + kind)
    for _ in range(3):
        A, B, D, Z = (rng.standard_normal((2, 2)) for _ in range(4))
        C = rng.standard_normal((1, 2))
        d1 = rng.uniform(0.1, 1.0, 2)
        d2 = d1 + rng.uniform(0.1, 3.0, 2)
        G0, Gf = rng.standard_normal((2, 2)), rng.standard_normal((2, 2))
        H0, Hf = rng.standard_normal((2, 1)), rng.standard_normal((2, 1))
        p_seq = rng.uniform(0.2, 0.9, 25)
        x0, xf0 = 5.0 * rng.standard_normal((150, 2)), rng.standard_normal((150, 2))
        u, g = rng.random((25, 150)), rng.standard_normal((25, 150))
        args = (A, B, C, D, Z, d1, d2, kind, G0, Gf, H0, Hf, has_gains, p_seq, x0, xf0, u, g, 0.7)
        with np.errstate(over="ignore", invalid="ignore"):
            np.testing.assert_array_equal(simulate_kernel_2x1(*args), simulate_kernel(*args))
