"""The compiled conditional estimator (papers/markov/kernels.py) against the numpy reference."""

import numpy as np
import pytest

from netrepro.papers.markov import estimators as est
from netrepro.papers.markov.kernels import pairwise_sum
from netrepro.papers.markov.model import LinearSystem

EX = {
    "I": dict(A=[[1.3, 0.3], [0.0, 1.2]], C=[[1.0, 1.0]], Q=np.eye(2).tolist(), R=[[1.0]], Sigma0=np.eye(2).tolist()),
    "II": dict(A=[[1.2, 0, 0], [0, 1.2, 0], [0, 0, -1.2]], C=[[1.0, 0, 1], [0, 1, 1]], Q=np.eye(3).tolist(),
               R=np.eye(2).tolist(), Sigma0=np.eye(3).tolist()),
}


@pytest.mark.parametrize("n", [0, 1, 7, 8, 9, 100, 128, 129, 300, 1031])
def test_pairwise_sum_is_numpy_sum(n):
    x = np.random.default_rng(n).normal(size=n) * 10.0 ** np.random.default_rng(n + 1).uniform(-5, 5, size=n)
    assert pairwise_sum(x, 0, n) == x.sum()


@pytest.mark.parametrize("name,p,q,T", [("I", 0.5, 0.65, 40), ("I", 0.9, 0.2, 40), ("II", 0.45, 0.5, 30),
                                        ("II", 0.9, 0.25, 30)])
@pytest.mark.parametrize("which", ["norm", "trace"])
def test_rb_kernel_matches_numpy(name, p, q, T, which):
    ex = EX[name]
    system, S0 = LinearSystem.from_config(ex), np.asarray(ex["Sigma0"], float)
    arr = est.gilbert_elliott_arrivals(np.random.default_rng(3), 200, T, p, q, initial=1)
    ref = est.rb_mean_norm(system, S0, p, q, arr, which=which, kernel="numpy")
    got = est.rb_mean_norm(system, S0, p, q, arr, which=which)
    # 2 x 2 and traces: bit for bit; the 3 x 3 norm's arccos (numpy's own vs libm) may differ by an ulp
    np.testing.assert_allclose(got, ref, rtol=1e-14, atol=0)
    if name == "I" or which == "trace":
        assert np.array_equal(got, ref)


def test_riccati_step_2x1_is_the_numpy_maps_bit_for_bit():
    """The compiled step of rb_trace_grid (2 states, 1 output) against numpy's riccati_g / riccati_h
    (np.where of both maps): bit for bit on this platform, for random systems and covariances over
    16 decades, with non-finite matrices and every received pattern."""
    from netrepro.papers.markov.kernels import riccati_step_2x1
    from netrepro.papers.markov.model import riccati_g, riccati_h

    rng = np.random.default_rng(11)
    systems = [(np.array(EX["I"]["A"]), np.array(EX["I"]["C"]), np.eye(2), np.array([[1.0]]))]
    for _ in range(4):
        L = rng.normal(size=(2, 2))
        systems.append((rng.normal(size=(2, 2)), rng.normal(size=(1, 2)), L @ L.T + 0.1 * np.eye(2),
                        np.array([[rng.uniform(0.01, 10.0)]])))
    for A, C, Q, R in systems:
        X = rng.normal(size=(3000, 2, 2))
        P = X @ np.swapaxes(X, -1, -2) * 10.0 ** rng.uniform(-8, 8, size=(3000, 1, 1))
        P[:3] = np.inf
        P[3, 0, 1] = np.nan
        for received in (rng.random(3000) < 0.4, np.ones(3000, bool), np.zeros(3000, bool)):
            with np.errstate(over="ignore", invalid="ignore"):
                ref = np.where(received[:, None, None], riccati_g(P, A, C, Q, R), riccati_h(P, A, Q))
                got = riccati_step_2x1(P, received, A, C, Q, R)
            assert np.array_equal(got, ref, equal_nan=True)
    with pytest.raises(ValueError, match="2-state|P \\(N, 2, 2\\)"):
        riccati_step_2x1(np.ones((4, 3, 3)), np.ones(4, bool), np.eye(3), np.ones((1, 3)), np.eye(3), np.eye(1))


def test_riccati_branch_2x1_is_both_numpy_maps_bit_for_bit():
    """The branching of the exact tree (every matrix's g, then every matrix's h) against numpy's maps."""
    from netrepro.papers.markov.kernels import riccati_branch_2x1
    from netrepro.papers.markov.model import riccati_g, riccati_h

    rng = np.random.default_rng(12)
    for A, C, Q, R in ((np.array(EX["I"]["A"]), np.array(EX["I"]["C"]), np.eye(2), np.array([[1.0]])),
                       (rng.normal(size=(2, 2)), rng.normal(size=(1, 2)), np.array([[1.0, 0.3], [0.3, 0.5]]),
                        np.array([[0.2]]))):
        X = rng.normal(size=(2000, 2, 2))
        P = X @ np.swapaxes(X, -1, -2) * 10.0 ** rng.uniform(-8, 8, size=(2000, 1, 1))
        P[:2] = np.inf
        with np.errstate(over="ignore", invalid="ignore"):
            ref = np.concatenate([riccati_g(P, A, C, Q, R), riccati_h(P, A, Q)])
            got = riccati_branch_2x1(P, A, C, Q, R)
        assert np.array_equal(got, ref, equal_nan=True)
    with pytest.raises(ValueError, match="riccati_branch_2x1 needs"):
        riccati_branch_2x1(np.ones((4, 2, 2)), np.eye(2), np.ones((2, 2)), np.eye(2), np.eye(2))
