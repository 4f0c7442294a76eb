"""Closed-form 2x2 matrix algebra of the `hinf` paper, broadcast over any leading axes.

The filters, the noise model and the motion control of Nelson & Freeman work with 2x2
matrices only (a target in the plane). Writing their inverses, determinants and smallest
eigenvalues in closed form lets every simulation be vectorised over Monte Carlo runs and
agents without a LAPACK call per matrix.
"""

from __future__ import annotations

import sys

import numpy as np

__all__ = ["I2", "det2", "inv2", "sym2", "min_eig2", "rotation", "use_compiled", "kernel_operand", "central_difference"]

I2 = np.eye(2)

# below this many 2x2 matrices a call stays in numpy even where numba is loaded
COMPILED_MIN_BATCH = 64


def use_compiled(kernel: str, n_matrices: int) -> bool:
    """Whether a function with a compiled and a numpy form (bit-identical) runs the compiled one.

    Importing numba and loading a kernel cost a process about 1-2 s, more than the compiled forms save in
    a single scenario; so ``"auto"`` runs them only where numba is already loaded: by the steps that run
    many filter updates (they import :mod:`.filter_kernels` up front) or that use another kernel.

    Parameters
    ----------
    kernel : {"auto", "compiled", "numpy"}
        ``"auto"``: compiled if numba is loaded and the call has at least ``COMPILED_MIN_BATCH`` matrices.
    n_matrices : int
        Number of 2x2 matrices in the call.

    Returns
    -------
    bool
    """
    if kernel not in ("auto", "compiled", "numpy"):
        raise ValueError(f"kernel must be 'auto', 'compiled' or 'numpy', got {kernel!r}")
    if kernel == "auto":
        return "numba" in sys.modules and n_matrices >= COMPILED_MIN_BATCH
    return kernel == "compiled"


def kernel_operand(a, shape):
    """``a`` broadcast to ``shape`` as a C-ordered, writable float64 array (one compiled signature).

    Parameters
    ----------
    a : array_like
        The operand (a scalar, or an array broadcastable to ``shape``).
    shape : tuple of int
        The shape the compiled kernel expects.

    Returns
    -------
    ndarray
        ``a`` itself when it already is such an array of that shape, else a copy.
    """
    if (isinstance(a, np.ndarray) and a.shape == shape and a.dtype == np.float64 and a.flags.c_contiguous
            and a.flags.writeable):
        return a
    return np.array(np.broadcast_to(a, shape), dtype=float, order="C")


def det2(a):
    """Determinant of 2x2 matrices.

    Parameters
    ----------
    a : ndarray, shape ``(..., 2, 2)``
        A stack of 2x2 matrices.

    Returns
    -------
    ndarray, shape ``(...)``
        ``a_00 a_11 - a_01 a_10``.
    """
    return a[..., 0, 0] * a[..., 1, 1] - a[..., 0, 1] * a[..., 1, 0]


def inv2(a):
    """Closed-form inverse of 2x2 matrices (no LAPACK call per matrix).

    Parameters
    ----------
    a : ndarray, shape ``(..., 2, 2)``
        A stack of 2x2 matrices, each nonsingular (a singular one gives inf or nan, not an error).

    Returns
    -------
    ndarray, shape ``(..., 2, 2)``
        ``adj(a) / det(a)``.
    """
    d = det2(a)
    out = np.empty_like(a, dtype=float)
    out[..., 0, 0] = a[..., 1, 1]
    out[..., 1, 1] = a[..., 0, 0]
    out[..., 0, 1] = -a[..., 0, 1]
    out[..., 1, 0] = -a[..., 1, 0]
    return out / d[..., None, None]


def sym2(a):
    """Symmetric part of square matrices.

    Parameters
    ----------
    a : ndarray, shape ``(..., n, n)``
        A stack of square matrices.

    Returns
    -------
    ndarray, shape ``(..., n, n)``
        ``(a + a^T) / 2``.
    """
    return 0.5 * (a + np.swapaxes(a, -1, -2))


def min_eig2(a):
    """Smallest eigenvalue of the symmetric part of 2x2 matrices.

    Parameters
    ----------
    a : ndarray, shape ``(..., 2, 2)``
        A stack of 2x2 matrices (need not be symmetric: their symmetric part is used).

    Returns
    -------
    ndarray, shape ``(...)``
        ``tr/2 - sqrt((s_00 - s_11)^2 / 4 + s_01^2)`` with ``s = (a + a^T)/2``.
    """
    s = sym2(a)
    tr = s[..., 0, 0] + s[..., 1, 1]
    diff = s[..., 0, 0] - s[..., 1, 1]
    return 0.5 * tr - np.sqrt(0.25 * diff * diff + s[..., 0, 1] ** 2)


def rotation(theta):
    """Rotation matrices ``T(theta) = [[cos, -sin], [sin, cos]]`` of eq (3).

    Parameters
    ----------
    theta : array_like
        Angles in radians.

    Returns
    -------
    ndarray, shape ``theta.shape + (2, 2)``
        ``T(theta)``, mapping the sensor frame (range, cross-range) to the world frame.
    """
    theta = np.asarray(theta, dtype=float)
    c, s = np.cos(theta), np.sin(theta)
    return np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2)


def central_difference(fun, z: float, eps: float = 1e-6):
    """Central finite difference ``(f(z + eps) - f(z - eps)) / (2 eps)`` of a scalar- or matrix-valued ``fun``.

    Parameters
    ----------
    fun : callable
        ``fun(z)`` returning a number or an array.
    z : float
        Point of the derivative.
    eps : float
        Half step.

    Returns
    -------
    float or ndarray
        The derivative estimate, error ``O(eps^2)`` (exact for quadratics up to rounding).
    """
    return (fun(z + eps) - fun(z - eps)) / (2 * eps)
