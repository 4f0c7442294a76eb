"""Correctness of the engines' fast paths added for issue 9 (small-state kernel, scalar kernel, warm bisection)."""

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

import netrepro.engines.riccati as ric
from netrepro.engines.lmi import bisect_bracketed, bisect_monotone, sweep_thresholds
from netrepro.engines.riccati import Sensor, covariance_paths, measurement_update, packed_flops_per_step


def _original_scalar(p0, a, q, r_eff, arrivals, keep):
    """The scalar recursion exactly as first written (np.where, fresh arrays)."""
    N, T, m = arrivals.shape
    p = np.full(N, p0)
    out = np.empty((N, T + 1))
    out[:, 0] = p
    with np.errstate(over="ignore", divide="ignore", invalid="ignore"):
        for k in range(T):
            for j in range(m):
                post = r_eff[j] / (1.0 + r_eff[j] / p)
                p = np.where(arrivals[:, k, j], post, p)
            p = a * a * p + q
            out[:, k + 1] = p
    return out if keep == "all" else p


def _system(rng, n):
    A = rng.normal(size=(n, n))
    M = rng.normal(size=(n, n))
    sensors = [Sensor(rng.normal(size=(1, n)), [[0.4]]),
               Sensor(rng.normal(size=(2, n)), [[0.5, 0.1], [0.1, 0.3]])]  # correlated noise: whitened rows
    return A, 0.3 * np.eye(n) + 0.01 * M @ M.T, sensors


@pytest.mark.parametrize("keep", ["all", "last"])
def test_scalar_kernel_is_bit_identical_to_original(rng, keep, monkeypatch):
    monkeypatch.setattr(ric, "SCALAR_CHUNK_PATHS", 37)  # several chunks, a ragged last one
    arrivals = rng.random((200, 700, 2)) < 0.002  # a = 10, rare receptions: paths overflow, then recover
    new = covariance_paths(5.0, [[10.0]], [[0.1]], [Sensor([[1.0]], [[0.5]]), Sensor([[2.0]], [[0.8]])], arrivals, keep,
                           kernel="numpy")
    old = _original_scalar(5.0, 10.0, 0.1, [0.5, 0.2], arrivals, keep)
    assert np.array_equal(new, old)


@pytest.mark.parametrize("keep", ["all", "last"])
def test_compiled_scalar_kernel_matches_original_with_overflow_and_recovery(rng, keep):
    """One division per update instead of two: equal to rounding, and the same inf semantics
    (a path that overflowed to inf recovers to r at its next reception)."""
    # a = 10 with rare receptions: runs of ~300 losses overflow (10^308); 600 paths are three blocks
    # of the compiled kernel, the last one ragged
    arrivals = rng.random((600, 700, 2)) < 0.002
    sensors = [Sensor([[1.0]], [[0.5]]), Sensor([[2.0]], [[0.8]])]
    new = covariance_paths(5.0, [[10.0]], [[0.1]], sensors, arrivals, keep, kernel="compiled")
    old = _original_scalar(5.0, 10.0, 0.1, [0.5, 0.2], arrivals, keep)
    assert np.array_equal(np.isinf(new), np.isinf(old))
    if keep == "all":
        assert (np.isinf(old[:, :-1]) & np.isfinite(old[:, 1:])).any()  # overflow, then recovery, did happen
    finite = np.isfinite(old)
    assert np.allclose(new[finite], old[finite], rtol=1e-13, atol=0)


@pytest.mark.parametrize("kernel", ["compiled", "numpy"])
@pytest.mark.parametrize("n", [2, 3])
@pytest.mark.parametrize("keep", ["all", "last"])
def test_small_state_kernel_matches_dense_form(rng, n, keep, kernel, monkeypatch):
    monkeypatch.setattr(ric, "CHUNK_PATHS", 23)
    A, Q, sensors = _system(rng, n)
    A = 0.8 * A / np.max(np.abs(np.linalg.eigvals(A)))
    arrivals = rng.random((301, 40, 2)) < 0.5  # two blocks of the compiled kernel, the last one ragged
    fast = covariance_paths(np.eye(n), A, Q, sensors, arrivals, keep, kernel=kernel)
    dense = ric._dense_paths(np.eye(n), A, Q, sensors, arrivals, keep)
    assert fast.shape == dense.shape
    assert np.allclose(fast, dense, rtol=1e-10, atol=1e-12)


@pytest.mark.parametrize("kernel", ["compiled", "numpy"])
def test_small_state_kernel_handles_scalar_P0_like_dense(rng, kernel):
    A, Q, sensors = _system(rng, 2)
    arrivals = rng.random((7, 5, 2)) < 0.5
    assert np.allclose(covariance_paths(2.0, 0.5 * A, Q, sensors, arrivals, kernel=kernel),
                       ric._dense_paths(2.0, 0.5 * A, Q, sensors, arrivals, "all"))


@pytest.mark.parametrize("kernel", ["compiled", "numpy"])
def test_small_state_kernel_diverged_paths_stay_inf(rng, kernel):
    A = np.array([[3.0, 0.0], [0.0, 0.5]])  # the unstable mode is unobserved by sensor 2
    sensors = [Sensor([[0.0, 1.0]], [[1.0]])]
    arrivals = rng.random((6, 1500)) < 0.5
    arrivals[0] = False
    out = covariance_paths(np.eye(2), A, np.eye(2), sensors, arrivals, keep="all", kernel=kernel)
    assert not np.isnan(out).any()
    dead_at = np.argmax(~np.isfinite(out).all(axis=(2, 3)), axis=1)
    assert np.all(dead_at > 0)
    for i, k in enumerate(dead_at):  # once non-finite, the whole matrix is inf for ever after
        assert np.isinf(out[i, k:]).all()
    assert np.isinf(covariance_paths(np.eye(2), A, np.eye(2), sensors, arrivals, keep="last", kernel=kernel)).all()


def test_singular_noise_falls_back_to_dense_form(rng, monkeypatch):
    calls = []
    original = ric._dense_paths
    monkeypatch.setattr(ric, "_dense_paths", lambda *a: calls.append(1) or original(*a))
    sensors = [Sensor([[1.0, 0.0], [0.0, 1.0]], [[1.0, 1.0], [1.0, 1.0]])]  # R singular: no Cholesky
    covariance_paths(np.eye(2), 0.5 * np.eye(2), np.eye(2), sensors, rng.random((3, 4)) < 0.5)
    assert calls


def test_scalar_innovation_update_equals_solve(rng):
    M = rng.normal(size=(5, 3, 3))
    P = M @ np.swapaxes(M, 1, 2) + np.eye(3)
    s = Sensor(rng.normal(size=(1, 3)), [[0.3]])
    got = measurement_update(P, s, np.ones(5, dtype=bool))
    S = s.C @ P @ s.C.T + s.R
    want = P - P @ s.C.T @ np.linalg.solve(S, s.C @ P)
    assert np.allclose(got, want, rtol=1e-12)


def test_flop_count():
    # n = 2, one row, counted by hand: u = P c^T 4 mul + 2 add... as multiply-adds 4 (8 flops),
    # s = c u + r 2 multiply-adds (4), w (1), t = w u (2), 3 entries updated (6), prediction
    # 3 outputs x 3 multiply-adds (18): 39
    assert packed_flops_per_step(2, 1) == 39
    # n = 3: 9 (18) + 3 (6) + 1 + 3 + 6 (12) per row = 40, prediction 6 x 6 (72)
    assert packed_flops_per_step(3, 2) == 2 * 40 + 72
    assert packed_flops_per_step(1, 1) == 2 + 2 + 1 + 1 + 2 + 2


# ----------------------------------------------------------------------------- bisection
def _step(threshold):
    calls = []

    def feasible(x):
        calls.append(x)
        return x >= threshold
    return feasible, calls


@pytest.mark.parametrize("guess,width", [(0.3, 0.01), (0.31, 1e-3), (0.9, 0.01), (0.0, 0.2), (0.3137, 1e-5)])
def test_bracketed_bisection_agrees_with_plain(guess, width):
    f, _ = _step(0.3137)
    plain = bisect_monotone(f, 0.0, 1.0, tol=1e-6)
    warm = bisect_bracketed(f, 0.0, 1.0, guess, width, tol=1e-6)
    assert warm.bracketed and warm.lower < 0.3137 <= warm.threshold
    assert (warm.threshold, warm.lower) == (plain.threshold, plain.lower)  # same lattice point, whatever the guess
    assert warm.threshold - warm.lower <= 1e-6


def test_bracketed_bisection_saves_solves_with_a_good_guess():
    f, calls = _step(0.3137)
    bisect_bracketed(f, 0.0, 1.0, 0.3136, 2e-4, tol=1e-6)
    assert len(calls) <= 12 < bisect_monotone(_step(0.3137)[0], 0.0, 1.0, tol=1e-6).n_evals


@settings(max_examples=200, deadline=None)
# lattice points are lo + (hi - lo) j / n rounded to doubles: here -0.49999999999999994 for -0.5
@example(threshold=-0.5, guess=0.0, width=0.0, lo=-0.9999999999999999, span=1.9999999999999998, tol=0.0625)
@given(threshold=st.floats(-0.5, 2.5), guess=st.floats(-1.0, 3.0), width=st.floats(0.0, 2.0),
       lo=st.floats(-1.0, 0.5), span=st.floats(1e-3, 2.0), tol=st.floats(1e-7, 0.1))
def test_bracketed_and_plain_bisection_return_the_same_lattice_point(threshold, guess, width, lo, span, tol):
    hi = lo + span
    plain = bisect_monotone(_step(threshold)[0], lo, hi, tol=tol)
    warm = bisect_bracketed(_step(threshold)[0], lo, hi, guess, width, tol=tol)
    assert warm.bracketed == plain.bracketed
    assert np.array_equal([warm.threshold, warm.lower], [plain.threshold, plain.lower], equal_nan=True)
    if plain.bracketed:
        # the lattice spacing is <= tol; each of the two points carries a rounding of its own
        rounding = 2 * np.spacing(max(abs(lo), abs(hi)))
        assert plain.lower < threshold <= plain.threshold and plain.threshold - plain.lower <= tol + rounding


@pytest.mark.parametrize("threshold,expected", [(-1.0, 0.0), (2.0, np.nan)])
def test_bracketed_bisection_end_points_like_plain(threshold, expected):
    f, _ = _step(threshold)
    res = bisect_bracketed(f, 0.0, 1.0, 0.5, 0.01, tol=1e-6)
    plain = bisect_monotone(_step(threshold)[0], 0.0, 1.0, tol=1e-6)
    assert not res.bracketed and not plain.bracketed
    assert (np.isnan(res.threshold) and np.isnan(plain.threshold)) or res.threshold == plain.threshold == expected


def test_sweep_warm_start_matches_plain_and_needs_fewer_solves():
    curve = lambda x: max(0.0, 0.6 - 0.5 * x - 0.3 * x * x)  # noqa: E731  (hits 0 inside the grid)
    grid = np.linspace(0.0, 1.0, 41)
    make = lambda x: _step(curve(x))[0]  # noqa: E731
    warm = sweep_thresholds(make, grid, 0.0, 1.0, tol=1e-5)
    plain = sweep_thresholds(make, grid, 0.0, 1.0, tol=1e-5, warm_start=False)
    for w, p, x in zip(warm, plain, grid):
        assert w.threshold == p.threshold  # warm starts change the solves, not the answers
        assert w.threshold >= curve(x) - 1e-12
    assert sum(r.n_evals for r in warm) < 0.7 * sum(r.n_evals for r in plain)


@pytest.mark.parametrize("kernel", ["compiled", "numpy"])
def test_small_state_kernel_is_exactly_symmetric_and_accurate(kernel):
    """Over 200 steps of an unstable 3-state system: exact symmetry, and close to a long-double loop."""
    rng = np.random.default_rng(7)
    A = np.array([[1.1, 0.3, 0.0], [-0.2, 0.95, 0.1], [0.0, 0.2, 0.8]])
    c, r = np.ones(3) / np.sqrt(3), 0.5
    arrivals = rng.random((8, 200)) < 0.7
    out = covariance_paths(np.eye(3), A, 0.1 * np.eye(3), [Sensor(c[None, :], [[r]])], arrivals, kernel=kernel)
    assert np.array_equal(out, np.swapaxes(out, 2, 3))
    L = np.longdouble
    for i in range(8):
        P, Al, cl = np.eye(3, dtype=L), A.astype(L), c.astype(L).reshape(1, 3)
        for k in range(200):
            if arrivals[i, k]:
                u = P @ cl.T
                P = P - (u @ u.T) / ((cl @ u)[0, 0] + L(r))
            P = Al @ P @ Al.T + L(0.1) * np.eye(3, dtype=L)
        P = P.astype(float)
        assert np.max(np.abs(out[i, -1] - P)) <= 1e-5 * np.max(np.abs(P))
