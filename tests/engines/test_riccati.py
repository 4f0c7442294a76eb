import numpy as np
import pytest

from netrepro.engines.riccati import (Sensor, as_sensors, covariance_paths, expected_riccati_map,
                                      iterate_expected_riccati, measurement_update)


def _joint_update(P, C, R):
    S = C @ P @ C.T + R
    return P - P @ C.T @ np.linalg.solve(S, C @ P)


def test_sequential_update_equals_joint_update(rng):
    n = 3
    M = rng.normal(size=(n, n))
    P = M @ M.T + np.eye(n)
    C = rng.normal(size=(2, n))
    R = np.diag([0.3, 0.7])
    post = P[None]
    for s in as_sensors(C, R):
        post = measurement_update(post, s, np.array([True]))
    assert np.allclose(post[0], _joint_update(P, C, R))


def test_matrix_path_matches_per_path_loop(rng):
    A = np.array([[1.2, 0.5], [0.0, 0.9]])  # non-symmetric: transposition slips show
    Q = np.diag([0.2, 0.1])
    sensors = [Sensor([[1.0, 0.0]], [[0.5]]), Sensor([[0.3, 1.0]], [[0.2]])]
    arrivals = rng.random((5, 12, 2)) < 0.6
    P0 = np.eye(2)
    batched = covariance_paths(P0, A, Q, sensors, arrivals)
    for i in range(5):
        P = P0.copy()
        for k in range(12):
            rows = [j for j in range(2) if arrivals[i, k, j]]
            if rows:
                C = np.vstack([sensors[j].C for j in rows])
                R = np.diag([sensors[j].R[0, 0] for j in rows])
                P = _joint_update(P, C, R)
            P = A @ P @ A.T + Q
            assert np.allclose(batched[i, k + 1], P)


def test_scalar_fast_path_matches_matrix_path(rng):
    arrivals = rng.random((50, 30)) < 0.5
    fast = covariance_paths(10.0, [[1.5]], [[0.1]], [Sensor([[2.0]], [[0.5]])], arrivals)
    # embed the scalar system as the first state of a decoupled 2-D system
    A = np.diag([1.5, 0.5])
    sensors = [Sensor([[2.0, 0.0]], [[0.5]])]
    slow = covariance_paths(np.diag([10.0, 1.0]), A, np.diag([0.1, 0.1]), sensors, arrivals)
    assert np.allclose(fast, slow[:, :, 0, 0])


def test_diverging_paths_are_inf_not_nan():
    arrivals = np.zeros((3, 3000), dtype=bool)
    arrivals[0, -1] = True
    p = covariance_paths(1.0, [[2.0]], [[1.0]], [Sensor([[1.0]], [[1.0]])], arrivals, keep="last")
    assert not np.any(np.isnan(p))
    assert np.isinf(p[1]) and np.isfinite(p[0])  # an arrival after overflow brings p back to a^2 R + Q


def test_expected_map_single_sensor_is_sinopoli_mare():
    a, q, r, lam, x = 1.5, 0.1, 0.5, 0.6, 2.0
    g = expected_riccati_map([[x]], [[a]], [[q]], [Sensor([[1.0]], [[r]])], [lam])
    assert g[0, 0] == pytest.approx(a * a * x + q - lam * a * a * x * x / (x + r))


def test_expected_map_two_sensors_is_corrected_eq15():
    a, q, s1, s2, l1, l2, x = 1.5, 0.1, 0.2, 0.5, 0.3, 0.6, 1.7
    g = expected_riccati_map([[x]], [[a]], [[q]], [Sensor([[1.0]], [[s1]]), Sensor([[1.0]], [[s2]])], [l1, l2])
    ones = np.ones((2, 1))
    both = (ones.T @ np.linalg.inv(ones * x @ ones.T + np.diag([s1, s2])) @ ones).item()
    expected = (a * a * x + q - l1 * l2 * a * a * x * x * both - l1 * (1 - l2) * a * a * x * x / (x + s1)
                - (1 - l1) * l2 * a * a * x * x / (x + s2))
    assert g[0, 0] == pytest.approx(expected)


def test_iterated_map_reaches_fixed_point():
    seq = iterate_expected_riccati([[1.0]], [[1.5]], [[0.1]], [Sensor([[1.0]], [[0.5]])], [0.8], 300)
    x = seq[-1]
    assert np.allclose(expected_riccati_map(x, [[1.5]], [[0.1]], [Sensor([[1.0]], [[0.5]])], [0.8]), x)


def test_bad_shapes_named():
    with pytest.raises(ValueError, match="sensor R must be"):
        Sensor([[1.0, 0.0]], [[1.0, 0.0], [0.0, 1.0]])
    with pytest.raises(ValueError, match="sensor channels"):
        covariance_paths(1.0, [[1.0]], [[1.0]], [Sensor([[1.0]], [[1.0]])], np.ones((2, 3, 2), dtype=bool))
