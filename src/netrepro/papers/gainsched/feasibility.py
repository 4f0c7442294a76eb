"""Certified feasibility decisions for the `gainsched` LMIs and the largest certified noise variance.

A decision is never read off a solver status (issue 16, section 1):

``feasible``
    The point the solver returned satisfies every block of the LMI strictly, checked here by
    our own eigenvalue computation: :math:`\\lambda_{\\max}(\\mathrm{sym}\\,M) < -\\tau(M)` for every
    block that must be negative definite (and :math:`\\lambda_{\\min} > \\tau` for every positive
    one), with :math:`\\tau(M) = 100\\, d\\, \\varepsilon \\|M\\|_F` (d the block size, ε the
    float64 unit roundoff). The symmetric eigensolver is backward stable (computed eigenvalues
    are exact for a matrix within :math:`p(d)\\varepsilon\\|M\\|_2` of the one given, p(d) a modest
    function of d), and evaluating M from the variable values adds an error of the same order;
    the factor 100 d covers both with room. The margin is fixed here, before any comparison.
``infeasible``
    An independent necessary condition fails: any of Theorems 1-3 (and the plant LMI) implies
    that (10) (resp. the plant (1)) is mean-square stable for every f in the sector (3), in
    particular for the linear f = F z with F at a vertex of the diagonal sector; so if the
    second-moment operator :math:`\\mathcal L_F = (A+BFZ)\\otimes(A+BFZ) + \\sigma^2 D\\otimes D`
    of the plant has spectral radius :math:`\\ge 1 + 10^{-9}` at a vertex (a 4 x 4 eigenvalue
    problem of a nonnegative operator, radius nondecreasing in σ²), no certificate exists.
``undecided``
    Neither: recorded, never counted either way.

The solver status is kept as information only.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .model import System, sector_cases

__all__ = [
    "FEASIBLE",
    "INFEASIBLE",
    "UNDECIDED",
    "RADIUS_MARGIN",
    "eig_margin",
    "Verdict",
    "check_blocks",
    "plant_vertex_radius",
    "plant_necessary_fails",
    "with_sigma2",
    "PlantLMI",
    "CertifiedBracket",
    "bisect_certified",
]

FEASIBLE, INFEASIBLE, UNDECIDED = "feasible", "infeasible", "undecided"
EPS = float(np.finfo(float).eps) / 2.0
RADIUS_MARGIN = 1e-9  # a radius computed to ~1e-15 (4 x 4 nonnegative matrix); 1e-9 leaves six orders


def eig_margin(M) -> float:
    """The fixed strictness margin τ(M) = 100 d ε ||M||_F of a d x d block (module docstring).

    Parameters
    ----------
    M : ndarray (d, d)

    Returns
    -------
    float
    """
    M = np.asarray(M, dtype=float)
    return 100.0 * M.shape[0] * EPS * float(np.linalg.norm(M))


def check_blocks(negative=(), positive=()):
    """Our own check of a candidate point: every block strictly on its side, beyond its margin.

    Parameters
    ----------
    negative : iterable of ndarray
        Blocks that must be negative definite (symmetrised here).
    positive : iterable of ndarray
        Blocks that must be positive definite.

    Returns
    -------
    tuple
        ``(ok, slack)``: ``ok`` True iff every block passes; ``slack`` the smallest of
        ``-lambda_max - tau`` (negative blocks) and ``lambda_min - tau`` (positive blocks),
        > 0 iff ``ok``.
    """
    slack = np.inf
    for M in negative:
        S = 0.5 * (np.asarray(M, float) + np.asarray(M, float).T)
        slack = min(slack, -float(np.linalg.eigvalsh(S)[-1]) - eig_margin(S))
    for M in positive:
        S = 0.5 * (np.asarray(M, float) + np.asarray(M, float).T)
        slack = min(slack, float(np.linalg.eigvalsh(S)[0]) - eig_margin(S))
    return bool(slack > 0), float(slack)


@dataclass(frozen=True)
class Verdict:
    """A certified decision at one point.

    Parameters
    ----------
    verdict : str
        ``feasible``, ``infeasible`` or ``undecided``.
    slack : float
        Smallest block slack of the checked point (> 0 iff feasible by the point check; nan without a point).
    radius : float
        Largest plant second-moment radius over the sector vertices (the necessary condition).
    status : str
        Solver status (information only).
    solver_margin : float
        The solver's objective t (information only).

    Returns
    -------
    Verdict
    """

    verdict: str
    slack: float
    radius: float
    status: str = ""
    solver_margin: float = np.nan


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
    return System(sys.A, sys.B, sys.C, sys.D, sys.Z, sys.F1, sys.F2, float(sigma2), sys.p1, sys.p2)


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


class PlantLMI:
    """Lyapunov-S-procedure LMI for the plant (1) alone under the sector condition (3)-(5).

    With V = x^T P x and f = F1 Z x + f_s, E V(x+) - V(x) - 2 f_s^T L (f_s - F Z x) < 0 for a
    diagonal L >= 0 reads

    .. math::

        \\begin{bmatrix} A_1^T P A_1 + \\sigma^2 D^T P D - P & A_1^T P B + Z^T F L \\\\
        B^T P A_1 + L F Z & B^T P B - 2L \\end{bmatrix} \\prec 0,\\quad P \\succ 0,\\quad A_1 = A + B F_1 Z,

    and since f_s^T L (f_s - F Z x) <= 0 on the sector (5), E V decreases geometrically: the plant is
    exponentially mean-square stable for every f in the sector. Built once with sigma^2 a parameter.

    Parameters
    ----------
    sys : System
    margin_cap : float
        The solver maximises t (blocks <= -t I, P >= t I) with t <= margin_cap.
    bound : float
        Entry-wise bound on P and L (scale fixing).

    Returns
    -------
    PlantLMI
    """

    def __init__(self, sys: System, margin_cap: float = 0.1, bound: float = 100.0):
        import cvxpy as cp

        self.sys = sys
        n, nz = sys.n, sys.nz
        self.sigma2 = cp.Parameter(nonneg=True, value=sys.sigma2)
        self.P = cp.Variable((n, n), symmetric=True)
        self.lam = cp.Variable(nz, nonneg=True)
        self.t = cp.Variable()
        M = self.matrix(self.P, cp.diag(self.lam), self.sigma2)
        d = n + nz
        cons = [0.5 * (M + M.T) << -self.t * np.eye(d), self.P >> self.t * np.eye(n), self.t <= margin_cap,
                cp.abs(self.P) <= bound, self.lam <= bound]
        self.problem = cp.Problem(cp.Maximize(self.t), cons)

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

    def certify(self, sigma2: float) -> Verdict:
        """Solve at ``sigma2`` and decide by our own check of the returned point, or the necessary condition.

        Parameters
        ----------
        sigma2 : float

        Returns
        -------
        Verdict
        """
        import cvxpy as cp

        from ...engines.lmi import SOLVER

        self.sigma2.value = float(sigma2)
        status, tval = "", np.nan
        try:
            self.problem.solve(solver=SOLVER)
            status = str(self.problem.status)
            tval = float(self.t.value) if self.t.value is not None else np.nan
        except cp.error.SolverError as exc:  # pragma: no cover - solver failure path
            status = f"solver_error: {exc}"
        radius = plant_vertex_radius(self.sys, sigma2)
        slack = np.nan
        if self.P.value is not None and self.lam.value is not None:
            P = np.array(self.P.value)
            L = np.diag(np.maximum(np.array(self.lam.value), 0.0))  # L >= 0 exactly
            ok, slack = check_blocks(negative=[self.matrix(P, L, float(sigma2))], positive=[P])
            if ok:
                return Verdict(FEASIBLE, slack, radius, status, tval)
        if radius >= 1.0 + RADIUS_MARGIN:
            return Verdict(INFEASIBLE, slack, radius, status, tval)
        return Verdict(UNDECIDED, slack, radius, status, tval)


@dataclass(frozen=True)
class CertifiedBracket:
    """Result of :func:`bisect_certified`.

    Parameters
    ----------
    lo : float
        Largest point decided feasible (nan if none).
    hi : float
        Smallest point decided infeasible (nan if none).
    undecided_lo : float
        Smallest point left undecided above ``lo`` (nan if none): the true limit lies in [lo, hi],
        and nothing is claimed about (lo, hi).
    n_evals : int
    history : tuple
        ``(x, verdict)`` pairs in evaluation order.

    Returns
    -------
    CertifiedBracket
    """

    lo: float
    hi: float
    undecided_lo: float
    n_evals: int
    history: tuple

    @property
    def certified(self) -> bool:
        """Both ends certified (a feasible lo and an infeasible hi).

        Returns
        -------
        bool
        """
        return bool(np.isfinite(self.lo) and np.isfinite(self.hi))


def bisect_certified(decide, lo: float, hi: float, tol: float, max_evals: int = 60) -> CertifiedBracket:
    """Bracket the limit of a monotone feasible-then-infeasible property with certified ends.

    Feasible points move the lower end up, infeasible points the upper end down; an undecided
    point moves neither end but narrows the search from above (the next points are tried below
    it), so the search ends when ``hi - lo <= tol`` or when the feasible end is within ``tol`` of
    the smallest undecided point.

    Parameters
    ----------
    decide : callable
        ``decide(x) -> Verdict`` (its ``verdict`` field is used).
    lo, hi : float
        Initial ends; each is evaluated first.
    tol : float
    max_evals : int

    Returns
    -------
    CertifiedBracket
    """
    history = []

    def ask(x):
        v = decide(float(x)).verdict
        history.append((float(x), v))
        return v

    a, b, u = np.nan, np.nan, np.nan
    va, vb = ask(lo), ask(hi)
    if va == FEASIBLE:
        a = lo
    if vb == INFEASIBLE:
        b = hi
    if va != FEASIBLE or vb == FEASIBLE:
        if vb == FEASIBLE:
            a = hi
        return CertifiedBracket(a, b, np.nan if vb != UNDECIDED else hi, len(history), tuple(history))
    top = hi  # search interval (a, top): top is infeasible or undecided
    if vb == UNDECIDED:
        u = hi
    while top - a > tol and len(history) < max_evals:
        mid = 0.5 * (a + top)
        v = ask(mid)
        if v == FEASIBLE:
            a = mid
        else:
            top = mid
            if v == INFEASIBLE:
                b = mid
            else:
                u = mid if not np.isfinite(u) else min(u, mid)
    return CertifiedBracket(a, b, u, len(history), tuple(history))


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
