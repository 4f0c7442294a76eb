"""The compiled kernels' building blocks, each against an independent computation."""

import numpy as np
import pytest

from netrepro.engines import kernels
from netrepro.engines.riccati import Sensor, covariance_paths


@pytest.mark.parametrize("n", [1, 2, 3, 4])
def test_packed_index_enumerates_the_upper_triangle_once(n):
    idx = kernels.packed_index(n)
    assert np.array_equal(idx, idx.T)
    a, b = np.triu_indices(n)
    assert np.array_equal(idx[a, b], np.arange(n * (n + 1) // 2))


@pytest.mark.parametrize("n", [1, 2, 3])
def test_packed_prediction_equals_the_matrix_product(rng, n):
    A = rng.normal(size=(n, n))
    Q = rng.normal(size=(n, n))
    Q = Q @ Q.T
    X = rng.normal(size=(n, n))
    P = X @ X.T
    M, q = kernels.packed_prediction(A, Q)
    a, b = np.triu_indices(n)
    want = (A @ P @ A.T + Q)[a, b]
    assert np.allclose(M @ P[a, b] + q, want, rtol=1e-13, atol=1e-13)


def test_compiled_gilbert_elliott_two_channels_matches_numpy_kernel(rng):
    from netrepro.engines.channels import gilbert_elliott_arrivals

    A = np.array([[1.05, 0.2, 0.0], [0.0, 0.9, 0.3], [0.1, 0.0, 1.1]])
    sensors = [Sensor([[1.0, 0.0, 0.5]], [[0.3]]), Sensor([[0.0, 1.0, 1.0]], [[0.7]])]
    arrivals = np.stack([gilbert_elliott_arrivals(rng, 517, 60, 0.2, 0.5) for _ in sensors], axis=-1)
    got = covariance_paths(np.eye(3), A, 0.2 * np.eye(3), sensors, arrivals, kernel="compiled")
    ref = covariance_paths(np.eye(3), A, 0.2 * np.eye(3), sensors, arrivals, kernel="numpy")
    scale = np.max(np.abs(ref), axis=(2, 3), keepdims=True)  # entries near 0 are compared at the matrix's scale
    assert np.max(np.abs(got - ref) / scale) < 1e-12


def test_unknown_kernel_is_refused_by_name():
    with pytest.raises(ValueError, match="kernel must be one of"):
        covariance_paths(1.0, [[1.0]], [[1.0]], [Sensor([[1.0]], [[1.0]])], np.ones((2, 3), dtype=bool),
                         kernel="fortran")


@pytest.mark.parametrize("T, m", [(16, 1), (13, 2), (5, 3)])  # row lengths 16, 26, 15: with and without padding
def test_block_transpose_of_arrival_words_equals_packbits(rng, T, m):
    arrivals = rng.random((37, T, m)) < 0.5
    words = kernels.arrival_words(arrivals)
    out = np.zeros((words.shape[1], 40), dtype=np.uint8)
    kernels._transpose_block(words, 3, 30, out)
    want = np.packbits(arrivals.reshape(37, T * m), axis=1)[3:33].T  # big-endian bit order, zero-padded
    assert np.array_equal(out[:, :30], want)
