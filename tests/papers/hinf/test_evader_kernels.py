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


# ----------------------------------------------------------------------------- exact solver: faces kernel
def _spd(rng, shape, cond=1.0):
    G = rng.standard_normal(shape + (2, 2))
    return G @ np.swapaxes(G, -1, -2) + cond * np.eye(2)


def _exact_cases():
    rng = np.random.default_rng(11)
    yield _instances(4, 12)
    yield _instances(3, 13)
    yield _instances(10, 14)[:6]
    yield _spd(rng, (30, 5), cond=0.05)
    near = _instances(4, 15)  # near-duplicate agents: nearly singular faces (Newton polish)
    near[..., 2, :, :] = near[..., 0, :, :] * (1 + 1e-9)
    yield near
    same = _instances(4, 16)  # identical agents: singular faces, infeasible stationary points
    same[..., 3, :, :] = same[..., 1, :, :]
    yield same
    yield np.broadcast_to(_spd(rng, (40, 1)), (40, 3, 2, 2))  # all agents identical


@pytest.mark.parametrize("case", range(7))
def test_exact_solver_compiled_matches_numpy_form(case):
    M = list(_exact_cases())[case]
    a, la = E.min_fused_trace_exact(M, kernel="numpy")
    b, lb = E.min_fused_trace_exact(M, kernel="compiled")
    assert a.tobytes() == b.tobytes() and la.tobytes() == lb.tobytes()  # tolerance: 0 (signed zeros included)


@pytest.mark.parametrize("k", [1, 2, 3])
def test_faces_kernel_matches_numpy_form_on_arbitrary_faces(k):
    """Arbitrary (not positive definite) H and traces: infeasible, singular and nan faces, a subset of rows."""
    from itertools import combinations

    from netrepro.papers.hinf.evader_kernels import faces_kernel

    rng = np.random.default_rng(20 + k)
    m, n = 400, 6
    S = rng.standard_normal((m, n, 3))
    S[:50, 1] = S[:50, 0]                                   # duplicate vertices
    S[50:60, 2] = 0.0                                       # zero matrices
    S[60:65, 3, 0] = np.nan                                 # nan entries
    S[65:70, 4] = -0.0
    H = E._polarised_det(S)
    l = S[..., 0] + S[..., 2]
    # rows 70-79: the best edge {0, 1} has the stationary weights (-0.0, 1.0) (P_0 = R_0 = 0, sum < 0), which
    # np.clip turns into +0.0
    H[70:80], l[70:80] = np.eye(n), 1e6
    H[70:80, 0, 0], H[70:80, 0, 1], H[70:80, 1, 0], H[70:80, 1, 1], l[70:80, :2] = 1.0, 2.0, 2.0, 2.0, 1.0
    combos = np.asarray(list(combinations(range(n), k)))
    rows = np.union1d(rng.choice(m, size=300, replace=False), np.arange(70, 80))
    best_f0 = np.where(rng.random(m) < 0.3, rng.random(m), np.inf)
    best_f0[70:80] = np.inf
    best_lam0 = rng.random((m, n))
    f1, l1, f2, l2 = best_f0.copy(), best_lam0.copy(), best_f0.copy(), best_lam0.copy()
    with np.errstate(all="ignore"):
        E._best_on_faces_numpy(H, l, combos, rows, f1, l1)
    faces_kernel(H, l, combos, rows, f2, l2)
    assert f1.tobytes() == f2.tobytes() and l1.tobytes() == l2.tobytes()
    assert not np.array_equal(f1, best_f0)  # the faces did improve some rows
    if k == 2:
        assert (l2[70:80, :2] == [0.0, 1.0]).all() and not np.signbit(l2[70:80]).any()


@pytest.mark.parametrize("case", range(7))
def test_compiled_bounds_match_numpy_form(case):
    """The certificate (value, lower bound) of the compiled path, whose gradient minimum is taken column by column."""
    M = np.ascontiguousarray(list(_exact_cases())[case], dtype=float)
    n = M.shape[-3]
    Mf = M.reshape(-1, n, 2, 2)
    lam = np.random.default_rng(case).dirichlet(np.ones(n), size=len(Mf))
    lam[::3, 0] = 0.0
    lam /= lam.sum(-1, keepdims=True)
    a = E.fused_trace_bounds(Mf, lam)
    b = E._fused_trace_bounds_flat(Mf, lam, True)
    assert all(u.tobytes() == v.tobytes() for u, v in zip(a, b))
