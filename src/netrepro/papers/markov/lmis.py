"""The LMI of Theorem 2 (iv), eqs. (10)-(11), Theorem 5's bisection (eq. 12) and the i.i.d.
LMI bound of Sinopoli et al. (Remark 4), every feasible answer certified by ``rho(H(K)) < 1`` (eq. 7).

cvxpy (and the shared LMI engine, which imports it) are imported lazily: the simulation
steps do not need them, and importing cvxpy costs seconds per pipeline job.
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass, field

import numpy as np

from ...errors import InputError
from .model import L_operator, h_radius, observability_index, stacked_output

__all__ = [
    "SOLVER", "CANDIDATE_STATUSES", "bisect_monotone", "LMIResult", "GilbertElliottLMI", "certify",
    "rebuild_solve", "thm5_lower_bound", "sinopoli_lmi_threshold", "schur_residual",
]

SOLVER = "CLARABEL"
# statuses whose answer is a *candidate*: it becomes a result only after the independent certificate
CANDIDATE_STATUSES = ("optimal", "optimal_inaccurate")


def _cp():
    import cvxpy

    return cvxpy


def bisect_monotone(*args, **kwargs):
    """:func:`netrepro.engines.lmi.bisect_monotone` (imported lazily).

    Parameters
    ----------
    *args, **kwargs
        As :func:`netrepro.engines.lmi.bisect_monotone`.

    Returns
    -------
    The engine's bisection result (``threshold``, ``lower``, ``bracketed``, ``n_evals``).
    """
    from ...engines.lmi import bisect_monotone as _bisect

    return _bisect(*args, **kwargs)


# ----------------------------------------------------------------------------- Theorem 2 LMI (10)-(11)
@dataclass
class LMIResult:
    """One solve of (10)-(11): solver status, margin, and the independent certificate.

    Parameters
    ----------
    p, q : float
        The point solved.
    status : str
        Solver status (information only).
    margin : float
        The solver's ``t`` (``Psi >= t I``).
    solver_feasible : bool
        Candidate status and ``margin > margin_tol``.
    certified : bool
        ``rho(H(K)) < 1`` (eq. 7) for the recovered gain.
    rho_H, lyap_margin : float
        The certificate's spectral radius and ``min eig(X - L_K(X))``.
    K : list of arrays
        Recovered gains ``K^{(i)}``.
    """

    p: float
    q: float
    status: str
    margin: float
    solver_feasible: bool
    certified: bool
    rho_H: float  # spectral radius of H(K) of eq. (7) for the recovered K (nan if none)
    lyap_margin: float  # min eig of X - L_K(X) (Theorem 2 (iii)) for the solver's X
    K: list = field(default_factory=list)


class GilbertElliottLMI:
    """Theorem 2 (iv): find ``F_i, X > 0, Y > 0`` with (10) ``>= 0`` and ``Psi > 0`` (11).

    .. math::
        (10):\\ \\begin{bmatrix} Y & \\sqrt{1-q}A'Y & \\sqrt{q}A'X \\\\ \\sqrt{1-q}YA & Y & 0 \\\\
                 \\sqrt{q}XA & 0 & X\\end{bmatrix} \\succeq 0, \\qquad
        (11):\\ \\Psi = \\begin{bmatrix} X & \\cdots & \\sqrt{w_i}\\,((A^i)'Y + C^{(i)\\prime}F_i) & \\cdots \\\\
                 \\vdots & & \\ddots \\\\ \\sqrt{w_i}\\,(YA^i + F_i'C^{(i)}) & & Y \\end{bmatrix} \\succ 0

    with ``w_i = p (1-p)^{i-1}``. Derivation (tested in ``tests/test_markov.py``): the Schur
    complement of (10) is ``Y - (1-q)A'YA - qA'XA >= 0``, hence ``Y >= Phi_X``; the Schur
    complement of (11) is ``X - sum_i w_i M_i' Y M_i`` with ``M_i = A^i + K^{(i)} C^{(i)}``,
    ``K^{(i)} = Y^{-1} F_i'``; so ``X > L_K(X)`` (Theorem 2 (iii)).

    The LMI is homogeneous; we maximise ``t`` with ``Psi >= t I`` and ``Y <= I``. The scalars
    ``sqrt(1-q), sqrt(q), sqrt(w_i)`` are :class:`cvxpy.Parameter` objects (DPP): one compile
    per system, every further solve only updates values. Every solver-feasible answer is
    certified independently by ``rho(H(K)) < 1`` (eq. 7).

    Parameters
    ----------
    A, C : array_like
        System and output matrices.
    l_o : int, optional
        Observability index (computed if omitted).
    margin_tol : float
        Smallest margin ``t`` counted as strictly feasible by the solver.

    Raises
    ------
    InputError
        If ``l_o = 1`` (the sum in eq. 9 is empty).
    """

    def __init__(self, A, C, l_o: int | None = None, margin_tol: float = 1e-7):
        cp = _cp()
        self.A = np.atleast_2d(np.asarray(A, dtype=float))
        self.C = np.atleast_2d(np.asarray(C, dtype=float))
        n, m = self.A.shape[0], self.C.shape[0]
        self.l_o = observability_index(self.A, self.C) if l_o is None else int(l_o)
        if self.l_o < 2:
            raise InputError("one-step observable system: the sum in (9) is empty (l_o = 1)")
        self.margin_tol = margin_tol
        r = self.l_o - 1
        self.s1mq = cp.Parameter(nonneg=True, name="sqrt_1mq")
        self.sq = cp.Parameter(nonneg=True, name="sqrt_q")
        self.sw = cp.Parameter(r, nonneg=True, name="sqrt_w")
        self.X = cp.Variable((n, n), symmetric=True, name="X")
        self.Y = cp.Variable((n, n), symmetric=True, name="Y")
        self.F = [cp.Variable((m * i, n), name=f"F{i}") for i in range(1, r + 1)]
        self.t = cp.Variable(name="t")
        A, X, Y = self.A, self.X, self.Y
        Z = np.zeros((n, n))
        lmi10 = cp.bmat([
            [Y, self.s1mq * (A.T @ Y), self.sq * (A.T @ X)],
            [self.s1mq * (Y @ A), Y, Z],
            [self.sq * (X @ A), Z, X],
        ])
        cols = []
        for i in range(1, r + 1):
            Ai = np.linalg.matrix_power(A, i)
            Ci = stacked_output(A, self.C, i)
            cols.append(self.sw[i - 1] * (Y @ Ai + self.F[i - 1].T @ Ci))
        psi = cp.bmat([[X] + [c.T for c in cols]] + [[cols[i]] + [Y if j == i else Z for j in range(r)]
                                                     for i in range(r)])
        size = n * (r + 1)
        cons = [0.5 * (lmi10 + lmi10.T) >> 0, 0.5 * (psi + psi.T) >> self.t * np.eye(size), Y << np.eye(n)]
        self.problem = cp.Problem(cp.Maximize(self.t), cons)
        self.n_solves = 0
        self.solve_time = 0.0

    def _set(self, p, q):
        self.s1mq.value = np.sqrt(1.0 - q)
        self.sq.value = np.sqrt(q)
        self.sw.value = np.sqrt(np.array([p * (1.0 - p) ** (i - 1) for i in range(1, self.l_o)]))

    def solve(self, p: float, q: float) -> LMIResult:
        """Solve at ``(p, q)``; recover ``K^{(i)} = Y^{-1} F_i'`` and certify ``rho(H(K)) < 1``.

        Parameters
        ----------
        p, q : float
            Failure and recovery rates.

        Returns
        -------
        LMIResult

        Raises
        ------
        InputError
            If ``(p, q)`` is out of range.
        """
        if not (0 < q <= 1) or p < 0 or (self.l_o > 2 and p > 1):
            raise InputError(f"need 0 < q <= 1 and 0 <= p (<= 1 when l_o > 2), got p={p}, q={q}")
        cp = _cp()
        self._set(p, q)
        start = time.perf_counter()
        try:
            with warnings.catch_warnings():  # "optimal_inaccurate" is kept as a status, not printed
                warnings.simplefilter("ignore", UserWarning)
                self.problem.solve(solver=SOLVER)
            status = str(self.problem.status)
        except cp.error.SolverError as exc:
            status = f"solver_error: {exc}"
        self.solve_time += time.perf_counter() - start
        self.n_solves += 1
        return certify(self.A, self.C, p, q, status, self.t.value, self.X.value, self.Y.value,
                       [F.value for F in self.F], self.margin_tol)


def certify(A, C, p, q, status, t, X, Y, F, margin_tol) -> LMIResult:
    """Independent check of a solver answer: ``rho(H(K)) < 1`` (eq. 7) and ``X - L_K(X) > 0`` (Thm 2 (iii)).

    Parameters
    ----------
    A, C : ndarray
        System and output matrices.
    p, q : float
        Failure and recovery rates.
    status : str
        Solver status.
    t : float or None
        Solver margin.
    X, Y : ndarray or None
        Solver variables.
    F : list of ndarray or None
        Solver variables ``F_i``.
    margin_tol : float
        Smallest margin counted as solver-feasible.

    Returns
    -------
    LMIResult
    """
    margin = float(t) if t is not None else np.nan
    feasible = status in CANDIDATE_STATUSES and margin > margin_tol
    if not feasible or Y is None or any(f is None for f in F):
        return LMIResult(p, q, status, margin, False, False, np.nan, np.nan)
    K = [np.linalg.solve(Y, f.T) for f in F]
    rho = h_radius(A, C, K, p, q)
    lyap = float(np.min(np.linalg.eigvalsh(X - L_operator(A, C, K, p, q, X))))
    return LMIResult(p, q, status, margin, True, bool(rho < 1.0), rho, lyap, K)


def rebuild_solve(A, C, p, q, l_o=None, margin_tol=1e-7) -> LMIResult:
    """The same LMI (10)-(11) built from scratch with constants (benchmark baseline: no cvxpy Parameters).

    Parameters
    ----------
    A, C : array_like
        System and output matrices.
    p, q : float
        Failure and recovery rates.
    l_o : int, optional
        Observability index (computed if omitted).
    margin_tol : float
        Smallest margin counted as solver-feasible.

    Returns
    -------
    LMIResult
    """
    cp = _cp()
    A = np.atleast_2d(np.asarray(A, dtype=float))
    C = np.atleast_2d(np.asarray(C, dtype=float))
    n, m = A.shape[0], C.shape[0]
    l_o = observability_index(A, C) if l_o is None else l_o
    r = l_o - 1
    X = cp.Variable((n, n), symmetric=True)
    Y = cp.Variable((n, n), symmetric=True)
    F = [cp.Variable((m * i, n)) for i in range(1, r + 1)]
    t = cp.Variable()
    Z = np.zeros((n, n))
    lmi10 = cp.bmat([[Y, np.sqrt(1 - q) * (A.T @ Y), np.sqrt(q) * (A.T @ X)],
                     [np.sqrt(1 - q) * (Y @ A), Y, Z], [np.sqrt(q) * (X @ A), Z, X]])
    cols = [np.sqrt(p * (1 - p) ** (i - 1)) * (Y @ np.linalg.matrix_power(A, i) + F[i - 1].T @ stacked_output(A, C, i))
            for i in range(1, r + 1)]
    psi = cp.bmat([[X] + [c.T for c in cols]] + [[cols[i]] + [Y if j == i else Z for j in range(r)]
                                                 for i in range(r)])
    prob = cp.Problem(cp.Maximize(t), [0.5 * (lmi10 + lmi10.T) >> 0,
                                       0.5 * (psi + psi.T) >> t * np.eye(n * (r + 1)), Y << np.eye(n)])
    try:
        prob.solve(solver=SOLVER)
        status = str(prob.status)
    except cp.error.SolverError as exc:
        status = f"solver_error: {exc}"
    return certify(A, C, p, q, status, t.value, X.value, Y.value, [f.value for f in F], margin_tol)


def thm5_lower_bound(lmi: GilbertElliottLMI, q: float, p_max: float, tol: float, p_min: float = 1e-6):
    """Theorem 5, eq. (12): ``p_underline(q) = sup{p : exists (K, P), L_K(P) < P, P > 0}`` by bisection.

    A point counts as feasible only when the solver says so *and* ``rho(H(K)) < 1`` is certified.
    For ``l_o = 2`` the LMI depends on ``p`` only through ``sqrt(p)`` and feasibility is monotone
    in ``p`` (``L_K`` is ``p`` times a fixed operator), so bisection is exact up to ``tol``.

    Parameters
    ----------
    lmi : GilbertElliottLMI
        The compiled LMI of the system.
    q : float
        Recovery rate.
    p_max : float
        Upper end of the search.
    tol : float
        Bisection tolerance.
    p_min : float
        Lower end of the search.

    Returns
    -------
    dict with ``p_lower`` (largest certified-feasible p found), ``p_upper`` (smallest infeasible),
    ``saturated`` (feasible at ``p_max``), ``n_solves``, ``n_uncertified`` (solver-feasible but not
    certified), ``statuses`` (set of solver statuses seen), ``rho_at_lower``.
    """
    results = {}

    def infeasible(p):
        res = lmi.solve(p, q)
        results[p] = res
        return not res.certified

    out = bisect_monotone(infeasible, p_min, p_max, tol=tol, max_evals=200)
    feas = [r for r in results.values() if r.certified]
    best = max(feas, key=lambda r: r.p) if feas else None
    if np.isnan(out.threshold):  # infeasible never found: feasible up to p_max
        p_lower, p_upper, saturated = p_max, np.nan, True
    elif not out.bracketed:  # infeasible at p_min
        p_lower, p_upper, saturated = 0.0, p_min, False
    else:
        p_lower, p_upper, saturated = out.lower, out.threshold, False
    return {
        "p_lower": p_lower, "p_upper": p_upper, "saturated": saturated, "n_solves": out.n_evals,
        "n_uncertified": sum(r.solver_feasible and not r.certified for r in results.values()),
        "statuses": sorted({r.status for r in results.values()}),
        "rho_at_lower": best.rho_H if best is not None else np.nan,
    }


def sinopoli_lmi_threshold(A, C, tol: float = 1e-5):
    """Sinopoli et al. (2004, Thm 5) LMI upper bound on the critical arrival rate ``lambda_c`` (i.i.d. losses).

    Smallest ``lambda`` with a certified-feasible ``Y > (1-lambda) A'YA + lambda (A+KC)'Y(A+KC)`` (shared
    :class:`~netrepro.engines.lmi.MareStabilizabilityLMI`, certified by the second-moment radius).

    Parameters
    ----------
    A, C : array_like
        System and output matrices.
    tol : float
        Bisection tolerance.

    Returns
    -------
    (float, int)
        The threshold and the number of LMI solves.
    """
    from ...engines.lmi import MareStabilizabilityLMI

    lmi = MareStabilizabilityLMI(A, [None, C])
    res = bisect_monotone(lambda lam: lmi.solve([1 - lam, lam]).certified, 1e-6, 1.0, tol=tol)
    return res.threshold, lmi.n_solves


def schur_residual(A, C, p, q, rng):
    """max |Schur complement of Psi (11) - (X - sum_i w_i M_i' Y M_i)| on random data, with C^{(i)} = [C; ...; CA^{i-1}].

    Parameters
    ----------
    A, C : ndarray
        System and output matrices.
    p, q : float
        Failure and recovery rates.
    rng : numpy.random.Generator
        Source of the random ``Y`` and ``F_i``.

    Returns
    -------
    float
        Largest absolute entry of the difference (zero up to rounding).
    """
    n, m = A.shape[0], C.shape[0]
    l_o = observability_index(A, C)
    X = np.eye(n) * 50.0
    G = rng.standard_normal((n, n))
    Y = G @ G.T + np.eye(n)
    F = [rng.standard_normal((m * i, n)) for i in range(1, l_o)]
    cols = [np.sqrt(p * (1 - p) ** (i - 1)) * (Y @ np.linalg.matrix_power(A, i) + F[i - 1].T @ stacked_output(A, C, i))
            for i in range(1, l_o)]
    schur = X - sum(c.T @ np.linalg.solve(Y, c) for c in cols)
    K = [np.linalg.solve(Y, f.T) for f in F]
    direct = X - sum(p * (1 - p) ** (i - 1) * M.T @ Y @ M for i, M in
                     ((i, np.linalg.matrix_power(A, i) + K[i - 1] @ stacked_output(A, C, i)) for i in range(1, l_o)))
    return float(np.max(np.abs(schur - direct)))

