"""Independent checks of the paper's statements: the mathematics behind the evidence of `gainsched`.

Moved out of :mod:`.evidence` (issue 29: the evidence step only assembles). Each function is an
independent computation of something the paper states or implies:

* :func:`ms_stability_index`, :func:`convergence_rate`: exponential mean-square stability of the
  error dynamics (10) (Definition 1) with given gains, from second-moment operators;
* :func:`r2_congruence_residuals`: the relation of R2 to S21, S22 in Theorem 3 / (23);
* :func:`missing_fraction`: the fraction of missing measurements under (6)-(7);
* :func:`eq15_residuals`: E ΔV of (14) against the two sign readings of (15);
* :func:`gap_relative`, :func:`relative_spread`, :func:`rms_ratio`: the relative quantities the findings
  and claims are judged on.
"""

from __future__ import annotations

import numpy as np

from .model import (
    GainschedError,
    Gains,
    System,
    frozen_radius,
    lyapunov_difference_bounds,
    scheduled_growth_rate,
    sector_cases,
    sector_nonlinearity,
)
from .moments import linear_gains

__all__ = [
    "ms_stability_index",
    "frozen_ms_radius",
    "ms_stable_decision",
    "convergence_rate",
    "r2_congruence_residuals",
    "missing_fraction",
    "eq15_residuals",
    "gap_relative",
    "relative_spread",
    "rms_ratio",
]


def ms_stability_index(sys: System, gains: Gains, ps, p_seq, worst_gain: bool = True) -> float:
    """Largest frozen second-moment radius of (10) and growth rate along ``p_seq`` (the MS stability index).

    Frozen radii at p in ``ps`` with f = F z at the diagonal sector vertices and (``worst_gain``,
    nz = 2) at the worst linear gain of class (3), K = (F1+F2)/2 + U(F2-F1)/2 with U orthogonal
    (:func:`.feasibility.worst_sector_gain` at ``sys.sigma2``: it meets (3) with equality and is
    not diagonal); growth along the scheduled ``p_seq``. (10) is exponentially mean-square stable
    for these linear f iff this is below 1 (Definition 1); a value >= 1 shows an f of class (3)
    for which (10) is not mean-square stable. (10) is block-triangular, so its radius is at least
    the plant's for the same f: the rotated gain reaches 1 at the plant's necessary end for class
    (3), below the diagonal vertices' end.

    Parameters
    ----------
    sys : System
        The plant (1), (2), (6) with its sector (3), noise variance and bounds of p(k).
    gains : Gains
        The filter gains of (9).
    ps : array_like
        Frozen probabilities.
    p_seq : array_like
        The scheduled p(k) of Section IV.
    worst_gain : bool
        Add the worst rotated gain of class (3) to the diagonal vertices (default; ``False``: the
        four diagonal vertices only, the former index).

    Returns
    -------
    float
        The larger of the largest frozen radius and the largest growth rate; below 1 for mean-square
        stability.
    """
    rho = frozen_ms_radius(sys, gains, ps, worst_gain)
    growth = max(scheduled_growth_rate(sys, gains, p_seq, F) for F in _class3_gains(sys, worst_gain))
    return float(max(rho, growth))


def frozen_ms_radius(sys: System, gains: Gains, ps, worst_gain: bool = True) -> float:
    """Largest second-moment spectral radius of (10) at frozen p in ``ps`` over linear f of class (3).

    A constant p(k) = p in [p1, p2] is an admissible schedule and f = F z with F meeting (3) an
    admissible nonlinearity, so a radius >= 1 shows that (10) is not exponentially mean-square
    stable for that f and p(k) (Definition 1): a necessary condition, unlike the finite-horizon
    growth rate of :func:`ms_stability_index` (a norm of a finite product, which exceeds the
    asymptotic rate by its transient). The gains F are the diagonal sector vertices and (nz = 2,
    ``worst_gain``) the worst rotated gain of :func:`.feasibility.worst_sector_gain` at ``sys.sigma2``.

    Parameters
    ----------
    sys : System
        The plant (1), (2), (6) with its sector (3), noise variance and bounds of p(k).
    gains : Gains
        The filter gains of (9).
    ps : array_like
        Frozen probabilities in [p1, p2].
    worst_gain : bool
        Add the worst rotated gain of class (3) to the diagonal vertices.

    Returns
    -------
    float
        The largest frozen radius.
    """
    return float(max(frozen_radius(sys, gains, float(p), F) for p in ps for F in _class3_gains(sys, worst_gain)))


def _class3_gains(sys: System, worst_gain: bool) -> list:
    """The linear gains F of class (3) the indices check: the diagonal sector vertices, and (nz = 2,
    ``worst_gain``) the worst rotated gain of :func:`.feasibility.worst_sector_gain` at ``sys.sigma2``."""
    from .feasibility import worst_sector_gain

    cases = list(sector_cases(sys).values())
    if worst_gain and sys.nz == 2:
        cases.append(worst_sector_gain(sys, sys.sigma2)["K"])
    return cases


def ms_stable_decision(index: float, sigma2: float, certified_to: float, refuted_from: float) -> tuple:
    """Decide mean-square stability of (10) for every f of class (3) at ``sigma2`` from its certificates.

    Sufficient: (24) with these gains certified feasible at ``certified_to`` (feasibility of (24) is
    monotone in sigma^2 > 0, and (24) implies (12), which implies mean-square stability for every f
    of the class: Theorems 1-3), so stable for every ``sigma2 <= certified_to``. Necessary: the
    frozen radius of :func:`frozen_ms_radius` >= 1 + RADIUS_MARGIN (a linear f of the class that is not
    mean-square stable), or ``sigma2 >= refuted_from`` (the plant alone is not mean-square stable
    for some f of the class from there on; the radius is nondecreasing in sigma^2). Otherwise
    undecided.

    Parameters
    ----------
    index : float
        :func:`frozen_ms_radius` at ``sigma2`` (a necessary condition: >= 1 refutes).
    sigma2 : float
        Variance of the multiplicative noise w(k) of (1).
    certified_to : float
        Certified feasible end of (24) for these gains (nan: none).
    refuted_from : float
        Certified infeasible end (the class's necessary end; nan: none).

    Returns
    -------
    tuple
        ``(value, decided)``: ``value`` a Python bool (True: stable for every f of the class),
        ``decided`` False when neither certificate applies (``value`` is then ``index < 1``, information).
    """
    from .feasibility import RADIUS_MARGIN

    if np.isfinite(certified_to) and sigma2 <= certified_to:
        return True, True
    if index >= 1.0 + RADIUS_MARGIN or (np.isfinite(refuted_from) and sigma2 >= refuted_from):
        return False, True
    return bool(index < 1.0), False


def convergence_rate(sys: System, gains: Gains, p_seq) -> float:
    """Worst per-step growth rate of E z̄ z̄^T of (10) along ``p_seq`` over f = F z, F in {F1, F2, (F1+F2)/2}.

    Below 1 iff E||e(k)||^2 -> 0 for every initial second moment (the errors of Figs 1-2 converge).

    Parameters
    ----------
    sys : System
        The plant (1), (2), (6) with its sector (3), noise variance and bounds of p(k).
    gains : Gains
        The filter gains of (9).
    p_seq : array_like
        The scheduled p(k) of Section IV.

    Returns
    -------
    float
        The largest per-step growth rate over the three linear gains.
    """
    return float(max(scheduled_growth_rate(sys, gains, p_seq, F) for F in linear_gains(sys).values()))


def r2_congruence_residuals(values: dict) -> dict:
    """||T^T S T - [[S11, R1], [R2, R2]]||_F with S21 = I and S22 from each reading of R2 (Theorem 3, (23)).

    ``corrected``: R2 = S21^T S22^{-T} S21, so S22 = R2^{-T}; ``printed``: R2 = S21^T S22^{-1} S21,
    S22 = R2^{-1}. S12 = R1 S22 (R1 = S12 S22^{-1} S21), T = diag(I, S22^{-1} S21).

    Parameters
    ----------
    values : dict
        A Theorem 3 solution (S11, R1, R2).

    Returns
    -------
    dict
        ``{"printed": float, "corrected": float}``.
    """
    n = values["R2"].shape[0]
    S21 = np.eye(n)
    out = {}
    for reading, S22 in (("corrected", np.linalg.inv(values["R2"]).T), ("printed", np.linalg.inv(values["R2"]))):
        S = np.block([[values["S11"], values["R1"] @ S22], [S21, S22]])
        T = np.block([[np.eye(n), np.zeros((n, n))], [np.zeros((n, n)), np.linalg.solve(S22, S21)]])
        target = np.block([[values["S11"], values["R1"]], [values["R2"], values["R2"]]])
        out[reading] = float(np.linalg.norm(T.T @ S @ T - target))
    return out


def missing_fraction(p_seq, n_runs: int, seed: int) -> tuple:
    """Fraction of missing measurements (xi(k) = 0) of (6)-(7) in ``n_runs`` simulated runs, and its standard error.

    Parameters
    ----------
    p_seq : array_like
        Prob{xi(k) = 1} (7).
    n_runs : int
        Number of simulated runs, each as long as ``p_seq``.
    seed : int
        Seed of the random generator (``numpy.random.default_rng``).

    Returns
    -------
    tuple of float
        ``(fraction, standard error)``.
    """
    p_seq = np.asarray(p_seq, dtype=float)
    xi = np.random.default_rng(seed).random((n_runs, p_seq.size)) < p_seq
    frac = 1.0 - xi.mean()
    se = float(np.sqrt(np.mean(p_seq * (1 - p_seq)) / xi.size))
    return float(frac), se


def eq15_residuals(sys: System, gains: Gains, Q0, Qp, rng: np.random.Generator, n_states: int = 4000,
                   scale: float = 3.0) -> tuple:
    """max of E ΔV (14) minus each reading of the right side of (15), over random states and nonlinearities.

    Over ``n_states`` random z̄, the nonlinearities sine_mid, lower and upper (as f(scale z)/scale,
    which stays in the sector and is far from linear) and the (p, p+) pairs (p1, p2), (p2, p1),
    (p1, p1). (15) bounds E ΔV from above, so a correct reading gives a value <= 0 (to rounding).

    Parameters
    ----------
    sys : System
        The plant (1), (2), (6) with its sector (3), noise variance and bounds of p(k).
    gains : Gains
        The filter gains of (9) that the Lyapunov matrix certifies.
    Q0, Qp : ndarray (2n, 2n)
        The Lyapunov matrix Q(p) = Q0 + p Qp of (27).
    rng : numpy.random.Generator
        Source of the random states z̄.
    n_states : int
        Number of random states z̄ (at least 1).
    scale : float
        Scale of the states fed to the nonlinearities, f(scale z)/scale, to leave their linear part.

    Returns
    -------
    tuple of float
        ``(printed, corrected)``: the largest excess with '+' (printed) and '-' (corrected) in (15).

    Raises
    ------
    GainschedError
        If ``n_states < 1``.
    """
    if n_states < 1:
        raise GainschedError(f"eq15_residuals: n_states must be >= 1, got {n_states}")
    zbar = rng.standard_normal((int(n_states), 2 * sys.n))
    worst_c, worst_p = -np.inf, -np.inf
    for kind in ("sine_mid", "lower", "upper"):
        f = sector_nonlinearity(zbar @ (sys.Z @ sys.N).T * scale, sys.F1, sys.F2, kind) / scale
        for p, pn in ((sys.p1, sys.p2), (sys.p2, sys.p1), (sys.p1, sys.p1)):
            dv, corr, prin = lyapunov_difference_bounds(sys, gains, Q0, Qp, p, pn, zbar, f)
            worst_c = max(worst_c, float(np.max(dv - corr)))
            worst_p = max(worst_p, float(np.max(dv - prin)))
    return worst_p, worst_c


def gap_relative(lower: float, upper: float) -> float:
    """(upper - lower) / upper: how far below ``upper`` the end ``lower`` lies, as a fraction of ``upper``.

    Parameters
    ----------
    lower, upper : float
        The two ends compared; ``upper`` must be positive and finite.

    Returns
    -------
    float
        (upper - lower) / upper.

    Raises
    ------
    GainschedError
        If ``upper`` is not positive and finite.
    """
    if not (np.isfinite(upper) and upper > 0):
        raise GainschedError(f"gap_relative: upper must be positive and finite, got {upper}")
    return float((upper - lower) / upper)


def relative_spread(values) -> float:
    """max / min - 1 of positive values: how much the largest exceeds the smallest, as a fraction.

    Parameters
    ----------
    values : array_like
        Positive numbers (e.g. one design's exact sum_k E||e(k)||^2 under several realisations).

    Returns
    -------
    float

    Raises
    ------
    GainschedError
        If ``values`` is empty or not all positive and finite.
    """
    v = np.asarray(values, dtype=float)
    if v.size == 0 or not np.all(np.isfinite(v) & (v > 0)):
        raise GainschedError(f"relative_spread needs positive finite values, got {v.tolist()}")
    return float(v.max() / v.min() - 1.0)


def rms_ratio(mse) -> float:
    """sqrt(E||e(K)||^2 / E||e(0)||^2): the factor by which the RMS error has shrunk from k = 0 to the last k.

    Parameters
    ----------
    mse : array_like (K+1,)
        E||e(k)||^2 in order of k.

    Returns
    -------
    float

    Raises
    ------
    GainschedError
        If ``mse`` is empty or E||e(0)||^2 is not positive.
    """
    m = np.asarray(mse, dtype=float)
    if m.size == 0 or not m[0] > 0:
        raise GainschedError(f"rms_ratio needs E||e(0)||^2 > 0, got {m[:1].tolist()}")
    return float(np.sqrt(m[-1] / m[0]))
