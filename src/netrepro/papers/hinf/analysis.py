"""Analyses of the `hinf` paper that the evidence quotes: the errata residuals, the gains of eq (6)
at the agents' start and end geometry, the sweet spot of eq (4), settling and ordering comparisons.

Moved out of :mod:`.evidence` (issue 29, part 3): the evidence step only selects and formats,
every number it quotes comes from here, from the other math modules or from the result tables.

The errata residuals compare each printed equation with its corrected form against an
independent computation (sampling, central finite differences), at one fixed test geometry drawn
from the configured seed (:func:`errata_residuals`).
"""

from __future__ import annotations

import math

import numpy as np

from .algebra import central_difference, rotation
from .filters import FilterDoesNotExist, gain_norms, steady_state_prior
from .model import settle_step
from .motion import control_law, printed_control_law, printed_sigma_gradient, sigma_gradient
from .noise import (NoiseModel, dinfo_dr_reading, geometry, noise_covariance, noise_information, noise_variances,
                    printed_dinfo_dtheta, sample_noise)

__all__ = [
    "ERRATA_POINT", "E4_RADII", "E9_RADII", "relative_distance", "ErrataGeometry", "errata_geometry",
    "covariance_form_residuals", "covariance_sampling_scale", "sigma_form_residuals", "sigma_gradient_residuals",
    "bearing_derivative_residuals", "control_direction_residuals", "average_information_residuals",
    "range_derivative_reading_residuals", "errata_residuals", "order_violation", "settles_first",
    "difference_correlation", "disturbance_weight", "information_at_positions", "mean_gain_norms",
    "sweet_spot_grid",
]

# the (range, bearing) at which E1, E4 and E9 are demonstrated: a range near the sweet spot, a generic bearing
ERRATA_POINT = (27.0, 0.9)
# the ranges of E4 (``a1`` of the model is added) and E9: inside, at and beyond the sweet spot
E4_RADII = (5.0, 27.0, 45.0)
E9_RADII = (5.0, 27.0, 45.0)


def relative_distance(a, b) -> float:
    """Relative Frobenius (2-norm for vectors) distance ``||a - b|| / ||b||``.

    Parameters
    ----------
    a : array_like
        The form judged.
    b : array_like
        The reference (nonzero).

    Returns
    -------
    float
    """
    return float(np.linalg.norm(np.asarray(a) - np.asarray(b)) / np.linalg.norm(b))


class ErrataGeometry:
    """The test geometry of the errata E2, E3, E5 and E6: four sensors around a target, a fixed prior.

    Parameters
    ----------
    agents : ndarray, shape ``(4, 2)``
        Sensor positions.
    target : ndarray, shape ``(2,)``
        Target position ``x``.
    Delta : ndarray, shape ``(2, 2)``
        Prior covariance ``Delta`` of eq (6) (fixed, symmetric positive definite).
    gamma_inv2 : float
        ``gamma^-2``.
    Lbar : ndarray, shape ``(2, 2)``
        ``L^T Q L``.

    Attributes
    ----------
    r, theta : ndarray, shape ``(4,)``
        Ranges and bearings of the target from the sensors.
    """

    def __init__(self, agents, target, Delta, gamma_inv2: float, Lbar):
        self.agents = np.asarray(agents, dtype=float)
        self.target = np.asarray(target, dtype=float)
        self.Delta = np.asarray(Delta, dtype=float)
        self.gamma_inv2 = float(gamma_inv2)
        self.Lbar = np.asarray(Lbar, dtype=float)
        self.r, self.theta = geometry(self.target, self.agents)

    def sigma(self, model: NoiseModel, agents=None, r=None):
        """``Sigma = Delta (I + S Delta - gamma^-2 Lbar Delta)^-1`` of eq (6), ``S = sum_i M_i^-1``.

        Parameters
        ----------
        model : NoiseModel
            The noise model of eq (4).
        agents : ndarray, shape ``(4, 2)``, optional
            Other sensor positions (default: the geometry's).
        r : ndarray, shape ``(4,)``, optional
            Other ranges at the geometry's bearings (default: the geometry's).

        Returns
        -------
        ndarray, shape ``(2, 2)``
        """
        if agents is not None:
            rr, tt = geometry(self.target, agents)
        else:
            rr, tt = (self.r if r is None else r), self.theta
        S = noise_information(rr, tt, model).sum(0)
        eye = np.eye(2)
        return self.Delta @ np.linalg.inv(eye + S @ self.Delta - self.gamma_inv2 * self.Lbar @ self.Delta)


def errata_geometry(rng: np.random.Generator, gamma: float) -> ErrataGeometry:
    """The errata's test geometry: four sensors drawn ``N(0, 20^2 I)``, target ``(1, 2)``, ``L^T Q L = I``.

    Parameters
    ----------
    rng : numpy.random.Generator
        Draws the sensor positions (8 normals).
    gamma : float
        Attenuation level of eq (6).

    Returns
    -------
    ErrataGeometry
        With ``Delta = [[0.3, 0.05], [0.05, 0.2]]``.
    """
    agents = rng.normal(scale=20, size=(4, 2))
    return ErrataGeometry(agents, np.array([1.0, 2.0]), np.array([[0.3, 0.05], [0.05, 0.2]]), gamma ** -2,
                          np.eye(2))


def covariance_form_residuals(rng: np.random.Generator, model: NoiseModel, r: float, theta: float, n: int):
    """Erratum E1: eq (3) gives the square root of the noise covariance, not the noise vector.

    Parameters
    ----------
    rng : numpy.random.Generator
        Draws ``n`` noise vectors of eq (3).
    model : NoiseModel
        The noise model of eq (4).
    r, theta : float
        Range and bearing.
    n : int
        Number of samples.

    Returns
    -------
    printed, corrected : float
        Relative distances to the empirical covariance of the samples of ``T diag(sqrt f_r, sqrt f_b)``
        (eq (3) read as the covariance) and of ``M = T diag(f_r, f_b) T^T``.
    """
    emp = np.cov(sample_noise(rng, np.full(n, r), np.full(n, theta), model).T)
    fr, fb = noise_variances(r, model)
    printed = rotation(theta) @ np.diag([math.sqrt(fr), math.sqrt(fb)])
    return relative_distance(printed, emp), relative_distance(noise_covariance(r, theta, model), emp)


def covariance_sampling_scale(M, n: int) -> float:
    """Root-mean-square relative Frobenius distance of the sample covariance of ``n`` Gaussian vectors to ``M``.

    For ``n`` draws of ``N(0, M)`` the sample covariance ``S`` has ``Var S_ij = (M_ii M_jj + M_ij^2) / (n - 1)``
    (Isserlis), so ``E ||S - M||_F^2 = ((tr M)^2 + ||M||_F^2) / (n - 1)``; divided by ``||M||_F``, the scale of
    erratum E1's residuals that sampling alone produces.

    Parameters
    ----------
    M : array_like, shape ``(d, d)``
        The covariance.
    n : int
        Number of draws (> 1).

    Returns
    -------
    float
        ``sqrt(((tr M)^2 + ||M||_F^2) / (n - 1)) / ||M||_F``.
    """
    M = np.asarray(M, dtype=float)
    fro = float(np.linalg.norm(M))
    return math.sqrt((float(np.trace(M)) ** 2 + fro ** 2) / (int(n) - 1)) / fro


def sigma_form_residuals(geo: ErrataGeometry, model: NoiseModel):
    """Erratum E2: the sign of ``S Delta`` in ``Sigma = Delta Omega^-1`` (eqs (6), (15)).

    Parameters
    ----------
    geo : ErrataGeometry
        Test geometry.
    model : NoiseModel
        The noise model of eq (4).

    Returns
    -------
    printed, corrected : float
        Relative distances to ``Sigma`` of eq (6) of ``Delta (I - g Lbar Delta - S Delta)^-1`` (printed) and of
        the ``Sigma`` that :func:`.motion.sigma_gradient` returns.
    """
    eye = np.eye(2)
    g2, Lbar, Delta = geo.gamma_inv2, geo.Lbar, geo.Delta
    S = noise_information(geo.r, geo.theta, model, derivatives=True)[0].sum(0)
    sig_true = geo.sigma(model, r=geo.r.copy())
    sig_printed = Delta @ np.linalg.inv(eye - g2 * Lbar @ Delta - S @ Delta)
    return (relative_distance(sig_printed, sig_true),
            relative_distance(sigma_gradient(Delta, Delta, S, S, g2, Lbar)[0], sig_true))


def _information_and_range_derivative(geo: ErrataGeometry, model: NoiseModel):
    Mi, dMr, dMt = noise_information(geo.r, geo.theta, model, derivatives=True)
    return Mi.sum(0), dMr, dMt


def sigma_gradient_residuals(geo: ErrataGeometry, model: NoiseModel):
    """Erratum E3: the range derivative ``Sigma^r_1`` of eq (16) against a central finite difference.

    Parameters
    ----------
    geo : ErrataGeometry
        Test geometry (``Delta`` held fixed).
    model : NoiseModel
        The noise model of eq (4).

    Returns
    -------
    printed, corrected, spread : float
        Relative distances of :func:`.motion.printed_sigma_gradient` and :func:`.motion.sigma_gradient` to
        the central difference of ``Sigma`` (eq (6)) with respect to sensor 1's range (half step 1e-6), and the
        largest relative distance of that difference to those with half steps 2e-6 and 5e-7 (the finite
        difference's own error, the uncertainty of both residuals).
    """
    S, dMr, _ = _information_and_range_derivative(geo, model)

    def sigma_of(ri):
        rr = geo.r.copy()
        rr[0] = ri
        return geo.sigma(model, r=rr)

    fd = central_difference(sigma_of, geo.r[0])
    # the finite difference's own error: its spread over half steps 2x larger and smaller (rounding grows as the
    # step shrinks, truncation as it grows), a bracket on how far fd is from the derivative
    spread = max(relative_distance(central_difference(sigma_of, geo.r[0], eps=e), fd) for e in (2e-6, 5e-7))
    zero = np.zeros((2, 2))
    _, corr = sigma_gradient(geo.Delta, zero, S, dMr[0], geo.gamma_inv2, geo.Lbar)
    prin = printed_sigma_gradient(geo.Delta, zero, S, dMr[0], geo.gamma_inv2, geo.Lbar)
    return relative_distance(prin, fd), relative_distance(corr, fd), spread


def bearing_derivative_residuals(model: NoiseModel, radii, theta: float):
    """Erratum E4: the bearing derivative of ``M^-1`` in eqs (17)-(18) against central finite differences.

    Parameters
    ----------
    model : NoiseModel
        The noise model of eq (4).
    radii : sequence of float
        Ranges at which it is checked.
    theta : float
        Bearing.

    Returns
    -------
    printed, corrected : float
        Largest relative distance over ``radii`` of :func:`.noise.printed_dinfo_dtheta` and of the corrected
        derivative of :func:`.noise.noise_information`.
    """
    res_p, res_c = [], []
    for rr in radii:
        fdt = central_difference(lambda t: noise_information(rr, t, model), theta)
        _, _, dt = noise_information(rr, theta, model, derivatives=True)
        res_p.append(relative_distance(printed_dinfo_dtheta(rr, theta, model), fdt))
        res_c.append(relative_distance(dt, fdt))
    return max(res_p), max(res_c)


def control_direction_residuals(geo: ErrataGeometry, model: NoiseModel):
    """Erratum E5: the direction of the control law (12) against steepest descent of ``J = tr Sigma``.

    Parameters
    ----------
    geo : ErrataGeometry
        Test geometry; sensor 1 moves.
    model : NoiseModel
        The noise model of eq (4).

    Returns
    -------
    printed, corrected : float
        ``1 - cos`` of the angle between ``u_1`` (:func:`.motion.printed_control_law`,
        :func:`.motion.control_law`) and ``-grad_p J``, the gradient by central finite differences.
    """
    S, dMr, dMt = _information_and_range_derivative(geo, model)
    eye = np.eye(2)
    p0 = geo.agents[0]

    def J_of(p):
        aa = geo.agents.copy()
        aa[0] = p
        return np.trace(geo.sigma(model, agents=aa))

    grad = np.array([central_difference(lambda s: J_of(p0 + s * e), 0.0) for e in eye])
    zero = np.zeros((2, 2))
    _, sr = sigma_gradient(geo.Delta, zero, S, dMr[0], geo.gamma_inv2, geo.Lbar)
    _, st = sigma_gradient(geo.Delta, zero, S, dMt[0], geo.gamma_inv2, geo.Lbar)
    r, th = geo.r, geo.theta
    u_c = control_law(np.trace(sr), np.trace(st), r[0], th[0], 1.0)
    u_p = printed_control_law(np.trace(sr), np.trace(st), r[0], th[0], 1.0)
    desc = -grad / np.linalg.norm(grad)
    return float(1 - u_p @ desc / np.linalg.norm(u_p)), float(1 - u_c @ desc / np.linalg.norm(u_c))


def average_information_residuals(geo: ErrataGeometry, model: NoiseModel):
    """Erratum E6: the decentralized motion law with ``M^-1`` replaced by ``C~`` (printed) or ``N C~`` (eq (9)).

    Parameters
    ----------
    geo : ErrataGeometry
        Test geometry (``N = 4`` sensors, exact average ``C~ = S / N``).
    model : NoiseModel
        The noise model of eq (4).

    Returns
    -------
    printed, corrected : float
        Relative distances of the gradient ``Sigma^r_1`` of eq (15) computed from ``C~`` and from ``N C~`` to
        the centralized one.
    sigma_offset : float
        Relative distance of ``Sigma`` computed from ``C~`` to the centralized ``Sigma`` of eq (6).
    """
    S, dMr, _ = _information_and_range_derivative(geo, model)
    eye, zero = np.eye(2), np.zeros((2, 2))
    g2, Lbar, Delta = geo.gamma_inv2, geo.Lbar, geo.Delta
    N = len(geo.agents)
    C_tilde = S / N
    _, s_cent = sigma_gradient(Delta, zero, S, dMr[0], g2, Lbar)
    _, s_print = sigma_gradient(Delta, zero, C_tilde, dMr[0], g2, Lbar)
    _, s_corr = sigma_gradient(Delta, zero, N * C_tilde, dMr[0], g2, Lbar)
    sig_print = Delta @ np.linalg.inv(eye + C_tilde @ Delta - g2 * Lbar @ Delta)
    sig_true = geo.sigma(model, r=geo.r.copy())
    return (relative_distance(s_print, s_cent), relative_distance(s_corr, s_cent),
            relative_distance(sig_print, sig_true))


def range_derivative_reading_residuals(model: NoiseModel, radii, theta: float):
    """Erratum E9: the reading of ``V`` and ``R`` in eq (17), against finite differences of ``M^-1`` in ``r``.

    Parameters
    ----------
    model : NoiseModel
        The noise model of eq (4).
    radii : sequence of float
        Ranges at which it is checked.
    theta : float
        Bearing.

    Returns
    -------
    printed, corrected : float
        Largest relative distance over ``radii`` of :func:`.noise.dinfo_dr_reading` with ``R`` read as
        ``diag(sqrt f_r, sqrt f_b)`` (the matrix of eq (3), 'printed') and as ``diag(f_r, f_b)``, ``V = M_i``.
    """
    res_right, res_other = [], []
    for rr in radii:
        fdr = central_difference(lambda z: noise_information(z, theta, model), rr)
        res_right.append(relative_distance(dinfo_dr_reading(rr, theta, model, "variances"), fdr))
        res_other.append(relative_distance(dinfo_dr_reading(rr, theta, model, "square_roots"), fdr))
    return max(res_other), max(res_right)


def errata_residuals(model: NoiseModel, gamma: float, seed: int, n_samples: int) -> dict:
    """Residuals of the printed and corrected forms of errata E1-E6 and E9, from one seeded generator.

    The generator first draws the ``n_samples`` noise vectors of E1, then the test geometry
    (:func:`errata_geometry`); E1, E4 and E9 are evaluated at :data:`ERRATA_POINT`.

    Parameters
    ----------
    model : NoiseModel
        The noise model of eq (4).
    gamma : float
        Attenuation level of eq (6).
    seed : int
        Seed of the generator.
    n_samples : int
        Samples of E1.

    Returns
    -------
    dict
        ``{id: (printed, corrected)}`` for ``E1`` ... ``E6``, ``E9``; ``E6`` has a third element, the
        relative error of ``Sigma`` itself under the printed form; ``"E4_radii"``: the ranges of E4.
    """
    rng = np.random.default_rng(int(seed))
    r0, th0 = ERRATA_POINT
    out = {"E1": covariance_form_residuals(rng, model, r0, th0, int(n_samples))}
    geo = errata_geometry(rng, gamma)
    out["E2"] = sigma_form_residuals(geo, model)
    out["E3"] = sigma_gradient_residuals(geo, model)
    radii = (E4_RADII[0], model.a1) + E4_RADII[1:]
    out["E4"] = bearing_derivative_residuals(model, radii, th0)
    out["E4_radii"] = radii
    out["E5"] = control_direction_residuals(geo, model)
    out["E6"] = average_information_residuals(geo, model)
    out["E9"] = range_derivative_reading_residuals(model, E9_RADII, th0)
    return out


def order_violation(a: float, b: float) -> float:
    """How far the order ``a >= b`` is violated: ``max(0, b - a)`` (0 where it holds).

    Parameters
    ----------
    a, b : float
        The two values the order compares.

    Returns
    -------
    float
    """
    return max(0.0, b - a)


def settles_first(a, b, threshold: float):
    """Whether series ``a`` settles below ``threshold`` before series ``b`` (:func:`.model.settle_step`).

    Parameters
    ----------
    a, b : array_like
        Error series over ``k = 0..K``.
    threshold : float
        Settling level.

    Returns
    -------
    quicker : bool
        ``a`` settles and ``b`` does not, or ``a`` settles at an earlier step.
    ka, kb : int
        Their settling steps (``-1``: never).
    """
    ka, kb = settle_step(a, threshold), settle_step(b, threshold)
    return bool(ka >= 0 and (kb < 0 or ka < kb)), ka, kb


def difference_correlation(a, b, c) -> float:
    """Pearson correlation over runs of the paired difference ``a - b`` with ``c`` (NaN if either is constant).

    Parameters
    ----------
    a, b, c : array_like, shape ``(R,)``
        Per-run values.

    Returns
    -------
    float
    """
    d = np.asarray(a, dtype=float) - np.asarray(b, dtype=float)
    c = np.asarray(c, dtype=float)
    if not (d.std(ddof=1) > 0 and c.std(ddof=1) > 0):
        return float("nan")
    return float(np.corrcoef(d, c)[0, 1])


def disturbance_weight(L, Q):
    """``Lbar = L^T Q L`` of eq (6).

    Parameters
    ----------
    L : array_like, shape ``(p, 2)``
        Estimated-output map.
    Q : array_like, shape ``(p, p)``
        Its weight.

    Returns
    -------
    ndarray, shape ``(2, 2)``
    """
    L = np.asarray(L)
    return L.T @ np.asarray(Q) @ L


def information_at_positions(target, agents, model: NoiseModel):
    """Information matrices ``M_i^-1`` of eqs (2)-(4) of sensors at ``agents`` looking at ``target``.

    Parameters
    ----------
    target : array_like, shape ``(R, 2)``
        Target position per run.
    agents : array_like, shape ``(R, N, 2)``
        Sensor positions per run.
    model : NoiseModel
        The noise model of eq (4).

    Returns
    -------
    ndarray, shape ``(R, N, 2, 2)``
    """
    d = np.asarray(target, dtype=float)[:, None, :] - np.asarray(agents, dtype=float)
    return noise_information(np.hypot(d[..., 0], d[..., 1]), np.arctan2(d[..., 1], d[..., 0]), model)


def mean_gain_norms(info, W: float, gamma: float, Lbar):
    """Mean steady-state gain norms of the local and the centralized filters of eq (6) at one geometry.

    Local filter of sensor ``i``: ``S = M_i^-1``; centralized: ``S = sum_i M_i^-1``, gain of sensor 1's
    block. Both with ``A = B = I`` and design noise ``W I`` (:func:`.filters.steady_state_prior`).

    Parameters
    ----------
    info : ndarray, shape ``(R, N, 2, 2)``
        Information matrices (:func:`information_at_positions`).
    W : float
        Design process noise.
    gamma : float
        Attenuation level (``inf``: Kalman filters).
    Lbar : ndarray, shape ``(2, 2)``
        ``L^T Q L``.

    Returns
    -------
    tuple of float
        Means over runs (and sensors) of ``||K_k||_2`` local, ``||K~_k||_2`` local, ``||K_k||_2``
        centralized, ``||K~_k||_2`` centralized (:func:`.filters.gain_norms`).

    Raises
    ------
    FilterDoesNotExist
        If a local filter does not exist at ``gamma`` (``Delta^-1 + M_i^-1 - gamma^-2 Lbar`` not positive
        definite: ``gamma < gamma_0``).
    """
    g2 = 0.0 if not np.isfinite(gamma) else gamma ** -2
    D_loc = steady_state_prior(info, W, g2, Lbar)
    if np.linalg.eigvalsh(np.linalg.inv(D_loc) + info - g2 * Lbar).min() <= 0:
        raise FilterDoesNotExist(f"the local filter does not exist at gamma = {gamma:g} (gamma < gamma_0)")
    K_loc, Kt_loc = gain_norms(D_loc, info, info)
    S = info.sum(1)
    D_c = steady_state_prior(S, W, g2, Lbar)
    K_c, Kt_c = gain_norms(D_c, S, info[:, 0])
    return float(K_loc.mean()), float(Kt_loc.mean()), float(K_c.mean()), float(Kt_c.mean())


def sweet_spot_grid(model: NoiseModel, r_max: float, r_step: float):
    """The sweet spot of eq (4) on a grid: the ranges minimising ``tr M(r)`` and ``det M(r)``.

    Parameters
    ----------
    model : NoiseModel
        The noise model of eq (4).
    r_max : float
        The grid is ``0, r_step, ..., r_max``.
    r_step : float
        Grid step.

    Returns
    -------
    r_trace, r_det : float
        Grid arguments of the minimum of ``tr M`` and of ``det M`` (bearing 0; both are
        rotation-invariant); the first on a tie.
    step : float
        The grid step.
    """
    r = np.arange(0.0, float(r_max) + 0.5 * float(r_step), float(r_step))
    M = noise_covariance(r, np.zeros_like(r), model)
    return (float(r[np.argmin(np.trace(M, axis1=-2, axis2=-1))]), float(r[np.argmin(np.linalg.det(M))]),
            float(r[1] - r[0]))
