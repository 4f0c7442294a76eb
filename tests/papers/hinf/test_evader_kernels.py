"""The compiled evader kernel (pairwise Frank-Wolfe) reproduces its numpy reference bit for bit (issue 16, speed)."""

import numpy as np
import pytest

from netrepro.papers.hinf import evader as E
from netrepro.papers.hinf.noise import NoiseModel, geometry, noise_information

MODEL = NoiseModel(a0=0.3528, a1=15.625, a2=0.0008, alpha=5.0)


def _instances(n_agents, seed):
    rng = np.random.default_rng(seed)
    x = rng.normal(scale=10.0, size=(40, 17, 2))
    P = rng.normal(scale=30.0, size=(40, 1, n_agents, 2))
    r, th = geometry(x, P)
    return noise_information(r, th, MODEL)


@pytest.mark.parametrize("n_iter", [1, 7, 100])
def test_pairwise_kernel_matches_numpy_reference(n_iter):
    M = _instances(4, 5)
    a, la = E._min_fused_trace_pairwise_numpy(M, n_iter)
    b, lb = E.min_fused_trace_pairwise(M, n_iter)
    assert np.array_equal(a, b) and np.array_equal(la, lb)  # tolerance: 0 (bit-identical)


def test_pairwise_kernel_start_weights():
    M = _instances(4, 6)[:3]
    lam0 = np.random.default_rng(7).dirichlet(np.ones(4), size=M.shape[:-3])
    a, la = E._min_fused_trace_pairwise_numpy(M, 20, lam0)
    b, lb = E.min_fused_trace_pairwise(M, 20, lam0)
    assert np.array_equal(a, b) and np.array_equal(la, lb)
    assert np.array_equal(lam0, np.random.default_rng(7).dirichlet(np.ones(4), size=M.shape[:-3]))  # not modified


@pytest.mark.parametrize("n_agents", [2, 10])
def test_pairwise_kernel_other_agent_counts(n_agents):
    M = _instances(n_agents, 8)
    a, la = E._min_fused_trace_pairwise_numpy(M, 30)
    b, lb = E.min_fused_trace_pairwise(M, 30)
    assert np.array_equal(a, b) and np.array_equal(la, lb)


def test_pairwise_kernel_duplicate_agents():
    # two agents at the same place: equal gradients (first-occurrence ties) and D = 0 (qa = qb = 0) steps
    M = _instances(4, 9)
    M[..., 1, :, :] = M[..., 0, :, :]
    a, la = E._min_fused_trace_pairwise_numpy(M, 25)
    b, lb = E.min_fused_trace_pairwise(M, 25)
    assert np.array_equal(a, b) and np.array_equal(la, lb)
