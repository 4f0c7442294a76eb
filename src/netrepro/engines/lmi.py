"""LMI helpers: parametrised cvxpy feasibility problems, certification, bisection.

A sweep over a probability builds its cvxpy problem once with
:class:`cvxpy.Parameter` objects (DPP-compliant), so every further solve only
updates parameter values. A solver's "optimal" is never taken as proof: every
candidate certificate is checked by an independent computation (for Riccati
stabilisability, the spectral radius of the expected closed-loop second-moment
operator), and the status string of every solve is kept.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .cvx import cp, solve_problem

__all__ = [
    "LMIOutcome",
    "BisectionResult",
    "bisect_monotone",
    "bisect_bracketed",
    "sweep_thresholds",
    "second_moment_radius",
    "MareStabilizabilityLMI",
]

from .cvx import SOLVER  # noqa: E402  (re-exported: the project's solver)


@dataclass
class LMIOutcome:
    """One solve: the solver's status, its margin, and our independent verdict.

    Attributes
    ----------
    status : str
        The solver's status (or ``solver_error: ...``).
    margin : float
        The maximised ``t`` in ``Psi >= t I`` (nan when the solver failed).
    solver_feasible : bool
        Status optimal and margin above the tolerance.
    certified : bool
        The independent check passed (see :class:`MareStabilizabilityLMI`).
    certificate_value : float
        E.g. the spectral radius of the closed loop (nan if none).
    variables : dict
        The recovered values (e.g. ``Y`` and the gains ``K``).
    """

    status: str
    margin: float  # the maximised t in Psi >= t I (nan when the solver failed)
    solver_feasible: bool  # status optimal and margin above tolerance
    certified: bool  # independent check passed
    certificate_value: float  # e.g. spectral radius of the closed loop (nan if none)
    variables: dict = field(default_factory=dict)


@dataclass
class BisectionResult:
    """Outcome of :func:`bisect_monotone` / :func:`bisect_bracketed`.

    Attributes
    ----------
    threshold : float
        Smallest value found feasible (upper end of the final bracket; nan if none).
    lower : float
        Largest value found infeasible (nan if none).
    n_evals : int
        Number of predicate evaluations.
    history : list of (float, bool)
        ``(value, feasible)`` pairs in evaluation order.
    bracketed : bool
        True when ``lower`` was infeasible and ``threshold`` feasible.
    """

    threshold: float  # smallest value found feasible (upper end of the final bracket)
    lower: float  # largest value found infeasible
    n_evals: int
    history: list  # (value, feasible) pairs, in evaluation order
    bracketed: bool  # True when lo was infeasible and hi feasible


def _lattice(lo: float, hi: float, tol: float, max_evals: int):
    """The points a bisection of ``[lo, hi]`` to width ``tol`` can visit: ``lo + (hi - lo) j / n``.

    ``n = 2^L`` with ``L`` the number of halvings that bring ``hi - lo`` to at most ``tol``
    (capped so that the ends and the halvings fit in ``max_evals``). Plain and bracketed
    bisections evaluate only these points, so for a monotone predicate both end on the same
    smallest feasible point, whatever the starting bracket.
    """
    levels = 0
    while (hi - lo) / 2.0 ** levels > tol and levels < max(max_evals - 2, 0):
        levels += 1
    n = 2 ** levels
    return n, (lambda j: lo + (hi - lo) * (j / n))


def _recording(is_feasible):
    """``(check, history)``: ``check(x)`` evaluates the predicate and appends ``(x, result)`` to ``history``."""
    history = []

    def check(x):
        ok = bool(is_feasible(x))
        history.append((float(x), ok))
        return ok

    return check, history


def _halve(check, point, a, b, history) -> BisectionResult:
    """Halve a bracket of lattice indices (``a`` infeasible, ``b`` feasible) to adjacent points."""
    while b - a > 1:
        mid = (a + b) // 2
        if check(point(mid)):
            b = mid
        else:
            a = mid
    return BisectionResult(point(b), point(a), len(history), history, True)


def bisect_monotone(is_feasible, lo: float, hi: float, tol: float = 1e-4, max_evals: int = 60) -> BisectionResult:
    """Smallest x in [lo, hi] with ``is_feasible(x)`` for a monotone predicate (False ... False True ... True).

    The ends are evaluated first; if ``lo`` is feasible, the threshold is ``lo``;
    if ``hi`` is infeasible the result has ``threshold = nan``. Otherwise the bracket is
    halved until it is at most ``tol`` wide; the threshold is a point of :func:`_lattice`.

    Parameters
    ----------
    is_feasible : callable
        ``is_feasible(x) -> bool``, monotone in ``x``.
    lo, hi : float
        The search interval.
    tol : float
        Target bracket width (the lattice spacing).
    max_evals : int
        Caps the number of halvings.

    Returns
    -------
    BisectionResult
        The threshold, the bracket and the evaluation history.
    """
    check, history = _recording(is_feasible)
    n, point = _lattice(lo, hi, tol, max_evals)
    if check(point(0)):
        return BisectionResult(lo, np.nan, len(history), history, False)
    if not check(point(n)):
        return BisectionResult(np.nan, hi, len(history), history, False)
    return _halve(check, point, 0, n, history)


def bisect_bracketed(is_feasible, lo: float, hi: float, guess: float, width: float, tol: float = 1e-4,
                     max_evals: int = 60) -> BisectionResult:
    """:func:`bisect_monotone` warm-started from a guess of the threshold; the same answer.

    The first bracket is ``[guess - width, guess + width]`` (clipped to ``[lo, hi]``; at least one
    lattice cell each side, so ``width = 0`` means the lattice points next to the guess) on the
    lattice of :func:`bisect_monotone`; while an end is on the wrong side it moves outwards by
    doubling steps, and reaching ``lo`` feasible or ``hi`` infeasible gives the same answers as
    :func:`bisect_monotone` (threshold ``lo``, or ``nan``). Then the bracket is halved to two
    adjacent lattice points. For a monotone predicate the threshold and the lower end are
    exactly those of :func:`bisect_monotone` (both are the smallest feasible lattice point and
    its neighbour), so the guess changes the number of evaluations, never the answer. With a
    good guess that is about ``2 + log2(2 width / tol)`` instead of ``2 + log2((hi - lo) / tol)``.

    Parameters
    ----------
    is_feasible : callable
        ``is_feasible(x) -> bool``, monotone in ``x``.
    lo, hi : float
        The search interval.
    guess : float
        Estimate of the threshold (non-finite: plain :func:`bisect_monotone`).
    width : float
        Half-width of the first bracket around ``guess``.
    tol, max_evals : float, int
        As in :func:`bisect_monotone`.

    Returns
    -------
    BisectionResult
        The same threshold and lower end as :func:`bisect_monotone`.

    Raises
    ------
    ValueError
        If ``lo > hi``.
    """
    if not lo <= hi:
        raise ValueError(f"bisect_bracketed needs lo <= hi, got lo={lo}, hi={hi}")
    if not np.isfinite(guess):
        return bisect_monotone(is_feasible, lo, hi, tol, max_evals)
    check, history = _recording(is_feasible)
    n, point = _lattice(lo, hi, tol, max_evals)
    cell = (hi - lo) / n if n else 1.0
    centre = int(round((min(max(float(guess), lo), hi) - lo) / cell)) if hi > lo else 0
    half = max(1, int(np.ceil(float(width) / cell))) if cell > 0 else 1
    step = half
    b = min(n, centre + half)
    a = None  # largest index known infeasible
    while not check(point(b)):
        a = b
        if b >= n:
            return BisectionResult(np.nan, hi, len(history), history, False)
        step *= 2
        b = min(n, b + step)
    if a is None:
        step = half
        a = max(0, min(centre - half, b - half))
        while check(point(a)):
            b = a
            if a <= 0:
                return BisectionResult(lo, np.nan, len(history), history, False)
            step *= 2
            a = max(0, a - step)
    return _halve(check, point, a, b, history)


def sweep_thresholds(make_predicate, grid, lo: float, hi: float, tol: float = 1e-4, max_evals: int = 60,
                     warm_start: bool = True) -> list[BisectionResult]:
    """Thresholds of a family of monotone predicates along ``grid``, each bisection bracketed by its neighbours.

    ``make_predicate(x)`` returns the predicate of grid point ``x``. The first
    point (and any point after a ``nan`` or end-point answer) runs a plain
    :func:`bisect_monotone`; the others start, via :func:`bisect_bracketed`, from
    the extrapolation of the previous bracketed thresholds (quadratic from three,
    width the second difference; linear from two, width half the last change;
    at least ``2 tol``). ``warm_start=False`` runs plain bisections throughout
    (the reference). For monotone predicates every threshold equals the plain bisection's
    exactly (:func:`bisect_bracketed`); only the number of solves changes.

    Parameters
    ----------
    make_predicate : callable
        ``make_predicate(x) -> is_feasible`` for grid point ``x``.
    grid : iterable of float
        The grid points, in sweep order.
    lo, hi, tol, max_evals : float, float, float, int
        As in :func:`bisect_monotone`.
    warm_start : bool
        Start each bisection from the extrapolated neighbours (same answers, fewer solves).

    Returns
    -------
    list of BisectionResult
        One per grid point.
    """
    results, found = [], []
    for x in grid:
        pred = make_predicate(x)
        usable = []
        for r in reversed(results[-3:]):  # the trailing run of bracketed answers, newest first
            if not (r.bracketed and np.isfinite(r.threshold)):
                break
            usable.append(r.threshold)
        if not warm_start or not usable:
            res = bisect_monotone(pred, lo, hi, tol, max_evals)
        else:
            if len(usable) == 3:  # quadratic extrapolation; its error is about the third difference
                t1, t2, t3 = usable
                guess, width = 3 * t1 - 3 * t2 + t3, abs(t1 - 2 * t2 + t3)
            elif len(usable) == 2:  # linear extrapolation
                guess, width = 2 * usable[0] - usable[1], 0.5 * abs(usable[0] - usable[1])
            else:
                guess, width = usable[0], 0.05 * (hi - lo)
            res = bisect_bracketed(pred, lo, hi, guess, max(width, 2 * tol), tol, max_evals)
        results.append(res)
        found.append(res.threshold)
    return results


def second_moment_radius(closed_loops, weights) -> float:
    """Spectral radius of X -> sum_i w_i F_i X F_i^T, i.e. of sum_i w_i kron(F_i, F_i).

    The expected error covariance of a switched linear recursion with i.i.d.
    mode weights ``w_i`` stays bounded for every noise level iff this is < 1.

    Parameters
    ----------
    closed_loops : sequence of ndarray (n, n)
        The matrices ``F_i``.
    weights : sequence of float
        The weights ``w_i``.

    Returns
    -------
    float
        The spectral radius.
    """
    op = sum(w * np.kron(F, F) for F, w in zip(closed_loops, weights))
    return float(np.max(np.abs(np.linalg.eigvals(np.atleast_2d(op)))))


class MareStabilizabilityLMI:
    """Existence of gains K_i and X > 0 with X > sum_i w_i (A + K_i C_i) X (A + K_i C_i)^T.

    This is the LMI test of Sinopoli et al. (2004, Thm 5) generalised to
    several independent loss modes as in Liu & Goldsmith (2004): mode i
    occurs with probability w_i and delivers the rows C_i (None: nothing
    arrives, closed loop A). By duality (the operator and its adjoint share
    their spectral radius) it is equivalent to Y > 0 with
    Y > sum_i w_i F_i^T Y F_i, and with Z_i = Y K_i the Schur complement gives

    .. math::

        \\Psi = \\begin{bmatrix} Y & \\sqrt{w_1}(YA+Z_1C_1)^T & \\cdots \\\\
                 \\sqrt{w_1}(YA+Z_1C_1) & Y & 0 \\\\ \\vdots & 0 & \\ddots \\end{bmatrix} \\succ 0 .

    The problem maximises t subject to Psi >= t I and 0 <= Y <= I (the LMI is
    homogeneous, so the bound only fixes the scale). The weights' square
    roots are :class:`cvxpy.Parameter` objects: a sweep compiles once.

    :meth:`solve` keeps its historical decision rule (status optimal, margin above
    ``margin_tol``, then the second-moment radius); :meth:`certify` gives the verdict of
    :mod:`netrepro.engines.certify` (feasible / infeasible / undecided, each certified).

    Parameters
    ----------
    A : array_like, shape ``(n, n)``
        State matrix.
    mode_outputs : sequence of (array_like or None)
        ``C_i`` delivered by mode ``i`` (None: nothing arrives).
    margin_tol : float
        Margin above which :meth:`solve` counts a solve as solver-feasible.

    Attributes
    ----------
    problem : cvxpy.Problem
        The parametrised problem (maximise ``t``).
    psi : cvxpy.Expression
        The symmetrised ``Psi``.
    n_solves : int
        Solves so far (:meth:`solve` and :meth:`certify`).
    """

    def __init__(self, A, mode_outputs, margin_tol: float = 1e-7):
        self.A = np.atleast_2d(np.asarray(A, dtype=float))
        n = self.A.shape[0]
        self.mode_outputs = [None if C is None else np.atleast_2d(np.asarray(C, dtype=float)) for C in mode_outputs]
        self.margin_tol = margin_tol
        self.sqrt_w = cp.Parameter(len(self.mode_outputs), nonneg=True, name="sqrt_w")
        self.Y = cp.Variable((n, n), symmetric=True, name="Y")
        self.Z = [None if C is None else cp.Variable((n, C.shape[0]), name=f"Z{i}") for i, C in enumerate(self.mode_outputs)]
        self.t = cp.Variable(name="t")
        m = len(self.mode_outputs)
        blocks = []
        cols = []
        for i, C in enumerate(self.mode_outputs):
            YF = self.Y @ self.A if C is None else self.Y @ self.A + self.Z[i] @ C
            cols.append(self.sqrt_w[i] * YF)
        zero = np.zeros((n, n))
        first_row = [self.Y] + [c.T for c in cols]
        blocks.append(first_row)
        for i in range(m):
            row = [cols[i]] + [self.Y if j == i else zero for j in range(m)]
            blocks.append(row)
        psi = cp.bmat(blocks)
        size = n * (m + 1)
        self.psi = 0.5 * (psi + psi.T)
        constraints = [self.psi >> self.t * np.eye(size), self.Y << np.eye(n), self.Y >> 0]
        self.problem = cp.Problem(cp.Maximize(self.t), constraints)
        self.n_solves = 0
        self._certifier = None

    def certifier(self, box=None, dual_routes=("exact", "box")):
        """The :class:`~netrepro.engines.certify.CertifiedLMI` of this LMI: blocks ``Psi > 0`` and ``Y > 0``.

        Built on first use and kept (the same cvxpy problem and parameters), so a sweep compiles
        once. The system is homogeneous in ``(Y, Z_i)``: a ``box`` bounds the coordinates after the
        normalisation ``lambda_min = 1`` (see :func:`~netrepro.engines.certify.check_dual_certificate`).

        Parameters
        ----------
        box : float, dict or None
            Passed to :class:`~netrepro.engines.certify.CertifiedLMI` on first use only.
        dual_routes : tuple of str
            Passed likewise.

        Returns
        -------
        CertifiedLMI
            The certifier.
        """
        if self._certifier is None:
            from .certify import CertifiedLMI

            self._certifier = CertifiedLMI([("Psi", self.psi), ("Y", self.Y)], problem=self.problem, box=box,
                                           dual_routes=dual_routes)
        return self._certifier

    def loss_condition(self, weights):
        """The necessary condition ``w_loss rho(A)^2 < 1``, computed without the LMI.

        ``w_loss`` is the total weight of the modes that deliver nothing (``C_i = None``): the
        operator dominates ``X -> w_loss A X A^T``, so a solution needs ``w_loss rho(A)^2 < 1``
        (Sinopoli et al. 2004; for ``C`` invertible it is also sufficient). Called violated
        only when ``w_loss rho(A)^2 >= 1 + 1e-9`` (the margin covers the eigenvalue error of a
        moderately conditioned ``A``).

        Parameters
        ----------
        weights : array_like
            Mode probabilities.

        Returns
        -------
        tuple (bool, str)
            ``(violated, evidence)``, the form :meth:`CertifiedLMI.certify` takes.
        """
        w_loss = float(sum(w for w, C in zip(np.asarray(weights, dtype=float), self.mode_outputs) if C is None))
        rho = float(np.max(np.abs(np.linalg.eigvals(self.A))))
        value = w_loss * rho ** 2
        return value >= 1.0 + 1e-9, f"w_loss * rho(A)^2 = {value:.12g}"

    def certify(self, weights, necessary=True, box=None):
        """Solve for mode probabilities ``weights`` and return the certified verdict.

        Unlike :meth:`solve` (kept unchanged for the tables that use it), the answer is one of
        ``feasible`` (our eigenvalue check of ``Psi > 0, Y > 0`` at the returned point),
        ``infeasible`` (the loss condition of :meth:`loss_condition` is violated, or a checked
        dual certificate) or ``undecided``; the solver status is information only.

        Parameters
        ----------
        weights : array_like
            Mode probabilities (non-negative, one per mode).
        necessary : bool or callable
            True: use :meth:`loss_condition`; False: none; a callable: ``() -> (violated, evidence)``.
        box : float, dict or None
            Passed to :meth:`certifier` on its first use.

        Returns
        -------
        Verdict
            The certified verdict.

        Raises
        ------
        ValueError
            If ``weights`` has the wrong length or a negative entry.
        """
        weights = np.asarray(weights, dtype=float)
        if weights.shape != (len(self.mode_outputs),) or np.any(weights < 0):
            raise ValueError(f"weights must be {len(self.mode_outputs)} non-negative numbers, got {weights}")
        self.sqrt_w.value = np.sqrt(weights)
        self.n_solves += 1
        if necessary is True:
            nec = (lambda: self.loss_condition(weights))
        else:
            nec = necessary or None
        return self.certifier(box).solve(necessary=nec)

    def solve(self, weights) -> LMIOutcome:
        """Solve for mode probabilities ``weights``; certify any feasible answer independently.

        Parameters
        ----------
        weights : array_like
            Mode probabilities (non-negative, one per mode).

        Returns
        -------
        LMIOutcome
            Status, margin, and the second-moment-radius check of the recovered gains.

        Raises
        ------
        ValueError
            If ``weights`` has the wrong length or a negative entry.
        """
        weights = np.asarray(weights, dtype=float)
        if weights.shape != (len(self.mode_outputs),) or np.any(weights < 0):
            raise ValueError(f"weights must be {len(self.mode_outputs)} non-negative numbers, got {weights}")
        self.sqrt_w.value = np.sqrt(weights)
        self.n_solves += 1
        try:
            solve_problem(self.problem)
            status = str(self.problem.status)
        except cp.error.SolverError as exc:
            return LMIOutcome(f"solver_error: {exc}", np.nan, False, False, np.nan)
        margin = float(self.t.value) if self.t.value is not None else np.nan
        solver_feasible = status == cp.OPTIMAL and margin > self.margin_tol
        if not solver_feasible:
            return LMIOutcome(status, margin, False, False, np.nan)
        Y = self.Y.value
        gains, loops = [], []
        for C, Z in zip(self.mode_outputs, self.Z):
            if C is None:
                gains.append(None)
                loops.append(self.A)
            else:
                K = np.linalg.solve(Y, Z.value)
                gains.append(K)
                loops.append(self.A + K @ C)
        rho = second_moment_radius(loops, weights)
        return LMIOutcome(status, margin, True, rho < 1.0, rho, {"Y": Y, "K": gains})
