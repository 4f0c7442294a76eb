"""Mathematics of the `hinf` paper (Nelson & Freeman, *Decentralized H-infinity Filtering in a Multi-Agent System*).

Everything here is a pure function of arrays. All 2x2 matrix algebra is
written in closed form and broadcasts over any leading axes, so the
simulations are vectorised over Monte Carlo runs and agents and loop over
time only.

Conventions (Section II of the paper)
-------------------------------------
* Target position ``x`` and agent positions ``p_i`` in the plane; the range
  is ``r_i = |x - p_i|`` and the bearing ``theta_i = angle(x - p_i)``.
* ``T(theta)`` is the rotation by ``theta``: it maps the sensor frame
  (range axis, cross-range axis) to the world frame.
* The measurement noise covariance is ``M_i = T_i diag(f_r, f_b) T_i^T``
  (eqs (3)-(4)); each agent measures the position directly, ``C_i = I_2``.
* "info" ``S = sum_i C_i^T M_i^{-1} C_i`` and ``s = sum_i C_i^T M_i^{-1} y_i``.

The paper prints several equations with sign or factor errors; the functions
here implement the corrected forms, and ``printed_*`` functions implement the
forms as printed so that the errata table can measure the difference.
"""

from __future__ import annotations

import numpy as np

from ..errors import ModelError

__all__ = [
    "NoiseModel", "FilterDoesNotExist",
    "inv2", "det2", "sym2", "min_eig2", "rotation", "geometry",
    "noise_variances", "noise_covariance", "noise_information", "sample_noise", "printed_dinfo_dtheta",
    "adjacency", "laplacian", "pi_consensus_step", "pi_consensus_modes", "pi_consensus_spectral_radius",
    "consensus_h_max", "run_pi_consensus",
    "hinf_update", "hinf_information", "decentralized_update", "kalman_update", "minimum_attenuation",
    "sigma_gradient", "printed_sigma_gradient", "control_law", "printed_control_law",
    "overbounding_ellipse", "fused_trace", "min_fused_trace", "evader_move",
]

I2 = np.eye(2)
_J = np.array([[0.0, -1.0], [1.0, 0.0]])


class FilterDoesNotExist(ModelError):
    """The H-infinity filter does not exist: gamma is below the minimum attenuation level gamma_0.

    Raised when the information matrix ``Sigma_k^{-1} = Delta_k^{-1} + C^T M^{-1} C - gamma^{-2} L^T Q L``
    of eq (6) (or (9)) is not positive definite at some step.
    """


# --------------------------------------------------------------------------- 2x2 algebra
def det2(a):
    """Determinant of 2x2 matrices, shape ``(..., 2, 2) -> (...)``."""
    return a[..., 0, 0] * a[..., 1, 1] - a[..., 0, 1] * a[..., 1, 0]


def inv2(a):
    """Closed-form inverse of 2x2 matrices, shape ``(..., 2, 2)`` (no LAPACK call per matrix)."""
    d = det2(a)
    out = np.empty_like(a, dtype=float)
    out[..., 0, 0] = a[..., 1, 1]
    out[..., 1, 1] = a[..., 0, 0]
    out[..., 0, 1] = -a[..., 0, 1]
    out[..., 1, 0] = -a[..., 1, 0]
    return out / d[..., None, None]


def sym2(a):
    """Symmetric part ``(a + a^T)/2``."""
    return 0.5 * (a + np.swapaxes(a, -1, -2))


def min_eig2(a):
    """Smallest eigenvalue of the symmetric part of 2x2 matrices."""
    s = sym2(a)
    tr = s[..., 0, 0] + s[..., 1, 1]
    diff = s[..., 0, 0] - s[..., 1, 1]
    return 0.5 * tr - np.sqrt(0.25 * diff * diff + s[..., 0, 1] ** 2)


def rotation(theta):
    """Rotation matrices ``T(theta) = [[cos, -sin], [sin, cos]]`` of eq (3), shape ``theta.shape + (2, 2)``."""
    theta = np.asarray(theta, dtype=float)
    c, s = np.cos(theta), np.sin(theta)
    return np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2)


def geometry(target, agents):
    """Range and bearing of the target seen from each agent (Section II).

    Parameters
    ----------
    target : ndarray, shape ``(..., 2)``
        Target position ``x``; broadcast against ``agents`` after inserting an agent axis.
    agents : ndarray, shape ``(..., N, 2)``

    Returns
    -------
    r, theta : ndarray, shape ``(..., N)``
        ``r_i = |x - p_i|`` and ``theta_i = angle(x - p_i)``.
    """
    d = np.asarray(target, dtype=float)[..., None, :] - np.asarray(agents, dtype=float)
    return np.hypot(d[..., 0], d[..., 1]), np.arctan2(d[..., 1], d[..., 0])


# --------------------------------------------------------------------------- noise model (3)-(4)
class NoiseModel:
    """Range-bearing noise model, eqs (3)-(4): ``f_r(r) = a2 (r - a1)^2 + a0``, ``f_b = alpha f_r``."""

    def __init__(self, a0: float, a1: float, a2: float, alpha: float):
        for name, val in (("a0", a0), ("a2", a2), ("alpha", alpha)):
            if not val > 0:
                raise ValueError(f"noise parameter {name} must be > 0, got {val!r}")
        self.a0, self.a1, self.a2, self.alpha = float(a0), float(a1), float(a2), float(alpha)

    @classmethod
    def from_config(cls, section: dict) -> "NoiseModel":
        return cls(section["a0"], section["a1"], section["a2"], section["alpha"])


def noise_variances(r, model: NoiseModel):
    """Range and bearing noise variances, eq (4).

    .. math:: f_r(r) = a_2 (r - a_1)^2 + a_0, \\qquad f_b(r) = \\alpha f_r(r)

    Returns
    -------
    f_r, f_b : ndarray, shape of ``r``
    """
    r = np.asarray(r, dtype=float)
    fr = model.a2 * (r - model.a1) ** 2 + model.a0
    return fr, model.alpha * fr


def noise_covariance(r, theta, model: NoiseModel):
    """Measurement noise covariance ``M = T(theta) diag(f_r, f_b) T(theta)^T`` implied by eq (3).

    Eq (3) gives the square root ``T diag(sqrt f_r, sqrt f_b)`` of this covariance.
    """
    fr, fb = noise_variances(r, model)
    T = rotation(theta)
    R = np.zeros(np.shape(fr) + (2, 2))
    R[..., 0, 0], R[..., 1, 1] = fr, fb
    return T @ R @ np.swapaxes(T, -1, -2)


def noise_information(r, theta, model: NoiseModel, derivatives: bool = False):
    """Information matrix ``M^{-1}`` and (optionally) its derivatives, eqs (17)-(18), corrected.

    .. math::

        \\frac{\\partial M^{-1}}{\\partial r} = -2 a_2 (r - a_1)\\, T R^{-2}
            \\begin{bmatrix}1&0\\\\0&\\alpha\\end{bmatrix} T^T, \\qquad
        \\frac{\\partial M^{-1}}{\\partial \\theta} = \\Psi + \\Psi^T, \\quad \\Psi = J T R^{-1} T^T

    with ``J = [[0, -1], [1, 0]]``. The paper prints
    ``V^{-1} (Psi + Psi^T) V^{-1}`` for the bearing derivative (erratum E3;
    see :func:`printed_dinfo_dtheta`); the range derivative (17) is correct.

    Returns
    -------
    Minv or (Minv, dMinv_dr, dMinv_dtheta) : ndarray, shape ``r.shape + (2, 2)``
    """
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
    """Bearing derivative of ``V^{-1}`` as printed in eqs (17)-(18): ``V^{-1}(Psi + Psi^T)V^{-1}``, ``Psi = J T R^{-1} T^T``."""
    Minv = noise_information(r, theta, model)
    psi = _J @ Minv
    return Minv @ (psi + np.swapaxes(psi, -1, -2)) @ Minv


def sample_noise(rng: np.random.Generator, r, theta, model: NoiseModel):
    """Draw measurement noise ``m_i = T_i diag(sqrt f_r, sqrt f_b) eps_i``, ``eps_i ~ N(0, I_2)`` (eq (3)).

    Returns an array of shape ``r.shape + (2,)``.
    """
    fr, fb = noise_variances(r, model)
    eps = rng.standard_normal(np.shape(fr) + (2,))
    local = np.stack([np.sqrt(fr) * eps[..., 0], np.sqrt(fb) * eps[..., 1]], -1)
    return (rotation(theta) @ local[..., None])[..., 0]


# --------------------------------------------------------------------------- communication graph and PI consensus (5)
def adjacency(positions, radius: float):
    """Communication links of eq (25): ``l_ij = 1`` iff ``|p_i - p_j| <= r`` (no self loops).

    ``positions`` has shape ``(..., N, 2)``; returns ``(..., N, N)`` floats.
    """
    p = np.asarray(positions, dtype=float)
    d = np.linalg.norm(p[..., :, None, :] - p[..., None, :, :], axis=-1)
    adj = (d <= radius).astype(float)
    n = p.shape[-2]
    adj[..., np.arange(n), np.arange(n)] = 0.0
    return adj


def laplacian(adj):
    """Graph Laplacian ``diag(adj 1) - adj``."""
    deg = adj.sum(-1)
    lap = -adj.copy()
    n = adj.shape[-1]
    lap[..., np.arange(n), np.arange(n)] = deg
    return lap


def pi_consensus_step(v, w, u, lap, gamma_c: float, h: float, K_p: float, K_i: float):
    """One step of the discrete PI dynamic consensus estimator, eq (5).

    .. math::

        v_i(k+1) &= (1-\\gamma h) v_i(k) - h K_p \\sum_{j\\in N_i}[v_i - v_j]
                    + h K_i \\sum_{j \\in N_i}[w_i - w_j] + \\gamma h u_i(k) \\\\
        w_i(k+1) &= w_i(k) - h K_i \\sum_{j \\in N_i} [v_i - v_j]

    Parameters
    ----------
    v, w, u : ndarray, shape ``(..., N, d)``
        Estimator states and inputs (``d`` signal components per agent).
    lap : ndarray, shape ``(..., N, N)``
        Graph Laplacian; ``(lap @ v)_i = sum_j l_ij (v_i - v_j)``.
    gamma_c, h, K_p, K_i : float
        The design parameter gamma of eq (5) (not the H-infinity gamma), step, gains.
    """
    Lv = lap @ v
    Lw = lap @ w
    v_new = (1.0 - gamma_c * h) * v - h * K_p * Lv + h * K_i * Lw + gamma_c * h * u
    w_new = w - h * K_i * Lv
    return v_new, w_new


def pi_consensus_modes(lam, gamma_c: float, h: float, K_p: float, K_i: float):
    """Eigenvalue moduli of eq (5) on the Laplacian eigenvector of eigenvalue ``lam``.

    On that eigenvector the pair ``(v, w)`` evolves by
    ``[[1 - gamma h - h K_p lam, h K_i lam], [-h K_i lam, 1]]``. For ``lam = 0``
    the ``w`` component is conserved (``sum_i w_i`` is invariant and never reaches ``v``),
    so only the ``v`` eigenvalue ``1 - gamma h`` matters. Returns the relevant spectral
    radius for each ``lam``.
    """
    lam = np.atleast_1d(np.asarray(lam, dtype=float))
    out = np.empty_like(lam)
    for n, l in enumerate(lam):
        if abs(l) < 1e-10:
            out[n] = abs(1.0 - gamma_c * h)
        else:
            F = np.array([[1.0 - gamma_c * h - h * K_p * l, h * K_i * l], [-h * K_i * l, 1.0]])
            out[n] = np.max(np.abs(np.linalg.eigvals(F)))
    return out


def pi_consensus_spectral_radius(lap, gamma_c, h, K_p, K_i) -> float:
    """Spectral radius of eq (5) on a fixed graph (the conserved ``sum w`` mode excluded); stable iff < 1."""
    lam = np.linalg.eigvalsh(np.asarray(lap, dtype=float))
    return float(pi_consensus_modes(lam, gamma_c, h, K_p, K_i).max())


def consensus_h_max(lap, gamma_c, K_p, K_i, h_hi: float = 10.0, tol: float = 1e-6) -> float:
    """Largest ``h`` such that eq (5) is stable for every step in ``(0, h]`` on graph ``lap``.

    Scans a fine grid for the first unstable ``h`` and refines by bisection. Small ``h``
    is always stable: for ``lam > 0`` the block has trace ``2 - h(gamma + K_p lam)`` and
    determinant ``1 - h(gamma + K_p lam) + h^2 K_i^2 lam^2``, so its eigenvalues are
    ``1 - h (gamma + K_p lam)/2 + O(h^2)`` inside the unit circle.
    """
    grid = np.linspace(0.0, h_hi, 4001)[1:]
    rho = np.array([pi_consensus_spectral_radius(lap, gamma_c, h, K_p, K_i) for h in grid])
    bad = np.nonzero(rho >= 1.0)[0]
    if bad.size == 0:
        return float(h_hi)
    if bad[0] == 0:
        lo, hi = 0.0, grid[0]
    else:
        lo, hi = grid[bad[0] - 1], grid[bad[0]]
    while hi - lo > tol:
        mid = 0.5 * (lo + hi)
        if pi_consensus_spectral_radius(lap, gamma_c, mid, K_p, K_i) < 1.0:
            lo = mid
        else:
            hi = mid
    return float(lo)


def run_pi_consensus(u, lap, gamma_c, h, K_p, K_i, n_iter: int, v0=None):
    """State ``v`` of eq (5) after ``n_iter`` steps with constant inputs ``u`` (shape ``(N, d)``), fixed graph.

    ``v0`` defaults to ``u`` (each agent starts from its own input), ``w0 = 0``. With
    constant inputs (5) is the affine iteration ``z+ = F z + g`` on ``z = [v; w]``, so ``n_iter``
    steps are computed exactly as a power of the augmented matrix ``[[F, g], [0, I]]``
    (``O(log n_iter)`` products): the slow integral mode of a path graph needs ~10^5 steps.
    """
    u = np.asarray(u, dtype=float)
    lap = np.asarray(lap, dtype=float)
    n, d = u.shape
    v = u.copy() if v0 is None else np.asarray(v0, dtype=float)
    eye = np.eye(n)
    F = np.block([[(1 - gamma_c * h) * eye - h * K_p * lap, h * K_i * lap], [-h * K_i * lap, eye]])
    aug = np.zeros((2 * n + d, 2 * n + d))
    aug[:2 * n, :2 * n] = F
    aug[:n, 2 * n:] = gamma_c * h * u  # column j of g multiplies the j-th unit "1" state
    aug[2 * n:, 2 * n:] = np.eye(d)
    z0 = np.vstack([v, np.zeros((n, d)), np.eye(d)])
    with np.errstate(over="ignore", invalid="ignore"):
        z = np.linalg.matrix_power(aug, int(n_iter)) @ z0
    return z[:n]


# --------------------------------------------------------------------------- H-infinity filters (6), (9)
def hinf_information(Delta, S, gamma_inv2: float, Lbar):
    """Information matrix ``Sigma^{-1} = Delta^{-1} + S - gamma^{-2} L^T Q L`` of eq (6).

    The filter exists at this step iff it is positive definite.
    """
    return sym2(inv2(Delta) + S - gamma_inv2 * Lbar)


def hinf_update(xhat, Sigma, y_info, S, A, BWB, gamma_inv2: float, Lbar, check: bool = True):
    """One step of the centralized H-infinity filter, eq (6), in its information form.

    .. math::

        \\Delta_k &= A \\Sigma_{k-1} A^T + B W_{k-1} B^T \\\\
        K_k &= \\Delta_k (I + C^T M_k^{-1} C \\Delta_k)^{-1} C^T M_k^{-1} \\\\
        \\hat x_k &= A \\hat x_{k-1} + K_k (y_k - C A \\hat x_{k-1}) \\\\
        \\Sigma_k &= \\Delta_k (I - \\gamma^{-2} L_k^T Q_k L_k \\Delta_k + C^T M_k^{-1} C \\Delta_k)^{-1}

    Using ``C^T M^{-1} C = S`` and ``C^T M^{-1} y = y_info`` (the sums of Section III),
    ``K_k (y_k - C A x) = Delta (I + S Delta)^{-1} (y_info - S A x)``.
    With ``gamma_inv2 = 0`` this is the Kalman filter.

    Parameters
    ----------
    xhat : ndarray ``(..., 2)``; Sigma : ``(..., 2, 2)``
    y_info : ndarray ``(..., 2)``; S : ``(..., 2, 2)``
    A, BWB, Lbar : ndarray ``(2, 2)`` (``Lbar = L^T Q L``)
    gamma_inv2 : float
        ``gamma^{-2}``.
    check : bool
        Raise :class:`FilterDoesNotExist` when ``Sigma_k^{-1}`` is not positive definite.

    Returns
    -------
    xhat, Sigma, Delta, min_info_eig
    """
    Delta = A @ Sigma @ A.T + BWB
    xpred = xhat @ A.T
    G = Delta @ inv2(I2 + S @ Delta)
    xnew = xpred + (G @ (y_info - (S @ xpred[..., None])[..., 0])[..., None])[..., 0]
    Omega = I2 - gamma_inv2 * Lbar @ Delta + S @ Delta
    Sig = sym2(Delta @ inv2(Omega))
    info_eig = min_eig2(hinf_information(Delta, S, gamma_inv2, Lbar))
    if check and not np.all(info_eig > 0):
        raise FilterDoesNotExist(
            f"Sigma^-1 not positive definite (min eigenvalue {np.min(info_eig):.3g}): gamma below gamma_0")
    return xnew, Sig, Delta, info_eig


def decentralized_update(xhat, Sigma, y_tilde, C_tilde, n_agents: int, A, BWB, gamma_inv2, Lbar, check=True):
    """One step of the decentralized H-infinity filter of agent i, eq (9).

    .. math::

        \\tilde K_k &= \\Delta_k (I + N \\tilde C \\Delta_k)^{-1} \\\\
        \\hat x_k &= A \\hat x_{k-1} + N \\tilde K_k (\\tilde y_k - \\tilde C A \\hat x_{k-1}) \\\\
        \\Sigma_k &= \\Delta_k (I - \\gamma^{-2} L_k^T Q_k L_k \\Delta_k + N \\tilde C \\Delta_k)^{-1}

    with ``C_tilde`` and ``y_tilde`` the consensus estimates of the averages (7)-(8).
    It is eq (6) with ``S = N C_tilde`` and ``y_info = N y_tilde``: with exact
    consensus it equals the centralized filter.
    """
    return hinf_update(xhat, Sigma, n_agents * y_tilde, n_agents * C_tilde, A, BWB, gamma_inv2, Lbar, check)


def kalman_update(xhat, P, y, M, A, BWB):
    """Textbook Kalman filter with stacked measurements ``y_i = x + m_i``, written independently of (6).

    ``y`` has shape ``(..., N, 2)``, ``M`` ``(..., N, 2, 2)``; stacked ``C = [I; ...; I]``.
    Used by the tests as the reference for the ``gamma -> infinity`` limit.
    """
    n = y.shape[-2]
    Delta = A @ P @ A.T + BWB
    xpred = xhat @ A.T
    C = np.tile(I2, (n, 1))
    lead = M.shape[:-3]
    Mbig = np.zeros(lead + (2 * n, 2 * n))
    for i in range(n):
        Mbig[..., 2 * i:2 * i + 2, 2 * i:2 * i + 2] = M[..., i, :, :]
    Sinn = C @ Delta @ C.T + Mbig
    K = Delta @ C.T @ np.linalg.inv(Sinn)
    innov = y.reshape(lead + (2 * n,)) - (C @ xpred[..., None])[..., 0]
    xnew = xpred + (K @ innov[..., None])[..., 0]
    Pnew = (np.eye(2) - K @ C) @ Delta
    return xnew, sym2(Pnew)


def minimum_attenuation(S_seq, Sigma0, A, BWB, Lbar, lo=1e-3, hi=1e3, tol=1e-6):
    """Minimum attenuation level ``gamma_0`` of eq (6) along a sequence of informations.

    ``gamma_0`` is the infimum of the ``gamma`` for which ``Sigma_k^{-1} > 0`` for every step
    (the existence condition of the a-posteriori H-infinity filter). Feasibility is
    monotone in ``gamma``; found by bisection on ``log gamma``.

    Parameters
    ----------
    S_seq : ndarray ``(K, ..., 2, 2)``
        ``C^T M_k^{-1} C`` for each step (leading axes after time are batched; gamma_0 is the max).
    """
    S_seq = np.asarray(S_seq, dtype=float)

    def exists(gamma):
        g2 = gamma ** -2.0
        Sig = np.broadcast_to(np.asarray(Sigma0, dtype=float), S_seq.shape[1:]).copy()
        for S in S_seq:
            Delta = A @ Sig @ A.T + BWB
            info = hinf_information(Delta, S, g2, Lbar)
            if not np.all(min_eig2(info) > 0):
                return False
            Sig = sym2(inv2(info))
        return True

    if exists(lo):
        return lo
    if not exists(hi):
        return np.inf
    a, b = np.log(lo), np.log(hi)
    while b - a > tol:
        m = 0.5 * (a + b)
        if exists(np.exp(m)):
            b = m
        else:
            a = m
    return float(np.exp(b))


# --------------------------------------------------------------------------- motion control (10)-(18)
def sigma_gradient(Delta, dDelta, S, dS, gamma_inv2, Lbar):
    """Covariance ``Sigma_k`` and its derivative w.r.t. one sensor coordinate, eqs (14)-(16) corrected.

    With ``Omega = I + S Delta - gamma^{-2} L^T Q L Delta`` (eq (11); the paper's (16) prints
    ``- C^T M^{-1} C Delta``, erratum E2) and ``Sigma = Delta Omega^{-1}``:

    .. math::

        \\Sigma^z = \\Delta^z \\Omega^{-1}
            - \\Delta \\Omega^{-1} C^T \\frac{\\partial M^{-1}}{\\partial z} C \\Delta \\Omega^{-1}
            - \\Delta \\Omega^{-1} (C^T M^{-1} C \\Delta^z - \\gamma^{-2} L^T Q L \\Delta^z) \\Omega^{-1}

    (the paper's (15) prints ``+`` on the middle term). ``dDelta = A Sigma^z_{k-1} A^T`` is eq (14).

    Parameters
    ----------
    Delta, dDelta, S, dS : ndarray ``(..., 2, 2)``
        ``Delta_k``, ``Delta_k^z``, ``C^T M^{-1} C``, ``C^T (dM^{-1}/dz) C``.

    Returns
    -------
    Sigma, dSigma : ndarray ``(..., 2, 2)``
    """
    Omega = I2 + S @ Delta - gamma_inv2 * Lbar @ Delta
    Oi = inv2(Omega)
    DOi = Delta @ Oi
    dSigma = dDelta @ Oi - DOi @ dS @ DOi - DOi @ (S @ dDelta - gamma_inv2 * Lbar @ dDelta) @ Oi
    return Delta @ Oi, dSigma


def printed_sigma_gradient(Delta, dDelta, S, dS, gamma_inv2, Lbar):
    """Eqs (15)-(16) exactly as printed (``Omega = I - g L Delta - S Delta``, ``+`` middle term)."""
    Omega = I2 - gamma_inv2 * Lbar @ Delta - S @ Delta
    Oi = inv2(Omega)
    DOi = Delta @ Oi
    return dDelta @ Oi + DOi @ dS @ DOi - DOi @ (S @ dDelta - gamma_inv2 * Lbar @ dDelta) @ Oi


def control_law(dJ_dr, dJ_dtheta, r, theta, Gamma: float, v_max: float = np.inf):
    """Gradient motion control law, eq (12) corrected, with a speed limit.

    With ``theta_i = angle(x - p_i)`` (Section II), ``grad_{p_i} J = -T_i [dJ/dr; dJ/dtheta / r]``,
    so steepest descent is

    .. math:: u_i = \\Gamma\\, T_i \\begin{bmatrix} \\partial J/\\partial r_i \\\\
              r_i^{-1} \\partial J / \\partial \\theta_i \\end{bmatrix}

    (the paper prints ``-Gamma T_i^T [...]``, erratum E4). The step is then scaled down to
    length ``v_max`` if longer (the agents' "limited motion capabilities", a reconstruction).

    Returns ``u`` of shape ``r.shape + (2,)``.
    """
    local = np.stack([dJ_dr, dJ_dtheta / r], -1)
    u = Gamma * (rotation(theta) @ local[..., None])[..., 0]
    norm = np.linalg.norm(u, axis=-1, keepdims=True)
    scale = np.where(norm > v_max, v_max / np.maximum(norm, 1e-300), 1.0)
    return u * scale


def printed_control_law(dJ_dr, dJ_dtheta, r, theta, Gamma: float):
    """Eq (12) as printed: ``u_i = -Gamma T_i^T [dJ/dr; dJ/dtheta / r]`` (no speed limit)."""
    local = np.stack([dJ_dr, dJ_dtheta / r], -1)
    return -Gamma * (np.swapaxes(rotation(theta), -1, -2) @ local[..., None])[..., 0]


# --------------------------------------------------------------------------- evasive target (19)-(24)
def overbounding_ellipse(A, b, rho):
    """The map ``(q, Q) = F(A, b, rho)`` of eq (23).

    .. math:: Q = [1 + b^T A^{-1} b - \\rho] A^{-1}, \\qquad q = A^{-1} b

    ``{x : x^T A x - 2 b^T x + rho <= 1} = {x : (x - q)^T Q^{-1} (x - q) <= 1}``.
    """
    Ai = inv2(A)
    q = (Ai @ b[..., None])[..., 0]
    scale = 1.0 + np.einsum("...i,...i->...", b, q) - rho
    return q, scale[..., None, None] * Ai


def fused_trace(Minv, lam, x_t):
    """``tr Q_fused`` of eq (24) for weights ``lam`` (shape ``(..., N)``), informations ``Minv`` ``(..., N, 2, 2)``."""
    A = np.einsum("...n,...nij->...ij", lam, Minv)
    b = (A @ x_t[..., None])[..., 0]
    rho = np.einsum("...i,...i->...", x_t, b)
    _, Q = overbounding_ellipse(A, b, rho)
    return Q[..., 0, 0] + Q[..., 1, 1]


def min_fused_trace(Minv, n_iter: int = 60, step: float = 1.0):
    """Smallest over-bounding ellipse of the intersection (22): ``min_lambda tr (sum_j lam_j M_j^{-1})^{-1}``.

    For ellipses centred on the same point, (24) gives ``Q = (sum_j lam_j M_j^{-1})^{-1}``; its
    trace is convex in ``lam`` on the simplex. Minimised by exponentiated-gradient (mirror) descent,
    vectorised over the leading axes. Returns ``(trace, lam)``.
    """
    n = Minv.shape[-3]
    lam = np.full(Minv.shape[:-2], 1.0 / n)
    best = None
    for _ in range(n_iter):
        A = np.einsum("...n,...nij->...ij", lam, Minv)
        Ai = inv2(A)
        tr = Ai[..., 0, 0] + Ai[..., 1, 1]
        best = tr if best is None else np.minimum(best, tr)
        AiAi = Ai @ Ai
        grad = -np.einsum("...ij,...nji->...n", AiAi, Minv)  # d tr A^{-1} / d lam_n
        g = grad / np.maximum(np.abs(grad).max(-1, keepdims=True), 1e-300)
        lam = lam * np.exp(-step * g)
        lam = lam / lam.sum(-1, keepdims=True)
    A = np.einsum("...n,...nij->...ij", lam, Minv)
    Ai = inv2(A)
    best = np.minimum(best, Ai[..., 0, 0] + Ai[..., 1, 1])
    return best, lam


def evader_move(x_t, agents, model: NoiseModel, step: float, n_headings: int, n_iter: int = 60):
    """Greedy evasive move, eqs (19) and (21): maximise ``tr Q_fused`` over the next position.

    Candidates are ``x_t`` itself and ``x_t + step (cos phi, sin phi)`` for ``n_headings``
    equally spaced headings; the target knows each agent's position and the sensor model,
    not the filters (Section V).

    Parameters
    ----------
    x_t : ndarray ``(R, 2)``; agents : ``(R, N, 2)``

    Returns
    -------
    x_next : ndarray ``(R, 2)``; value : ``(R,)`` the maximised ``tr Q_fused``.
    """
    phi = 2 * np.pi * np.arange(n_headings) / n_headings
    offs = np.concatenate([np.zeros((1, 2)), step * np.stack([np.cos(phi), np.sin(phi)], -1)])
    cand = x_t[:, None, :] + offs[None]  # (R, H+1, 2)
    r, th = geometry(cand, agents[:, None, :, :])  # (R, H+1, N)
    Minv = noise_information(r, th, model)
    tr, _ = min_fused_trace(Minv, n_iter)
    best = np.argmax(tr, axis=1)
    idx = np.arange(len(x_t))
    return cand[idx, best], tr[idx, best]


# --------------------------------------------------------------------------- simulation (Section VI)
FILTER_KINDS = {
    "local": ("local", False), "decentralized": ("decentralized", False), "centralized": ("centralized", False),
    "kalman_local": ("local", True), "kalman_decentralized": ("decentralized", True),
    "kalman_centralized": ("centralized", True),
}


def _psd_floor(C, floor):
    """Shift 2x2 symmetric matrices up so their smallest eigenvalue is at least ``floor``; count the shifts."""
    C = sym2(C)
    low = min_eig2(C)
    shift = np.maximum(floor - low, 0.0)
    return C + shift[..., None, None] * I2, int(np.count_nonzero(shift))


def _connected(adj):
    lam = np.linalg.eigvalsh(laplacian(adj))
    return lam[..., 1] > 1e-9


def simulate(sc: dict) -> dict:
    """Monte Carlo simulation of one scenario of Section VI, vectorised over runs and agents.

    Parameters
    ----------
    sc : dict
        Resolved scenario: ``agents0 (N, 2)``, ``target0 (2,)``, ``target`` in
        {``random``, ``stationary``, ``evasive``}, ``W_true``, ``W_filter``, ``A`` (2x2),
        ``gamma``, ``Lbar`` (= L^T Q L), ``P0``, ``model`` (:class:`NoiseModel`), ``radius``,
        ``consensus`` (``gamma_c, h, K_p, K_i, iters``), ``mobile``, ``driver``, ``control``
        (``Gamma, v_max, recursion``), ``evader`` (``n_headings, n_iter, step``), ``filters``,
        ``horizon``, ``runs``, ``seed``, ``psd_floor``.

    Returns
    -------
    dict
        ``errors[name]``: ``(runs, n, horizon + 1)`` position-error norms ``|xhat - x|``
        (``n = N`` for local/decentralized, 1 for centralized); ``target (runs, K+1, 2)``;
        ``agents (runs, K+1, N, 2)``; ``connected (K+1,)`` fraction of runs with a connected
        graph; ``max_degree``; ``fused_trace (runs, K+1)`` (min over lambda of tr Q_fused, eq (22));
        ``trace_sigma[name] (runs, K+1)`` mean over agents of ``tr Sigma``; ``n_psd_fix``.

    Raises
    ------
    FilterDoesNotExist
        If an H-infinity filter does not exist (gamma below gamma_0) at some step.
    """
    R, K = int(sc["runs"]), int(sc["horizon"])
    P = np.broadcast_to(np.asarray(sc["agents0"], dtype=float), (R,) + np.shape(sc["agents0"])).copy()
    N = P.shape[1]
    A = np.asarray(sc["A"], dtype=float)
    BWB = np.asarray(sc["W_filter"], dtype=float)
    Wt = np.asarray(sc["W_true"], dtype=float)
    Lbar = np.asarray(sc["Lbar"], dtype=float)
    g2 = float(sc["gamma"]) ** -2.0
    model = sc["model"]
    cons = sc["consensus"]
    ctrl = sc.get("control", {})
    ev = sc.get("evader", {})
    names = list(sc["filters"])
    for name in names:
        if name not in FILTER_KINDS:
            raise ValueError(f"unknown filter {name!r}; expected one of {sorted(FILTER_KINDS)}")
    mobile = bool(sc.get("mobile", False))
    driver = sc.get("driver", "decentralized")
    if mobile and driver not in names:
        raise ValueError(f"driver filter {driver!r} must be among the filters {names}")
    ss = np.random.SeedSequence(int(sc["seed"]))
    rng0, rng_t, rng_m = (np.random.default_rng(s) for s in ss.spawn(3))

    x = np.broadcast_to(np.asarray(sc["target0"], dtype=float), (R, 2)).copy()
    x0hat = x + np.sqrt(float(sc["P0"])) * rng0.standard_normal((R, 2))
    Sig0 = float(sc["P0"]) * I2
    est, cov = {}, {}
    for name in names:
        kind, _ = FILTER_KINDS[name]
        shape = (R,) if kind == "centralized" else (R, N)
        est[name] = np.broadcast_to(x0hat[:, None, :] if kind != "centralized" else x0hat, shape + (2,)).copy()
        cov[name] = np.broadcast_to(Sig0, shape + (2, 2)).copy()
    errors = {n: np.empty((R, 1 if FILTER_KINDS[n][0] == "centralized" else N, K + 1)) for n in names}
    trace_sigma = {n: np.empty((R, K + 1)) for n in names}
    for n in names:
        e = np.linalg.norm(est[n] - (x if FILTER_KINDS[n][0] == "centralized" else x[:, None, :]), axis=-1)
        errors[n][..., 0] = e if e.ndim == 2 else e[:, None]
        trace_sigma[n][:, 0] = 2 * float(sc["P0"])
    tgt = np.empty((R, K + 1, 2))
    tgt[:, 0] = x
    ags = np.empty((R, K + 1, N, 2))
    ags[:, 0] = P
    fused = np.full((R, K + 1), np.nan)
    connected = np.empty(K + 1)
    adj = adjacency(P, sc["radius"])
    lap = laplacian(adj)
    connected[0] = _connected(adj).mean()
    max_degree = int(adj.sum(-1).max())
    need_cons = any(FILTER_KINDS[n][0] == "decentralized" for n in names)
    v = w = None
    dsig = np.zeros((2, R, N, 2, 2))  # local copies of Sigma^r_i, Sigma^theta_i (eq (14))
    n_psd_fix = 0
    for k in range(1, K + 1):
        # 1. target motion
        if sc["target"] == "random":
            x = x @ A.T + rng_t.multivariate_normal(np.zeros(2), Wt, size=R) if np.any(Wt) else x @ A.T
        elif sc["target"] == "evasive":
            x, fz = evader_move(x, P, model, float(ev["step"]), int(ev["n_headings"]), int(ev["n_iter"]))
            fused[:, k] = fz
        elif sc["target"] != "stationary":
            raise ValueError(f"unknown target mode {sc['target']!r}")
        # 2. measurements (2)-(4) from the true geometry
        r, th = geometry(x, P)
        Minv = noise_information(r, th, model)
        y = x[:, None, :] + sample_noise(rng_m, r, th, model)
        yinfo = (Minv @ y[..., None])[..., 0]
        # 3. PI consensus (5) on u_i = (C_i^T M_i^-1 C_i, C_i^T M_i^-1 y_i), eqs (7)-(8)
        if need_cons:
            u = np.concatenate([Minv.reshape(R, N, 4), yinfo], -1)
            if v is None:
                v, w = u.copy(), np.zeros_like(u)
            for _ in range(int(cons["iters"])):
                v, w = pi_consensus_step(v, w, u, lap, cons["gamma_c"], cons["h"], cons["K_p"], cons["K_i"])
            Ct, nfix = _psd_floor(v[..., :4].reshape(R, N, 2, 2), float(sc.get("psd_floor", 1e-9)))
            n_psd_fix += nfix
            yt = v[..., 4:]
        # 4. filters (6), (9) and their Kalman counterparts
        deltas = {}
        for n in names:
            kind, is_kf = FILTER_KINDS[n]
            gi = 0.0 if is_kf else g2
            if kind == "local":
                out = hinf_update(est[n], cov[n], yinfo, Minv, A, BWB, gi, Lbar)
            elif kind == "centralized":
                out = hinf_update(est[n], cov[n], yinfo.sum(1), Minv.sum(1), A, BWB, gi, Lbar)
            else:
                out = decentralized_update(est[n], cov[n], yt, Ct, N, A, BWB, gi, Lbar)
            est[n], cov[n], deltas[n] = out[0], out[1], out[2]
            if kind == "centralized":
                errors[n][:, 0, k] = np.linalg.norm(est[n] - x, axis=-1)
                trace_sigma[n][:, k] = cov[n][..., 0, 0] + cov[n][..., 1, 1]
            else:
                errors[n][:, :, k] = np.linalg.norm(est[n] - x[:, None, :], axis=-1)
                trace_sigma[n][:, k] = (cov[n][..., 0, 0] + cov[n][..., 1, 1]).mean(1)
        # 5. decentralized gradient motion control (12)-(18), each agent with its own estimate
        if mobile:
            gi = 0.0 if FILTER_KINDS[driver][1] else g2
            xh = est[driver]  # (R, N, 2)
            d = xh - P
            rh, thh = np.hypot(d[..., 0], d[..., 1]), np.arctan2(d[..., 1], d[..., 0])
            rh = np.maximum(rh, 1e-6)
            _, dMr, dMt = noise_information(rh, thh, model, derivatives=True)
            Delta = deltas[driver]
            S_hat = N * Ct if FILTER_KINDS[driver][0] == "decentralized" else Minv
            grads = []
            for z, dM in enumerate((dMr, dMt)):
                dDelta = A @ dsig[z] @ A.T if ctrl.get("recursion", True) else np.zeros_like(Delta)
                _, dS = sigma_gradient(Delta, dDelta, S_hat, dM, gi, Lbar)
                dsig[z] = dS
                grads.append(dS[..., 0, 0] + dS[..., 1, 1])
            P = P + control_law(grads[0], grads[1], rh, thh, float(ctrl["Gamma"]), float(ctrl["v_max"]))
            adj = adjacency(P, sc["radius"])
            lap = laplacian(adj)
            max_degree = max(max_degree, int(adj.sum(-1).max()))
        connected[k] = _connected(adj).mean() if mobile else connected[0]
        tgt[:, k] = x
        ags[:, k] = P
    if sc["target"] == "evasive" or sc.get("fused_all", True):
        r, th = geometry(tgt[:, 0], ags[:, 0])
        fused[:, 0] = min_fused_trace(noise_information(r, th, model), int(ev.get("n_iter", 40)))[0]
    return {"errors": errors, "target": tgt, "agents": ags, "connected": connected, "max_degree": max_degree,
            "fused_trace": fused, "trace_sigma": trace_sigma, "n_psd_fix": n_psd_fix}
