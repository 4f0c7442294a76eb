r"""Certified feasibility for the `gainsched` LMIs: the plant LMI, the necessary condition, sigma^2 brackets.

Every decision goes through the shared solve-and-certify engine
(:mod:`netrepro.engines.certify`, issue 16 section 1) and is never read off a solver status:

``feasible``
    The returned point satisfies every block strictly by the engine's own eigenvalue check
    (margin: eigensolver backward error plus the rounding of evaluating the blocks).
``infeasible``
    A checked dual certificate of the engine, or the independent necessary condition of this
    module: any of Theorems 1-3 (and the plant LMI) implies that (10) (resp. the plant (1)) is
    mean-square stable for every f in the sector (3), in particular for the linear f = F z with
    F at a vertex of the diagonal sector; so if the plant's second-moment operator
    :math:`\mathcal L_F = (A+BFZ)\otimes(A+BFZ) + \sigma^2 D\otimes D` has spectral radius
    :math:`\ge 1 + 10^{-9}` at a vertex (a 4 x 4 eigenvalue problem of a nonnegative operator,
    computed to about 1e-15, radius nondecreasing in sigma^2), no certificate exists.
``undecided``
    Neither: recorded, never counted either way.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from .model import System, sector_cases

__all__ = [
    "RADIUS_MARGIN",
    "plant_vertex_radius",
    "plant_necessary_fails",
    "necessary_condition",
    "with_sigma2",
    "PlantLMI",
    "necessary_limit",
]

RADIUS_MARGIN = 1e-9  # a radius computed to ~1e-15 (4 x 4 nonnegative matrix); 1e-9 leaves six orders


def with_sigma2(sys: System, sigma2: float) -> System:
    """The same system with noise variance ``sigma2``.

    Parameters
    ----------
    sys : System
    sigma2 : float

    Returns
    -------
    System
    """
    return dataclasses.replace(sys, sigma2=float(sigma2))


def plant_vertex_radius(sys: System, sigma2: float) -> float:
    """max over diagonal sector vertices F of rho((A+BFZ) (x) (A+BFZ) + sigma^2 D (x) D), plant (1).

    Parameters
    ----------
    sys : System
    sigma2 : float

    Returns
    -------
    float
    """
    rho = 0.0
    for F in sector_cases(sys).values():
        AF = sys.A + sys.B @ F @ sys.Z
        op = np.kron(AF, AF) + float(sigma2) * np.kron(sys.D, sys.D)
        rho = max(rho, float(np.max(np.abs(np.linalg.eigvals(op)))))
    return rho


def plant_necessary_fails(sys: System, sigma2: float) -> bool:
    """True when the necessary condition for mean-square stability under the sector fails (certified).

    Parameters
    ----------
    sys : System
    sigma2 : float

    Returns
    -------
    bool
        ``plant_vertex_radius >= 1 + RADIUS_MARGIN``.
    """
    return plant_vertex_radius(sys, sigma2) >= 1.0 + RADIUS_MARGIN


def necessary_condition(sys: System, sigma2: float):
    """The necessary condition as the engine's callable ``() -> (violated, evidence)``.

    Parameters
    ----------
    sys : System
    sigma2 : float

    Returns
    -------
    callable
        ``violated`` is :func:`plant_necessary_fails`; the evidence names the radius.
    """
    def check():
        rho = plant_vertex_radius(sys, sigma2)
        return rho >= 1.0 + RADIUS_MARGIN, f"plant vertex second-moment radius {rho:.12g} at sigma2 = {sigma2:.12g}"

    return check


class PlantLMI:
    """Lyapunov-S-procedure LMI for the plant (1) alone under the sector condition (3)-(5).

    With V = x^T P x and f = F1 Z x + f_s, E V(x+) - V(x) - 2 f_s^T L (f_s - F Z x) < 0 for a
    diagonal L >= 0 reads

    .. math::

        \\begin{bmatrix} A_1^T P A_1 + \\sigma^2 D^T P D - P & A_1^T P B + Z^T F L \\\\
        B^T P A_1 + L F Z & B^T P B - 2L \\end{bmatrix} \\prec 0,\\quad P \\succ 0,\\quad A_1 = A + B F_1 Z,

    and since f_s^T L (f_s - F Z x) <= 0 on the sector (5), E V decreases geometrically: the plant is
    exponentially mean-square stable for every f in the sector. Built once with sigma^2 a parameter;
    decided by :class:`netrepro.engines.certify.CertifiedLMI` (blocks: the matrix, P and the
    entries of L, all strict).

    Parameters
    ----------
    sys : System
    margin_cap : float
        The solver maximises t (blocks <= -t I, P >= t I, L >= t) with t <= margin_cap.
    bound : float
        Entry-wise bound on P and L (scale fixing; not part of the question).

    Returns
    -------
    PlantLMI
    """

    def __init__(self, sys: System, margin_cap: float = 0.1, bound: float = 100.0):
        import cvxpy as cp

        from ...engines.certify import CertifiedLMI

        self.sys = sys
        n, nz = sys.n, sys.nz
        self.sigma2 = cp.Parameter(nonneg=True, value=sys.sigma2, name="sigma2")
        self.P = cp.Variable((n, n), symmetric=True, name="P")
        self.lam = cp.Variable(nz, name="lambda")
        self.t = cp.Variable(name="t")
        M = self.matrix(self.P, cp.diag(self.lam), self.sigma2)
        d = n + nz
        negM = -0.5 * (M + M.T)
        cons = [negM >> self.t * np.eye(d), self.P >> self.t * np.eye(n), self.lam >= self.t, self.t <= margin_cap,
                cp.abs(self.P) <= bound, self.lam <= bound]
        self.problem = cp.Problem(cp.Maximize(self.t), cons)
        self.certifier = CertifiedLMI([("decrease", negM), ("P", self.P), ("lambda", self.lam)], problem=self.problem)

    def matrix(self, P, L, sigma2):
        """The block matrix of the class docstring for given P, L, sigma^2 (arrays or cvxpy expressions).

        Parameters
        ----------
        P : (n, n)
        L : (nz, nz), diagonal
        sigma2 : float or cvxpy parameter

        Returns
        -------
        ndarray or cvxpy expression (n + nz, n + nz)
        """
        import cvxpy as cp

        s = self.sys
        A1 = s.A + s.B @ s.F1 @ s.Z
        rows = [[A1.T @ P @ A1 + sigma2 * (s.D.T @ P @ s.D) - P, A1.T @ P @ s.B + s.Z.T @ s.F @ L],
                [s.B.T @ P @ A1 + L @ s.F @ s.Z, s.B.T @ P @ s.B - 2 * L]]
        if any(type(x).__module__.startswith("cvxpy") for x in (P, L, sigma2)):
            return cp.bmat(rows)
        return np.block(rows)

    def certify(self, sigma2: float):
        """Solve at ``sigma2`` and decide with the engine (point check, necessary condition, dual certificate).

        Parameters
        ----------
        sigma2 : float

        Returns
        -------
        netrepro.engines.certify.Verdict
        """
        self.sigma2.value = float(sigma2)
        return self.certifier.solve(necessary=necessary_condition(self.sys, sigma2))


def necessary_limit(sys: System, lo: float, hi: float, tol: float = 1e-6) -> tuple:
    """Bracket of the sigma^2 where the plant's vertex second-moment radius reaches 1 + RADIUS_MARGIN.

    The radius is nondecreasing in sigma^2 (the operator is a nonnegative combination of
    positive maps), so plain bisection applies.

    Parameters
    ----------
    sys : System
    lo, hi : float
        The radius must be below the threshold at ``lo`` and at or above it at ``hi``.
    tol : float

    Returns
    -------
    tuple of float
        ``(below, above)``: necessary condition holds at ``below``, fails (certified infeasible) at ``above``;
        ``(nan, nan)`` if ``hi`` does not reach the threshold.
    """
    if not plant_necessary_fails(sys, hi):
        return np.nan, np.nan
    a, b = float(lo), float(hi)
    while b - a > tol:
        mid = 0.5 * (a + b)
        if plant_necessary_fails(sys, mid):
            b = mid
        else:
            a = mid
    return a, b
