"""The shared ``fma`` intrinsic rounds once: against exact rational arithmetic rounded to a double."""

from fractions import Fraction

import numpy as np
from numba import njit

from netrepro.engines.intrinsics import fma


@njit
def _fma_all(x, y, z, out):
    for i in range(len(x)):
        out[i] = fma(x[i], y[i], z[i])


def _exact(x, y, z):
    return float(Fraction(x) * Fraction(y) + Fraction(z))  # one rounding of the exact value


def test_fma_is_the_correctly_rounded_product_plus_sum(rng):
    x, y, z = rng.standard_normal((3, 500)) * rng.choice([1e-8, 1.0, 1e8], (3, 500))
    out = np.empty(500)
    _fma_all(x, y, z, out)
    assert [float(v) for v in out] == [_exact(a, b, c) for a, b, c in zip(x, y, z)]


def test_fma_differs_from_multiply_then_add_where_that_rounds_twice():
    e = 2.0 ** -30
    x, y, z = np.array([1 + e]), np.array([1 - e]), np.array([-1.0])
    out = np.empty(1)
    _fma_all(x, y, z, out)
    assert out[0] == -(2.0 ** -60) and x[0] * y[0] + z[0] == 0.0
