"""Exact E(p_k) at every k for i.i.d. arrivals (eqs. (6) and (14)), with a rigorous error bound.

Idea
----
Decompose by the time j of the last step before k at which some packet arrived (the
conditional Monte Carlo of :mod:`.estimators` uses the same identity): a run of m losses
acts affinely, L^m(x) = a^{2m} x + c_m, so

.. math::

    E(p_k) = \\sum_{j<k} \\pi_0^{m} \\big(a^{2m} \\mu_j + (1-\\pi_0) c_m\\big)
             + \\pi_0^k (a^{2k} p_0 + c_k), \\qquad m = k-1-j,

with pi_0 = P(no packet) and mu_j = E[V(p_j)], V(x) = sum_{S != {}} pi_S phi_S(x), phi_S the
arrival map of pattern S (phi(x) = a^2 x R/(x + R) + R1 with R = (sum_{i in S} 1/sigma_i^2)^{-1}).
V is bounded, and mu_j = (P^j V)(p_0) with the one-step averaging operator
(P h)(x) = sum_S pi_S h(M_S x) (M_emptyset = L). So all mu_j come from ONE backward
recursion u_0 = V, u_{n+1} = P u_n, mu_n = u_n(p_0): no enumeration of arrival sequences.

Every map is a Moebius transformation of x. In the coordinate t = 1/(x + R_ref) the
states x in [x_min, inf) (x_min = min(p_0, fixed point of the full-arrival map); this
interval is invariant) become the compact interval [0, t*], and every u_n is analytic there:
it is a convex combination of compositions of Moebius maps that send a Bernstein ellipse
E_rho around [0, t*] into itself (checked). So u_n is represented by its Chebyshev
interpolant of degree N in t, which converges like rho^{-N}.

Error bound (rigorous up to the stated floating-point allowance)
----------------------------------------------------------------
Let u~_n be the computed interpolants and d_n = P u~_{n-1} - u~_n (d_0 = V - u~_0) the
defect of step n. P is an average (positive, P 1 = 1) and the interval is invariant, so
||u_n - u~_n||_inf <= sum_{i<=n} ||d_i||_inf. Each ||d_i||_inf on [0, t*] is bounded by the
sum of the absolute Chebyshev coefficients of the degree-N2 interpolant of d_i plus the
interpolation remainder 4 M rho^{-N2} / (rho - 1) (Trefethen, ATAP, Thm 8.2), where
M >= sup_{E_rho} |d_i| <= B(u~_{i-1}) + B(u~_i), B(c) = sum_k |c_k| rho^k (the maps send
E_rho into itself, so P does not increase the sup over E_rho); for d_0, sup |V| on E_rho
(maximum modulus on the boundary, with a 10 % allowance) replaces B(u~_{i-1}). The iteration
and the defect checks run in 80-bit extended precision (eps = 1.1e-19); an allowance of
8 (N2 + 1) eps times the coefficient sums covers the rounding of the check itself, and
4 (T + 1) eps64 the float64 rounding of mu_j and of the final sums. The
containment M_S(E_rho) in E_rho is checked on 4096 boundary points with a 2 % margin in the
ellipse parameter (the images of the smooth boundary are smooth curves; this check is the one
non-interval-arithmetic step). The absolute error of E(p_k) is then at most
sum_j pi_0^m a^{2m} err(mu_j), and its relative error at most that over E(p_k).

Stationary mean (stable case, pi_0 a^2 < 1): min over [0, t*] of u_n does not decrease and
max does not increase with n, and both tend to mu_inf = lim mu_n, so
mu_inf in [min u_n, max u_n] for every n; iterate until this bracket is narrow, then
E(p_inf) = mu_inf / (1 - pi_0 a^2) + (1 - pi_0) sum_m pi_0^m c_m.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
from numpy.polynomial import chebyshev as C

from ...engines.channels import arrival_patterns
from ...errors import InputError, ModelError
from .estimators import conditional_mean_weights, loss_path_terms

__all__ = ["ExactMean", "exact_mean", "stationary_mean", "arrival_moebius_maps"]

_LD = np.longdouble  # 80-bit extended precision on x86-64 (eps 1.1e-19); float64 where it is not available
_EPS = float(np.finfo(_LD).eps)
_PI = np.arccos(_LD(-1.0))
_RHO_CANDIDATES = (4.0, 3.0, 2.5, 2.0, 1.75, 1.5, 1.35, 1.25, 1.15, 1.1)


@dataclass(frozen=True)
class ExactMean:
    """Result of :func:`exact_mean`.

    Attributes
    ----------
    mean : ndarray (T + 1,)
        E(p_k), k = 0..T.
    rel_error_bound : ndarray (T + 1,)
        Bound on |computed - exact| / exact for each k.
    mu : ndarray (T,)
        mu_j = E[V(p_j)], j = 0..T-1.
    mu_error_bound : ndarray (T,)
        Bound on the absolute error of each mu_j.
    rho : float
        Bernstein ellipse parameter of the analyticity check.
    degree : int
        Chebyshev degree N of the iterates.
    """

    mean: np.ndarray
    rel_error_bound: np.ndarray
    mu: np.ndarray
    mu_error_bound: np.ndarray
    rho: float
    degree: int


def arrival_moebius_maps(a, R1, sensor_vars, probs):
    """The maps of eq. (14) (eq. (6) for one sensor) as 2x2 Moebius matrices acting on x = p.

    Parameters
    ----------
    a, R1 : float
        System coefficient and process noise variance.
    sensor_vars : sequence of float
        Measurement noise variances sigma_i^2 of the scalar (C = 1) sensors.
    probs : sequence of float
        Independent arrival probabilities of the sensors.

    Returns
    -------
    weights : ndarray (2^m,)
        pi_S, the probability of each arrival pattern (ordered as ``arrival_patterns``).
    maps : ndarray (2^m, 2, 2)
        [[alpha, beta], [gamma, delta]] with M_S(x) = (alpha x + beta)/(gamma x + delta):
        L = [[a^2, R1], [0, 1]] for no arrival, [[a^2 R + R1, R1 R], [1, R]] for a pattern with
        combined variance R = (sum_{i in S} 1/sigma_i^2)^{-1}.
    arrived : ndarray (2^m,) of bool
        Whether the pattern delivers at least one packet.
    """
    patterns, weights = arrival_patterns(probs)
    inv = 1.0 / np.asarray(sensor_vars, dtype=float)
    maps = np.empty((len(weights), 2, 2))
    arrived = patterns.any(axis=1)
    for i, pattern in enumerate(patterns):
        if not pattern.any():
            maps[i] = [[a * a, R1], [0.0, 1.0]]
        else:
            R = 1.0 / inv[pattern].sum()
            maps[i] = [[a * a * R + R1, R1 * R], [1.0, R]]
    return np.asarray(weights, dtype=float), maps, arrived


def _apply(m, z):
    """Moebius matrix (or stack) applied to z."""
    return (m[..., 0, 0] * z + m[..., 0, 1]) / (m[..., 1, 0] * z + m[..., 1, 1])


def _ellipse_param(s):
    """rho(s) = |s + sqrt(s^2 - 1)| with the branch of modulus >= 1: s lies on the boundary of E_rho(s)."""
    s = np.asarray(s, dtype=complex)
    r = s + np.sqrt(s - 1) * np.sqrt(s + 1)
    return np.maximum(np.abs(r), 1.0 / np.maximum(np.abs(r), 1e-300))


class _Setup:
    """Coordinates, maps and the analyticity ellipse of one problem."""

    def __init__(self, p0, a, R1, sensor_vars, probs):
        if p0 < 0 or R1 <= 0 or min(sensor_vars) <= 0:
            raise InputError("exact_mean needs p0 >= 0, R1 > 0 and positive sensor variances")
        self.weights, self.x_maps, self.arrived = arrival_moebius_maps(a, R1, sensor_vars, probs)
        self.pi0 = float(self.weights[~self.arrived].sum())
        # the lowest map is the all-sensors arrival; its positive fixed point bounds the states from below
        R_all = 1.0 / np.sum(1.0 / np.asarray(sensor_vars, dtype=float))
        b = R_all - a * a * R_all - R1  # x^2 + b x - R1 R_all = 0
        p_fix = 0.5 * (-b + np.sqrt(b * b + 4 * R1 * R_all))
        self.x_min = min(float(p0), float(p_fix))
        self.R_ref = R_all
        self.t_max = 1.0 / (self.x_min + self.R_ref)
        T = np.array([[0.0, 1.0], [1.0, self.R_ref]])  # t(x) = 1 / (x + R_ref)
        T_inv = np.array([[-self.R_ref, 1.0], [1.0, 0.0]])  # x(t) = (1 - R_ref t) / t
        self.t_maps = np.einsum("ij,njk,kl->nil", T, self.x_maps, T_inv)
        # the same in extended precision for the iteration and the defect checks
        x_ld = _ld_maps(a, R1, sensor_vars, self.weights.shape[0], probs)
        T_ld = np.array([[0, 1], [1, _LD(self.R_ref)]], dtype=_LD)
        T_inv_ld = np.array([[-_LD(self.R_ref), 1], [1, 0]], dtype=_LD)
        self.t_maps_ld = np.einsum("ij,njk,kl->nil", T_ld, x_ld, T_inv_ld)
        self.v_maps_ld = np.einsum("njk,kl->njl", x_ld[self.arrived], T_inv_ld)
        self.weights_ld = _ld_weights(probs)
        # V(t) = sum_{S arrived} pi_S x(M_S t): x of the image, a Moebius function of t
        self.v_maps = np.einsum("njk,kl->njl", self.x_maps[self.arrived], T_inv)
        self.v_weights = self.weights[self.arrived]
        self.p0 = float(p0)
        self.t0 = 1.0 / (self.p0 + self.R_ref)
        self.rho = self._find_rho()

    def s_of_t(self, t):
        return 2.0 * t / self.t_max - 1.0

    def t_of_s(self, s):
        return 0.5 * (s + 1.0) * self.t_max

    def V(self, t, extended=False):
        t = np.asarray(t)
        maps, weights = (self.v_maps_ld, self.weights_ld[self.arrived]) if extended else (self.v_maps, self.v_weights)
        maps = maps.reshape((len(maps),) + (1,) * t.ndim + (2, 2))
        return np.tensordot(weights, _apply(maps, t[None]), axes=1)

    def _find_rho(self):
        theta = np.linspace(0.0, 2 * np.pi, 4096, endpoint=False)
        for rho in _RHO_CANDIDATES:
            s = 0.5 * (rho * np.exp(1j * theta) + np.exp(-1j * theta) / rho)
            t = self.t_of_s(s)
            ok = True
            for m in self.t_maps:
                # the pole of the map must lie outside the ellipse (else the image is unbounded)
                if m[1, 0] != 0 and _ellipse_param(self.s_of_t(-m[1, 1] / m[1, 0])) <= rho:
                    ok = False
                    break
                if np.max(_ellipse_param(self.s_of_t(_apply(m, t)))) > rho / 1.02:
                    ok = False
                    break
            for m in self.v_maps:  # V must be analytic on E_rho: its poles outside
                if m[1, 0] != 0 and _ellipse_param(self.s_of_t(-m[1, 1] / m[1, 0])) <= rho * 1.02:
                    ok = False
            if ok:
                self.V_sup = 1.1 * float(np.max(np.abs(self.V(t))))  # maximum modulus on the boundary
                return rho
        raise ModelError("no Bernstein ellipse around the state interval is mapped into itself by every arrival map; "
                         "the exact method does not apply to these parameters")


def _ld_maps(a, R1, sensor_vars, n_patterns, probs):
    """:func:`arrival_moebius_maps` in extended precision (from the same float64 parameters)."""
    patterns, _ = arrival_patterns(probs)
    a2, R1 = _LD(a) * _LD(a), _LD(R1)
    inv = 1 / np.asarray(sensor_vars, dtype=_LD)
    maps = np.empty((n_patterns, 2, 2), dtype=_LD)
    for i, pattern in enumerate(patterns):
        if not pattern.any():
            maps[i] = [[a2, R1], [0, 1]]
        else:
            R = 1 / inv[pattern].sum()
            maps[i] = [[a2 * R + R1, R1 * R], [1, R]]
    return maps


def _ld_weights(probs):
    """Pattern probabilities in extended precision, ordered as ``arrival_patterns``."""
    patterns, _ = arrival_patterns(probs)
    p = np.asarray(probs, dtype=_LD)
    return np.prod(np.where(patterns, p, 1 - p), axis=1)


def _cheb_nodes(n):
    return np.cos(_PI * np.arange(n + 1, dtype=_LD) / n)


@functools.lru_cache(maxsize=None)
def _dct1_matrix(n):
    """cos(pi j l / n), j, l = 0..n, in extended precision (read-only; cached: the extended cosines are slow)."""
    j = np.arange(n + 1, dtype=_LD)
    m = np.cos(_PI * np.outer(j, j) / n)
    m.flags.writeable = False
    return m


def _cheb_coeffs(values):
    """Chebyshev coefficients of the interpolant at the points cos(pi j / n), j = 0..n (a DCT-I)."""
    n = len(values) - 1
    w = np.ones(n + 1, dtype=_LD)
    w[[0, -1]] = 0.5
    c = (_LD(2) / n) * (_dct1_matrix(n) @ (w * np.asarray(values, dtype=_LD)))
    c[[0, -1]] *= 0.5
    return c


def _backward(setup, n_iter, degree, stop_width=None):
    """u_0 = V, u_{n+1} = P u_n as Chebyshev interpolants; returns mu_n = u_n(t0), the error bounds, the last u."""
    N, N2 = degree, 2 * degree
    rho = setup.rho
    nodes_t = setup.t_of_s(_cheb_nodes(N))
    check_t = setup.t_of_s(_cheb_nodes(N2))
    pow_rho = rho ** np.arange(N + 1)
    tail = 4.0 * rho ** (-N2) / (rho - 1.0)
    images_nodes = _apply(setup.t_maps_ld[:, None], nodes_t[None, :])  # (n_maps, N+1)
    images_check = _apply(setup.t_maps_ld[:, None], check_t[None, :])
    s_nodes = setup.s_of_t(images_nodes)
    s_check = setup.s_of_t(images_check)
    s_t0 = setup.s_of_t(1 / (_LD(setup.p0) + _LD(setup.R_ref)))
    w = setup.weights_ld

    # every point at which a coefficient set is evaluated, in one array: one Clenshaw pass per set
    # (elementwise, so each value is the one a separate chebval call gives)
    parts = (_cheb_nodes(N2), np.reshape(s_t0, 1), s_nodes.ravel(), s_check.ravel())
    x_all = np.concatenate(parts)
    cuts = np.cumsum([len(q) for q in parts])[:-1]

    def evaluate(c):
        """c at the check nodes (own interpolant), at t0, and at the images of the nodes and check nodes."""
        at_check, at_t0, at_nodes, at_images = np.split(C.chebval(x_all, c), cuts)
        return at_check, at_t0[0], at_nodes.reshape(s_nodes.shape), at_images.reshape(s_check.shape)

    def defect_bound(exact_check, approx_check, c_new, sup_old, size_old):
        """sup-norm bound of the defect on [0, t*]: sup_old bounds the old function on E_rho, size_old on [0, t*].

        ``approx_check`` is ``c_new`` evaluated at the check nodes."""
        d = exact_check - approx_check
        coef = _cheb_coeffs(d)
        fp = 8 * (N2 + 1) * _EPS * (size_old + np.abs(c_new).sum())
        return float(np.abs(coef).sum() + tail * (sup_old + float(np.abs(c_new) @ pow_rho)) + fp)

    v_check = setup.V(check_t, extended=True)
    c = _cheb_coeffs(setup.V(nodes_t, extended=True))
    at_check, at_t0, at_nodes, at_images = evaluate(c)
    err = defect_bound(v_check, at_check, c, setup.V_sup, float(np.abs(v_check).max()))
    mus, errs = [float(at_t0)], [err]
    n = 0
    while n < n_iter - 1:
        c_new = _cheb_coeffs(w @ at_nodes)
        exact_check = w @ at_images
        at_check, at_t0, at_nodes, at_images = evaluate(c_new)
        err += defect_bound(exact_check, at_check, c_new, float(np.abs(c) @ pow_rho), float(np.abs(c).sum()))
        c = c_new
        n += 1
        mus.append(float(at_t0))
        errs.append(err)
        if stop_width is not None and n % 10 == 0:
            lo, hi = _range(c)
            if hi - lo < stop_width * abs(mus[-1]) or hi - lo <= 16 * err:
                break
    return np.array(mus, dtype=float), np.array(errs), c


def _range(c):
    """Rigorous bracket [lo, hi] of the Chebyshev series c over s in [-1, 1]."""
    s = np.linspace(-1.0, 1.0, 2049).astype(_LD)
    v = C.chebval(s, c)
    k = np.arange(len(c))
    slack = 0.5 * float(s[1] - s[0]) * float(np.sum(k * k * np.abs(c)))  # Markov: |u'| <= sum k^2 |c_k|
    slack += 8 * len(c) * _EPS * float(np.abs(c).sum())  # rounding of the evaluations
    return float(v.min()) - slack, float(v.max()) + slack


def _degree(rho, target=1e-21):
    return int(np.clip(np.ceil(np.log(1.0 / target) / np.log(rho)), 16, 256))


def exact_mean(p0, a, R1, sensor_vars, probs, horizon) -> ExactMean:
    """Exact E(p_k), k = 0..horizon, of eq. (6) (one sensor) or eq. (14) (several), with an error bound.

    See the module docstring for the method and the bound.

    Parameters
    ----------
    p0 : float
        Deterministic p_0 >= 0.
    a, R1 : float
        System coefficient and process noise variance (R1 > 0).
    sensor_vars : sequence of float
        Measurement noise variances of the scalar (C = 1) sensors (R2 for eq. (6)).
    probs : sequence of float
        Independent arrival probabilities of the sensors.
    horizon : int
        T.

    Returns
    -------
    ExactMean
        E(p_k) with its relative error bound, and the mu_j.

    Raises
    ------
    InputError
        If an argument is out of range.
    ModelError
        If the analyticity check fails (no ellipse is mapped into itself).
    """
    if horizon < 0:
        raise InputError(f"horizon must be >= 0, got {horizon}")
    setup = _Setup(p0, a, R1, sensor_vars, probs)
    degree = _degree(setup.rho)
    T = int(horizon)
    if T == 0:
        return ExactMean(np.array([float(p0)]), np.zeros(1), np.zeros(0), np.zeros(0), setup.rho, degree)
    mu, mu_err, _ = _backward(setup, T, degree)
    mu_err = mu_err + np.finfo(float).eps * np.abs(mu)  # mu rounded to float64
    W = conditional_mean_weights(T, a, setup.pi0)
    with np.errstate(over="ignore", invalid="ignore"):
        mean = mu @ W + loss_path_terms(T, p0, a, R1, setup.pi0)
        abs_err = mu_err @ W
        rel = abs_err / mean + 4 * (T + 1) * np.finfo(float).eps  # plus the float64 rounding of the final sums
    rel[0] = 0.0
    return ExactMean(mean, rel, mu, mu_err, setup.rho, degree)


def stationary_mean(a, R1, sensor_vars, probs, p0=0.0, width=1e-14, max_iter=5000) -> dict:
    """lim E(p_k) for a stable case (pi_0 a^2 < 1), bracketed rigorously.

    Parameters
    ----------
    a, R1 : float
        System coefficient and process noise variance.
    sensor_vars, probs : sequence of float
        Sensor variances and arrival probabilities.
    p0 : float
        Any p_0 (the limit does not depend on it; it only sets the state interval).
    width : float
        Stop once the bracket of mu_inf is narrower than ``width`` relative.
    max_iter : int
        Iteration cap.

    Returns
    -------
    dict
        ``mean, lo, hi`` (E(p_inf) and its bracket), ``mu, mu_lo, mu_hi``, ``n_iter``.

    Raises
    ------
    ModelError
        If pi_0 a^2 >= 1 (E(p_k) diverges) or the analyticity check fails.
    """
    setup = _Setup(p0, a, R1, sensor_vars, probs)
    pi0 = setup.pi0
    if pi0 * a * a >= 1.0:
        raise ModelError(f"pi_0 a^2 = {pi0 * a * a:.6g} >= 1: E(p_k) is unbounded, no stationary mean")
    degree = _degree(setup.rho)
    mus, errs, c = _backward(setup, max_iter, degree, stop_width=width)
    lo, hi = _range(c)
    mu_lo, mu_hi = lo - errs[-1], hi + errs[-1]
    mu_lo, mu_hi = mu_lo * (1 - 4 * np.finfo(float).eps), mu_hi * (1 + 4 * np.finfo(float).eps)  # float64 rounding
    if np.isclose(a * a, 1.0):
        const = (1.0 - pi0) * R1 * pi0 / (1.0 - pi0) ** 2
    else:
        const = (1.0 - pi0) * R1 / (a * a - 1.0) * (1.0 / (1.0 - pi0 * a * a) - 1.0 / (1.0 - pi0))
    gain = 1.0 / (1.0 - pi0 * a * a)
    mu = 0.5 * (mu_lo + mu_hi)
    rnd = 8 * np.finfo(float).eps  # rounding of the closed form below
    return {"mean": gain * mu + const, "lo": (gain * mu_lo + const) * (1 - rnd), "hi": (gain * mu_hi + const) * (1 + rnd),
            "mu": mu, "mu_lo": mu_lo, "mu_hi": mu_hi, "n_iter": len(mus)}
