"""Gradient motion control of the `hinf` paper, eqs (10)-(16) and (12).

Each agent moves along the steepest descent of ``J = tr Sigma_k`` with respect to its own
position, using the gradient recursion (14) for ``Sigma_k^z``.
"""

from __future__ import annotations

import math

import numpy as np

from .algebra import I2, inv2, kernel_operand, rotation, use_compiled
from .noise import plane_norm

__all__ = ["sigma_gradient", "printed_sigma_gradient", "control_law", "printed_control_law", "path_statistics"]


def sigma_gradient(Delta, dDelta, S, dS, gamma_inv2, Lbar, kernel: str = "auto"):
    """Covariance ``Sigma_k`` and its derivative w.r.t. one sensor coordinate, eqs (14)-(16) corrected.

    With ``Omega = I + S Delta - gamma^{-2} L^T Q L Delta`` (eq (11); the paper's (16) prints
    ``- C^T M^{-1} C Delta``, erratum E2) and ``Sigma = Delta Omega^{-1}``:

    .. math::

        \\Sigma^z = \\Delta^z \\Omega^{-1}
            - \\Delta \\Omega^{-1} C^T \\frac{\\partial M^{-1}}{\\partial z} C \\Delta \\Omega^{-1}
            - \\Delta \\Omega^{-1} (C^T M^{-1} C \\Delta^z - \\gamma^{-2} L^T Q L \\Delta^z) \\Omega^{-1}

    (the paper's (15) prints ``+`` on the middle term, erratum E3). ``dDelta = A Sigma^z_{k-1} A^T``
    is eq (14).

    Parameters
    ----------
    Delta, dDelta, S, dS : ndarray, shape ``(..., 2, 2)``
        ``Delta_k``, ``Delta_k^z``, ``C^T M^{-1} C``, ``C^T (dM^{-1}/dz) C``.
    gamma_inv2 : float
        ``gamma^{-2}``.
    Lbar : ndarray, shape ``(2, 2)``
        ``L^T Q L``.
    kernel : {"auto", "compiled", "numpy"}
        ``"compiled"``: :func:`.filter_kernels.sigma_gradient_kernel`, the same arithmetic matrix by matrix
        (bit-identical); ``"numpy"``: the reference form; ``"auto"``: see :func:`.algebra.use_compiled`.

    Returns
    -------
    Sigma, dSigma : ndarray, shape ``(..., 2, 2)``
    """
    shapes = [np.shape(a) for a in (Delta, dDelta, S, dS)]
    lead = np.broadcast_shapes(*(sh[:-2] for sh in shapes))
    if not use_compiled(kernel, math.prod(lead)):
        return _sigma_gradient_numpy(Delta, dDelta, S, dS, gamma_inv2, Lbar)
    from .filter_kernels import sigma_gradient_kernel  # numba: imported by the steps that move agents

    def flat(a):
        return kernel_operand(a, lead + (2, 2)).reshape(-1, 2, 2)

    Sigma, dSigma = np.empty(lead + (2, 2)), np.empty(lead + (2, 2))
    sigma_gradient_kernel(flat(Delta), flat(dDelta), flat(S), flat(dS), float(gamma_inv2),
                          np.array(Lbar, dtype=float, order="C"), Sigma.reshape(-1, 2, 2), dSigma.reshape(-1, 2, 2))
    return Sigma, dSigma


def _sigma_gradient_numpy(Delta, dDelta, S, dS, gamma_inv2, Lbar):
    """Eqs (14)-(16) corrected in numpy (the reference form of :func:`sigma_gradient`): ``Sigma, dSigma``."""
    Omega = I2 + S @ Delta - gamma_inv2 * Lbar @ Delta
    Oi = inv2(Omega)
    DOi = Delta @ Oi
    dSigma = dDelta @ Oi - DOi @ dS @ DOi - DOi @ (S @ dDelta - gamma_inv2 * Lbar @ dDelta) @ Oi
    return Delta @ Oi, dSigma


def printed_sigma_gradient(Delta, dDelta, S, dS, gamma_inv2, Lbar):
    """Eqs (15)-(16) exactly as printed (``Omega = I - g L Delta - S Delta``, ``+`` middle term).

    Parameters
    ----------
    Delta, dDelta, S, dS : ndarray, shape ``(..., 2, 2)``
        ``Delta_k``, ``Delta_k^z`` (eq (14)), ``C^T M^{-1} C`` and ``C^T (dM^{-1}/dz) C``.
    gamma_inv2 : float
        ``gamma^{-2}``.
    Lbar : ndarray, shape ``(2, 2)``
        ``L^T Q L``.

    Returns
    -------
    ndarray, shape ``(..., 2, 2)``
        The printed ``Sigma^z`` (wrong: errata E2, E3).
    """
    Omega = I2 - gamma_inv2 * Lbar @ Delta - S @ Delta
    Oi = inv2(Omega)
    DOi = Delta @ Oi
    return dDelta @ Oi + DOi @ dS @ DOi - DOi @ (S @ dDelta - gamma_inv2 * Lbar @ dDelta) @ Oi


def control_law(dJ_dr, dJ_dtheta, r, theta, Gamma: float, v_max: float = np.inf, kernel: str = "auto"):
    """Gradient motion control law, eq (12) corrected, with a speed limit.

    With ``theta_i = angle(x - p_i)`` (Section II), ``grad_{p_i} J = -T_i [dJ/dr; dJ/dtheta / r]``,
    so steepest descent is

    .. math:: u_i = \\Gamma\\, T_i \\begin{bmatrix} \\partial J/\\partial r_i \\\\
              r_i^{-1} \\partial J / \\partial \\theta_i \\end{bmatrix}

    (the paper prints ``-Gamma T_i^T [...]``, erratum E5). The step is then scaled down to
    length ``v_max`` if longer (the agents' "limited motion capabilities", a reconstruction).

    Parameters
    ----------
    dJ_dr, dJ_dtheta, r, theta : ndarray, same shape
        Derivatives of ``J`` w.r.t. range and bearing, range and bearing.
    Gamma : float
        Control gain of eq (12).
    v_max : float
        Largest step length.
    kernel : {"auto", "compiled", "numpy"}
        ``"compiled"``: ``T_i [...]`` by :func:`.filter_kernels.rotate_kernel` (bit-identical; arguments of one
        shape); ``"numpy"``: the reference form; ``"auto"``: see :func:`.algebra.use_compiled`.

    Returns
    -------
    ndarray, shape ``r.shape + (2,)``
        The steps ``u_i``.
    """
    theta = np.asarray(theta, dtype=float)
    if np.shape(dJ_dr) == np.shape(dJ_dtheta) == np.shape(r) == theta.shape and use_compiled(kernel, theta.size):
        from .filter_kernels import rotate_kernel  # T(theta) v as numpy's matmul rounds it (bit-identical)

        Tv = np.empty(theta.shape + (2,))
        rotate_kernel(np.cos(theta).ravel(), np.sin(theta).ravel(), np.asarray(dJ_dr, dtype=float).ravel(),
                      np.asarray(dJ_dtheta / r, dtype=float).ravel(), Tv.reshape(-1, 2))
        u = Gamma * Tv
    else:
        local = np.stack([dJ_dr, dJ_dtheta / r], -1)
        u = Gamma * (rotation(theta) @ local[..., None])[..., 0]
    norm = plane_norm(u)[..., None]  # np.linalg.norm(axis=-1, keepdims=True), bit for bit
    scale = np.where(norm > v_max, v_max / np.maximum(norm, 1e-300), 1.0)
    return u * scale


def printed_control_law(dJ_dr, dJ_dtheta, r, theta, Gamma: float):
    """Eq (12) as printed: ``u_i = -Gamma T_i^T [dJ/dr; dJ/dtheta / r]`` (no speed limit).

    Parameters
    ----------
    dJ_dr, dJ_dtheta, r, theta : ndarray, same shape
        Derivatives of ``J`` w.r.t. range and bearing (eq (13)), range and bearing (radians).
    Gamma : float
        Control gain of eq (12).

    Returns
    -------
    ndarray, shape ``r.shape + (2,)``
        The printed steps ``u_i`` (wrong: the sign and ``T_i^T`` for ``T_i``, erratum E5).
    """
    local = np.stack([dJ_dr, dJ_dtheta / r], -1)
    return -Gamma * (np.swapaxes(rotation(theta), -1, -2) @ local[..., None])[..., 0]


def path_statistics(paths, v_max: float, target=None) -> dict[str, np.ndarray]:
    """How the agents' paths move: heading reversals, clipped steps, step length, strokes and their direction, per run.

    A step is ``p_i(k+1) - p_i(k)``. A heading reversal is a pair of consecutive steps of one agent
    whose directions are more than 90 degrees apart (negative inner product): the zig-zag of Fig 6.
    A clipped step is one the speed limit of :func:`control_law` shortened (length ``v_max`` to
    within 1e-9 relative). A stroke is the run of steps between two consecutive reversals of one agent
    (its length in steps: the difference of their step indices). The tangential share of a step is the
    part of its squared length across the line of sight from the agent at the step's start to the target at its
    end (in :func:`.model.simulate` the target moves before the agents), ``(s . t)^2 / |s|^2`` with ``t`` the unit
    vector perpendicular to ``x(k+1) - p_i(k)`` (1: a pure bearing move, 0: a
    pure range move; 0.5 for directions drawn uniformly).

    Parameters
    ----------
    paths : array_like, shape (runs, steps + 1, agents, 2)
        Agent positions over time (``simulate(...)["agents"]``).
    v_max : float
        The speed limit of the control law (largest step length).
    target : array_like, shape (runs, steps + 1, 2), optional
        The target's positions (``simulate(...)["target"]``); needed for ``tangential_share``.

    Returns
    -------
    dict of str to ndarray, each of shape (runs,)
        ``reversal_fraction`` (reversals per pair of consecutive steps, over agents and time),
        ``clipped_fraction`` (clipped steps per step), ``mean_step`` (mean step length),
        ``stroke_median`` (median stroke length in steps over the run's agents; NaN without two reversals),
        ``one_step_strokes`` (fraction of the run's strokes of one step; NaN without a stroke) and, with
        ``target``, ``tangential_share`` (sum over agents and steps of ``(s . t)^2`` over that of ``|s|^2``).
    """
    paths = np.asarray(paths, dtype=float)
    steps = np.diff(paths, axis=1)
    length = np.linalg.norm(steps, axis=-1)
    turns = np.einsum("rkad,rkad->rka", steps[:, 1:], steps[:, :-1])
    rev = turns < 0
    R = paths.shape[0]
    med, one = np.full(R, np.nan), np.full(R, np.nan)
    for r in range(R):
        strokes = np.concatenate([np.diff(np.flatnonzero(rev[r, :, a])) for a in range(rev.shape[2])])
        if len(strokes):
            med[r], one[r] = np.median(strokes), np.mean(strokes == 1)
    out = {"reversal_fraction": rev.mean(axis=(1, 2)),
           "clipped_fraction": (length >= v_max * (1 - 1e-9)).mean(axis=(1, 2)),
           "mean_step": length.mean(axis=(1, 2)), "stroke_median": med, "one_step_strokes": one}
    if target is not None:
        # line of sight from the agent at the step's start to the target it steers toward (the target moves first)
        los = np.asarray(target, dtype=float)[:, 1:, None, :] - paths[:, :-1]
        los_len = np.maximum(np.linalg.norm(los, axis=-1), 1e-12)
        across = (steps[..., 0] * -los[..., 1] + steps[..., 1] * los[..., 0]) / los_len  # s . t, t = rot90(los) / |los|
        out["tangential_share"] = (across ** 2).sum(axis=(1, 2)) / np.maximum((length ** 2).sum(axis=(1, 2)), 1e-300)
    return out
