"""Estimators beyond the paper: simulation of the model, the grid (point-mass) 1-bit filter and
smoother, and the unquantized Kalman filter / RTS smoother, all vectorised over runs.

The model is the random walk (21) observed through (20) (unquantized) or (28) (1-bit).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.special import ndtr

from .model import stationary_variance

__all__ = ["simulate_block", "grid_filter_smoother", "kalman_rts"]


def simulate_block(rng, n_runs: int, horizon: int, eps: float, sigma_z2: float, sigma_eta: float):
    """Stationary random-walk paths (21), unquantized (20) and 1-bit (28) measurements.

    ``theta_0 ~ N(0, sigma_theta_inf^2)`` (stationary start). Returns
    ``theta`` (n, horizon+1), ``y`` and ``r`` (n, horizon) for k = 1..horizon.

    Parameters
    ----------
    rng : numpy.random.Generator
        Random source.
    n_runs, horizon : int
        Runs and steps K.
    eps : float
        ``1 - alpha`` of the random walk (21).
    sigma_z2 : float
        Transition noise variance.
    sigma_eta : float
        Measurement noise standard deviation.
    """
    alpha = 1.0 - eps
    sd_inf = math.sqrt(float(stationary_variance(eps, sigma_z2)))
    theta = np.empty((n_runs, horizon + 1))
    theta[:, 0] = sd_inf * rng.standard_normal(n_runs)
    z = math.sqrt(sigma_z2) * rng.standard_normal((n_runs, horizon))
    for k in range(horizon):
        theta[:, k + 1] = alpha * theta[:, k] + z[:, k]
    y = theta[:, 1:] + sigma_eta * rng.standard_normal((n_runs, horizon))
    return theta, y, np.where(y >= 0, 1.0, -1.0)


def grid_filter_smoother(r, eps: float, sigma_z2: float, sigma_eta: float, grid_half_width: float = 6.0,
                         points_per_sigma_z: float = 1.5, quantized: bool = True):
    r"""Conditional means :math:`E[\theta_k|r_{1:k}]` and :math:`E[\theta_k|r_{1:K}]` on a grid, vectorised over runs.

    The point-mass approximation of the exact Bayesian recursions
    (Chapman-Kolmogorov + Bayes, forward; backward messages
    :math:`\beta_{k-1} = \sum p(\theta_k|\theta_{k-1}) p(r_k|\theta_k)\beta_k`),
    with :math:`p(r|\theta) = \Phi(r\theta/\sigma_\eta)`. The grid spans
    ``grid_half_width`` stationary standard deviations with spacing
    ``sigma_z / points_per_sigma_z``, so the discretised Gaussian transition
    keeps its first two moments to ~exp(-2 pi^2 points^2) (Poisson summation).

    Parameters
    ----------
    r : ndarray (n_runs, K)
        1-bit measurements (+-1) at k = 1..K, or, with ``quantized=False``,
        unquantized measurements (20) (Gaussian likelihood; the grid then
        reproduces the Kalman filter / RTS smoother, which tests the grid).

    Returns
    -------
    filt, smooth : ndarray (n_runs, K+1)
        Estimates for k = 0..K (k = 0: prior mean, smoothed).
    """
    alpha = 1.0 - eps
    sd_inf = math.sqrt(float(stationary_variance(eps, sigma_z2)))
    sz = math.sqrt(sigma_z2)
    n_half = int(math.ceil(grid_half_width * sd_inf / (sz / points_per_sigma_z)))
    x = np.linspace(-grid_half_width * sd_inf, grid_half_width * sd_inf, 2 * n_half + 1)
    # T[j, i] = p(theta_k = x_i | theta_{k-1} = x_j), rows normalised
    T = np.exp(-0.5 * ((x[None, :] - alpha * x[:, None]) / sz) ** 2)
    T /= T.sum(axis=1, keepdims=True)
    lik_pos = ndtr(x / sigma_eta)

    def likelihood(k):
        if quantized:
            return np.where(r[:, k : k + 1] > 0, lik_pos, 1.0 - lik_pos)
        return np.exp(-0.5 * ((r[:, k : k + 1] - x) / sigma_eta) ** 2)

    n, K = r.shape
    prior = np.exp(-0.5 * (x / sd_inf) ** 2)
    prior /= prior.sum()
    post = np.empty((n, K + 1, len(x)))
    post[:, 0] = prior
    for k in range(K):
        p = (post[:, k] @ T) * likelihood(k)
        post[:, k + 1] = p / p.sum(axis=1, keepdims=True)
    filt = post @ x
    beta = np.ones((n, len(x)))
    smooth = np.empty((n, K + 1))
    smooth[:, K] = filt[:, K]
    for k in range(K, 0, -1):
        beta = (beta * likelihood(k - 1)) @ T.T
        beta /= beta.sum(axis=1, keepdims=True)
        g = post[:, k - 1] * beta
        smooth[:, k - 1] = (g @ x) / g.sum(axis=1)
    return filt, smooth


def kalman_rts(y, eps, sigma_z2, sigma_eta):
    """Scalar Kalman filter and RTS smoother means (unquantized reference), vectorised over runs.

    Parameters
    ----------
    y : ndarray (n_runs, K)
        Unquantized measurements (20).
    eps : float
        ``1 - alpha`` of the random walk (21).
    sigma_z2 : float
        Transition noise variance.
    sigma_eta : float
        Measurement noise standard deviation.

    Returns
    -------
    mf, ms : ndarray (n_runs, K+1)
        Filtered and smoothed means, k = 0..K, started from the stationary prior.
    """
    alpha = 1.0 - eps
    n, K = y.shape
    P = float(stationary_variance(eps, sigma_z2))
    m = np.zeros(n)
    mf, Pf, mp, Pp = np.zeros((n, K + 1)), np.zeros(K + 1), np.zeros((n, K + 1)), np.zeros(K + 1)
    Pf[0] = P
    for k in range(1, K + 1):
        mpk, Ppk = alpha * m, alpha**2 * P + sigma_z2
        G = Ppk / (Ppk + sigma_eta**2)
        m, P = mpk + G * (y[:, k - 1] - mpk), (1 - G) * Ppk
        mp[:, k], Pp[k], mf[:, k], Pf[k] = mpk, Ppk, m, P
    ms = mf.copy()
    for k in range(K - 1, -1, -1):
        C = Pf[k] * alpha / Pp[k + 1]
        ms[:, k] = mf[:, k] + C * (ms[:, k + 1] - mp[:, k + 1])
    return mf, ms

