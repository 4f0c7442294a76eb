"""Sensing geometry and the range-bearing noise model of the `hinf` paper, eqs (2)-(4), (17)-(18).

Conventions (Section II): target position ``x`` and agent positions ``p_i`` in the plane;
range ``r_i = |x - p_i|``, bearing ``theta_i = angle(x - p_i)``. Each agent measures the
position directly (``C_i = I_2``) with noise ``m_i`` of covariance
``M_i = T_i diag(f_r, f_b) T_i^T`` (eqs (3)-(4)).
"""

from __future__ import annotations

import math

import numpy as np

from ...errors import InputError
from .algebra import kernel_operand, rotation, use_compiled

__all__ = [
    "NoiseModel", "geometry", "plane_norm", "noise_variances", "noise_covariance", "noise_information",
    "printed_dinfo_dtheta", "dinfo_dr_reading", "sample_noise", "fit_noise_model",
]

_J = np.array([[0.0, -1.0], [1.0, 0.0]])


def geometry(target, agents):
    """Range and bearing of the target seen from each agent (Section II).

    Parameters
    ----------
    target : ndarray, shape ``(..., 2)``
        Target position ``x``; broadcast against ``agents`` after inserting an agent axis.
    agents : ndarray, shape ``(..., N, 2)``
        Agent positions ``p_i``.

    Returns
    -------
    r, theta : ndarray, shape ``(..., N)``
        ``r_i = |x - p_i|`` and ``theta_i = angle(x - p_i)``.
    """
    d = np.asarray(target, dtype=float)[..., None, :] - np.asarray(agents, dtype=float)
    return np.hypot(d[..., 0], d[..., 1]), np.arctan2(d[..., 1], d[..., 0])


def plane_norm(d):
    """``np.linalg.norm(d, axis=-1)`` of vectors in the plane, bit for bit, without its generic reduction.

    numpy computes it as ``sqrt(add.reduce(d * d, axis=-1))``; a reduction over two elements is the one sum
    ``d_0^2 + d_1^2``, written here directly (several times faster on the simulations' small stacked arrays).

    Parameters
    ----------
    d : ndarray, shape ``(..., 2)``
        Real vectors (position errors, separations, velocities).

    Returns
    -------
    ndarray, shape ``(...)``
        Their Euclidean norms.
    """
    s = d * d
    return np.sqrt(s[..., 0] + s[..., 1])


class NoiseModel:
    """Range-bearing noise model, eqs (3)-(4): ``f_r(r) = a2 (r - a1)^2 + a0``, ``f_b = alpha f_r``.

    Parameters
    ----------
    a0, a1, a2, alpha : float
        Smallest range variance ``a0 > 0`` (at the sweet spot ``r = a1``), curvature ``a2 > 0``,
        bearing-to-range variance ratio ``alpha > 0``.

    Raises
    ------
    InputError
        If ``a0``, ``a2`` or ``alpha`` is not positive.
    """

    def __init__(self, a0: float, a1: float, a2: float, alpha: float):
        for name, val in (("a0", a0), ("a2", a2), ("alpha", alpha)):
            if not val > 0:
                raise InputError(f"noise parameter {name} must be > 0, got {val!r}")
        self.a0, self.a1, self.a2, self.alpha = float(a0), float(a1), float(a2), float(alpha)

    @classmethod
    def from_config(cls, section: dict) -> "NoiseModel":
        """The model of a configuration section with keys ``a0, a1, a2, alpha``."""
        return cls(section["a0"], section["a1"], section["a2"], section["alpha"])


def noise_variances(r, model: NoiseModel):
    """Range and bearing noise variances, eq (4).

    .. math:: f_r(r) = a_2 (r - a_1)^2 + a_0, \\qquad f_b(r) = \\alpha f_r(r)

    Parameters
    ----------
    r : array_like
        Ranges ``r_i = |x - p_i|`` (the length unit of ``a1``).
    model : NoiseModel
        The range-bearing noise model of eqs (3)-(4) (``a0``, ``a1``, ``a2``, ``alpha``).

    Returns
    -------
    f_r, f_b : ndarray, shape of ``r``
        Range and bearing noise variances.
    """
    r = np.asarray(r, dtype=float)
    fr = model.a2 * (r - model.a1) ** 2 + model.a0
    return fr, model.alpha * fr


def noise_covariance(r, theta, model: NoiseModel):
    """Measurement noise covariance ``M = T(theta) diag(f_r, f_b) T(theta)^T`` implied by eq (3).

    Eq (3) gives the square root ``T diag(sqrt f_r, sqrt f_b)`` of this covariance.

    Parameters
    ----------
    r, theta : array_like
        Range and bearing (radians) of the target from the agent (same shape).
    model : NoiseModel
        The range-bearing noise model of eqs (3)-(4) (``a0``, ``a1``, ``a2``, ``alpha``).

    Returns
    -------
    ndarray, shape ``r.shape + (2, 2)``
        The covariance ``M`` (world frame).
    """
    fr, fb = noise_variances(r, model)
    T = rotation(theta)
    R = np.zeros(np.shape(fr) + (2, 2))
    R[..., 0, 0], R[..., 1, 1] = fr, fb
    return T @ R @ np.swapaxes(T, -1, -2)


def noise_information(r, theta, model: NoiseModel, derivatives: bool = False, kernel: str = "auto"):
    """Information matrix ``M^{-1}`` and (optionally) its derivatives, eqs (17)-(18), corrected.

    .. math::

        \\frac{\\partial M^{-1}}{\\partial r} = -2 a_2 (r - a_1)\\, T R^{-2}
            \\begin{bmatrix}1&0\\\\0&\\alpha\\end{bmatrix} T^T, \\qquad
        \\frac{\\partial M^{-1}}{\\partial \\theta} = \\Psi + \\Psi^T, \\quad \\Psi = J T R^{-1} T^T

    with ``J = [[0, -1], [1, 0]]``. The paper prints
    ``V^{-1} (Psi + Psi^T) V^{-1}`` for the bearing derivative (erratum E4;
    see :func:`printed_dinfo_dtheta`); the range derivative (17) is correct.

    Parameters
    ----------
    r, theta : array_like
        Range and bearing (radians) of the target from the agent (same shape).
    model : NoiseModel
        The range-bearing noise model of eqs (3)-(4) (``a0``, ``a1``, ``a2``, ``alpha``).
    derivatives : bool
        Also return the derivatives with respect to ``r`` and ``theta``.
    kernel : {"auto", "compiled", "numpy"}
        ``"compiled"``: the products by :func:`.filter_kernels.noise_information_kernel`, the same arithmetic
        matrix by matrix (bit-identical); ``"numpy"``: the reference form; ``"auto"``: see
        :func:`.algebra.use_compiled`.

    Returns
    -------
    Minv or (Minv, dMinv_dr, dMinv_dtheta) : ndarray, shape ``r.shape + (2, 2)``
    """
    shape = np.broadcast_shapes(np.shape(r), np.shape(theta))
    if not use_compiled(kernel, math.prod(shape)):
        return _noise_information_numpy(r, theta, model, derivatives)
    from .filter_kernels import noise_information_kernel  # numba: imported by the steps that simulate

    fr, fb = noise_variances(np.broadcast_to(r, shape), model)
    theta = np.asarray(theta, dtype=float)
    c, s = (kernel_operand(f(theta), shape).ravel() for f in (np.cos, np.sin))  # copied only if broadcast
    rinv_r, rinv_b = 1.0 / fr.ravel(), 1.0 / fb.ravel()
    if derivatives:
        g = -2.0 * model.a2 * (np.asarray(r, dtype=float) - model.a1)
        d_r, d_b = (kernel_operand(v, shape).ravel()
                    for v in (g / fr**2, g * model.alpha / fb**2))  # R^{-2} diag(1, alpha)
    else:
        d_r = d_b = rinv_r
    out = [np.empty(shape + (2, 2)) for _ in range(3 if derivatives else 1)]
    flat = [o.reshape(-1, 2, 2) for o in out] + [out[0].reshape(-1, 2, 2)] * (2 if not derivatives else 0)
    noise_information_kernel(c, s, rinv_r, rinv_b, d_r, d_b, bool(derivatives), *flat)
    return tuple(out) if derivatives else out[0]


def _noise_information_numpy(r, theta, model: NoiseModel, derivatives: bool = False):
    """Eqs (3), (17)-(18) corrected in numpy (the reference form of :func:`noise_information`)."""
    fr, fb = noise_variances(r, model)
    T = rotation(theta)
    Tt = np.swapaxes(T, -1, -2)
    Rinv = np.zeros(np.shape(fr) + (2, 2))
    Rinv[..., 0, 0], Rinv[..., 1, 1] = 1.0 / fr, 1.0 / fb
    Minv = T @ Rinv @ Tt
    if not derivatives:
        return Minv
    g = -2.0 * model.a2 * (np.asarray(r, dtype=float) - model.a1)
    D = np.zeros_like(Rinv)
    D[..., 0, 0], D[..., 1, 1] = g / fr**2, g * model.alpha / fb**2  # R^{-2} diag(1, alpha)
    dr = T @ D @ Tt
    psi = _J @ Minv
    return Minv, dr, psi + np.swapaxes(psi, -1, -2)


def printed_dinfo_dtheta(r, theta, model: NoiseModel):
    """Bearing derivative of ``V^{-1}`` as printed in eqs (17)-(18): ``V^{-1}(Psi + Psi^T)V^{-1}``.

    Parameters
    ----------
    r, theta : array_like
        Range and bearing (radians) of the target from the agent (same shape).
    model : NoiseModel
        The range-bearing noise model of eqs (3)-(4) (``a0``, ``a1``, ``a2``, ``alpha``).

    Returns
    -------
    ndarray, shape ``r.shape + (2, 2)``
        The printed form, with ``Psi = J T R^{-1} T^T`` (wrong: erratum E4).
    """
    Minv = noise_information(r, theta, model)
    psi = _J @ Minv
    return Minv @ (psi + np.swapaxes(psi, -1, -2)) @ Minv


def dinfo_dr_reading(r, theta, model: NoiseModel, reading: str = "variances"):
    """Range derivative of ``M^{-1}`` by eq (17), under a reading of its undefined ``R`` (erratum E9).

    Eq (17) reads ``d V^{-1}/d r = -2 a2 (r - a1) T R^{-2} diag(1, alpha) T^T`` (``V = M_i``). With
    ``R = diag(f_r, f_b)`` (``reading="variances"``) this is the derivative of :func:`noise_information`;
    with ``R = diag(sqrt f_r, sqrt f_b)``, the matrix of eq (3) (``reading="square_roots"``), it is not.

    Parameters
    ----------
    r, theta : float
        Range and bearing.
    model : NoiseModel
        The range-bearing noise model of eqs (3)-(4) (``a1``, ``a2``, ``alpha``).
    reading : {"variances", "square_roots"}
        The reading of ``R`` in eq (17): the variances ``diag(f_r, f_b)`` or their square roots (the matrix
        of eq (3)).

    Returns
    -------
    ndarray, shape ``(2, 2)``
        ``d M^{-1} / d r`` under that reading.

    Raises
    ------
    ValueError
        If ``reading`` is unknown.
    """
    f_r, f_b = noise_variances(r, model)
    if reading == "variances":
        inv_r2 = np.diag([f_r ** -2, f_b ** -2])
    elif reading == "square_roots":
        inv_r2 = np.diag([1 / f_r, 1 / f_b])
    else:
        raise ValueError(f"unknown reading {reading!r}; expected 'variances' or 'square_roots'")
    T = rotation(theta)
    return -2 * model.a2 * (r - model.a1) * T @ inv_r2 @ np.diag([1.0, model.alpha]) @ T.T


def sample_noise(rng: np.random.Generator, r, theta, model: NoiseModel, kernel: str = "auto"):
    """Draw measurement noise ``m_i = T_i diag(sqrt f_r, sqrt f_b) eps_i``, ``eps_i ~ N(0, I_2)`` (eq (3)).

    Parameters
    ----------
    rng : numpy.random.Generator
        The random generator the standard normal ``eps_i`` are drawn from.
    r, theta : array_like
        Range and bearing (radians) of the target from the agent (same shape).
    model : NoiseModel
        The range-bearing noise model of eqs (3)-(4) (``a0``, ``a1``, ``a2``, ``alpha``).
    kernel : {"auto", "compiled", "numpy"}
        ``"compiled"``: the rotation by :func:`.filter_kernels.rotate_kernel`, the same arithmetic sensor by
        sensor (bit-identical; ``r`` and ``theta`` of one shape); ``"numpy"``: the reference form;
        ``"auto"``: see :func:`.algebra.use_compiled`.

    Returns
    -------
    ndarray, shape ``r.shape + (2,)``
        One noise vector ``m_i`` (world frame) per range.
    """
    fr, fb = noise_variances(r, model)
    eps = rng.standard_normal(np.shape(fr) + (2,))
    v0, v1 = np.sqrt(fr) * eps[..., 0], np.sqrt(fb) * eps[..., 1]
    theta = np.asarray(theta, dtype=float)
    if theta.shape != fr.shape or not use_compiled(kernel, fr.size):
        local = np.stack([v0, v1], -1)
        return (rotation(theta) @ local[..., None])[..., 0]
    from .filter_kernels import rotate_kernel  # numba: imported by the steps that simulate

    out = np.empty(fr.shape + (2,))
    rotate_kernel(np.cos(theta).ravel(), np.sin(theta).ravel(), v0.ravel(), v1.ravel(), out.reshape(-1, 2))
    return out


def fit_noise_model(r, var_range, var_bearing) -> dict:
    """Recover ``a0, a1, a2, alpha`` of eq (4) from variances by least squares.

    Parameters
    ----------
    r : array_like
        Ranges.
    var_range, var_bearing : array_like
        Variances along and across the line of sight at each range.

    Returns
    -------
    dict
        ``a0, a1, a2`` from a quadratic fit of ``var_range``, ``alpha = sum var_bearing / sum var_range``.
    """
    r = np.asarray(r, dtype=float)
    c2, c1, c0 = np.polyfit(r, np.asarray(var_range, dtype=float), 2)
    a2 = c2
    a1 = -c1 / (2 * c2)
    a0 = c0 - c2 * a1 ** 2
    alpha = float(np.sum(var_bearing) / np.sum(var_range))
    return {"a0": a0, "a1": a1, "a2": a2, "alpha": alpha}
