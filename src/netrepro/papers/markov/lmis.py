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
    "CANDIDATE_STATUSES", "LMIResult", "GilbertElliottLMI", "certify",
    "rebuild_solve", "thm5_lower_bound", "sinopoli_lmi_threshold", "schur_residual", "lmi_necessary_condition", "as_verdict", "kernel_rate",
]

# statuses whose answer is a *candidate*: it becomes a result only after the independent certificate
CANDIDATE_STATUSES = ("optimal", "optimal_inaccurate")


def _cp():
    from ...engines.cvx import cp

    return cp


def _solve_problem(problem) -> str:
    """Solve through the shared engine (:func:`netrepro.engines.cvx.solve_problem`), imported lazily with cvxpy."""
    from ...engines.cvx import solve_problem as solve

    return solve(problem)


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
    verdict, evidence : str
        The certified verdict (:mod:`netrepro.engines.certify`) and its evidence.
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
    verdict: str = ""  # certified verdict of the engine: feasible / infeasible / undecided
    evidence: str = ""  # what backs the verdict (eigenvalue check, necessary condition, dual certificate)


class GilbertElliottLMI:
    """Theorem 2 (iv): find ``F_i, X > 0, Y > 0`` with (10) ``>= 0`` and ``Psi > 0`` (11).

    .. math::
        (10):\\ \\begin{bmatrix} Y & \\sqrt{1-q}A'Y & \\sqrt{q}A'X \\\\ \\sqrt{1-q}YA & Y & 0 \\\\
                 \\sqrt{q}XA & 0 & X\\end{bmatrix} \\succeq 0, \\qquad
        (11):\\ \\Psi = \\begin{bmatrix} X & \\cdots & \\sqrt{w_i}\\,((A^i)'Y + C^{(i)\\prime}F_i) & \\cdots \\\\
                 \\vdots & & \\ddots \\\\ \\sqrt{w_i}\\,(YA^i + F_i'C^{(i)}) & & Y \\end{bmatrix} \\succ 0

    with ``w_i = p (1-p)^{i-1}``. Derivation (tested on the LMI's own blocks in
    ``tests/papers/markov/test_lmis.py``): the Schur
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
        # (10) >= t I as well as Psi >= t I: the proposed point is then interior to both blocks, so our
        # eigenvalue check can certify it (a point on the boundary of (10) could never be certified)
        cons = [0.5 * (lmi10 + lmi10.T) >> self.t * np.eye(3 * n), 0.5 * (psi + psi.T) >> self.t * np.eye(size),
                Y << np.eye(n)]
        self.problem = cp.Problem(cp.Maximize(self.t), cons)
        # the question asked of the certify engine: (10) >= 0 and Psi > 0 (t dropped); Y <= I is a normalisation
        self.blocks = [("lmi10", cons[0]), ("psi", cons[1])]
        self._certifier = None
        self.n_solves = 0
        self.solve_time = 0.0

    def _set(self, p, q):
        self.s1mq.value = np.sqrt(1.0 - q)
        self.sq.value = np.sqrt(q)
        self.sw.value = np.sqrt(np.array([p * (1.0 - p) ** (i - 1) for i in range(1, self.l_o)]))

    def solve(self, p: float, q: float) -> LMIResult:
        """Solve at ``(p, q)``, certify the answer with the shared engine, recover ``K^{(i)} = Y^{-1} F_i'``
        and check ``rho(H(K)) < 1``.

        The verdict is ``feasible`` (our eigenvalue check of (10) and (11) at the returned point,
        whatever the solver status), ``infeasible`` (:func:`lmi_necessary_condition` violated, or a
        checked dual certificate) or ``undecided``. ``certified`` = feasible and ``rho(H(K)) < 1``.

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
                _solve_problem(self.problem)
            status = str(self.problem.status)
        except cp.error.SolverError as exc:
            status = f"solver_error: {exc}"
        self.solve_time += time.perf_counter() - start
        self.n_solves += 1
        verdict = self.certifier.certify(status, necessary=lambda: lmi_necessary_condition(self.A, self.C, p, q))
        return certify(self.A, self.C, p, q, status, self.t.value, self.X.value, self.Y.value,
                       [F.value for F in self.F], self.margin_tol, verdict)

    @property
    def certifier(self):
        """The :class:`~netrepro.engines.certify.CertifiedLMI` of (10) ``>= 0``, ``Psi > 0`` (built once).

        Returns
        -------
        netrepro.engines.certify.CertifiedLMI
        """
        if self._certifier is None:
            from ...engines.certify import CertifiedLMI

            self._certifier = CertifiedLMI(self.blocks, problem=self.problem, drop=[self.t])
        return self._certifier


def certify(A, C, p, q, status, t, X, Y, F, margin_tol, verdict=None) -> LMIResult:
    """Independent checks of an answer: the engine's verdict, ``rho(H(K)) < 1`` (eq. 7) and ``X - L_K(X) > 0`` (Thm 2 (iii)).

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
        Smallest margin counted as solver-feasible (``solver_feasible``, information only when
        ``verdict`` is given).
    verdict : netrepro.engines.certify.Verdict or None
        The engine's certified verdict. ``None`` (benchmark only): the legacy rule, solver status
        and margin, then ``rho(H(K)) < 1``.

    Returns
    -------
    LMIResult
    """
    margin = float(t) if t is not None else np.nan
    solver_feasible = status in CANDIDATE_STATUSES and margin > margin_tol
    v, ev = (verdict.verdict, verdict.evidence) if verdict is not None else ("", "legacy rule (not certified)")
    usable = Y is not None and X is not None and all(f is not None for f in F)
    if verdict is None and not solver_feasible:
        usable = False
    if not usable:
        return LMIResult(p, q, status, margin, solver_feasible, False, np.nan, np.nan, [], v, ev)
    try:
        K = [np.linalg.solve(Y, f.T) for f in F]
    except np.linalg.LinAlgError:
        return LMIResult(p, q, status, margin, solver_feasible, False, np.nan, np.nan, [], v, ev)
    rho = h_radius(A, C, K, p, q)
    lyap = float(np.min(np.linalg.eigvalsh(X - L_operator(A, C, K, p, q, X))))
    ok = bool(rho < 1.0) and (verdict.feasible if verdict is not None else solver_feasible)
    return LMIResult(p, q, status, margin, solver_feasible, ok, rho, lyap, K, v, ev)


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
    prob = cp.Problem(cp.Maximize(t), [0.5 * (lmi10 + lmi10.T) >> t * np.eye(3 * n),
                                       0.5 * (psi + psi.T) >> t * np.eye(n * (r + 1)), Y << np.eye(n)])
    try:
        _solve_problem(prob)
        status = str(prob.status)
    except cp.error.SolverError as exc:
        status = f"solver_error: {exc}"
    return certify(A, C, p, q, status, t.value, X.value, Y.value, [f.value for f in F], margin_tol)


def thm5_lower_bound(lmi: GilbertElliottLMI, q: float, p_max: float, tol: float, p_min: float = 1e-6):
    """Theorem 5, eq. (12): ``p_underline(q) = sup{p : exists (K, P), L_K(P) < P, P > 0}`` by bisection.

    Certified bisection (:func:`netrepro.engines.certify.bisect_certified`): a point is feasible when the
    engine's eigenvalue check passes *and* ``rho(H(K)) < 1``; infeasible when
    :func:`lmi_necessary_condition` is violated or a dual certificate is checked; both bracket ends are
    certified (``certified``), undecided points are never an end.
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
    dict with ``p_lower`` (certified-feasible end), ``p_upper`` (certified-infeasible end, nan if none),
    ``certified`` (both ends), ``saturated`` (feasible at ``p_max``), ``n_solves``, ``n_undecided``,
    ``n_uncertified`` (engine-feasible but ``rho(H(K)) >= 1``: must be 0), ``statuses`` (solver statuses
    seen, information only), ``rho_at_lower``, ``lower_evidence``, ``upper_evidence``.
    """
    from ...engines.certify import bisect_certified

    results = {}

    def decide(p):
        res = lmi.solve(p, q)
        results[p] = res
        return as_verdict(res)

    # the kernel bound p < 1 / c(q) is only a starting guess (it changes the number of solves, not the answer)
    lam = float(np.max(np.abs(np.linalg.eigvals(lmi.A))))
    c = kernel_rate(lmi.A, lmi.C, q) if lam ** 2 * (1 - q) < 1 else np.nan
    guess = 1.0 / c if np.isfinite(c) and p_min < 1.0 / c < p_max else None
    br = bisect_certified(decide, p_min, p_max, tol=tol, max_evals=200, feasible_above=False, guess=guess,
                          width=4 * tol if guess is not None else 0.0)
    feas = [r for r in results.values() if r.certified]
    best = max(feas, key=lambda r: r.p) if feas else None
    saturated = bool(np.isnan(br.infeasible_end) and br.feasible_end == p_max)
    p_lower = br.feasible_end if np.isfinite(br.feasible_end) else 0.0
    lower_res, upper_res = results.get(br.feasible_end), results.get(br.infeasible_end)
    return {
        "p_lower": p_lower, "p_upper": br.infeasible_end, "saturated": saturated, "n_solves": br.n_evals,
        "certified": bool(br.certified), "n_undecided": len(br.undecided),
        "n_uncertified": sum(r.verdict == "feasible" and not r.certified for r in results.values()),
        "statuses": sorted({r.status for r in results.values()}),
        "rho_at_lower": best.rho_H if best is not None else np.nan,
        "lower_evidence": lower_res.evidence if lower_res is not None else "",
        "upper_evidence": upper_res.evidence if upper_res is not None else "",
    }


def as_verdict(res: LMIResult):
    """The engine verdict of a solve, with ``feasible`` kept only when ``rho(H(K)) < 1`` also holds.

    Parameters
    ----------
    res : LMIResult
        One solve of :class:`GilbertElliottLMI`.

    Returns
    -------
    netrepro.engines.certify.Verdict
        ``feasible`` (eigenvalue check and ``rho(H(K)) < 1``), ``infeasible`` or ``undecided``.
    """
    from ...engines.certify import UNDECIDED, Verdict

    if res.verdict == "feasible" and not res.certified:
        return Verdict(UNDECIDED, res.status, f"eigenvalue check passed but rho(H(K)) = {res.rho_H:.6g} >= 1")
    return Verdict(res.verdict or UNDECIDED, res.status, res.evidence)


def lmi_necessary_condition(A, C, p, q, margin: float = 1e-9):
    """Necessary conditions for the LMI (10)-(11), computed without it: ``(violated, evidence)``.

    1. (10) with ``X, Y > 0`` gives ``Y - (1-q) A'YA >= q A'XA > 0``, so ``sqrt(1-q) A`` is Schur:
       ``|lambda_A|^2 (1-q) < 1``.
    2. Theorem 2: a feasible LMI gives a ``K`` with ``rho(H(K)) < 1`` (eq. 7). For ``v != 0`` with
       ``C v = 0`` the forward map of ``H(K)`` sends ``v v'`` to ``p S_1`` with
       ``S_1 = q sum_j (1-q)^{j-1} A^j (A v)(A v)' (A^j)'`` *for every* ``K`` (``(A + K C) v = A v``),
       and ``S_1 >= c v v'`` with ``c = 1 / (v' S_1^+ v)`` when ``v`` is in the range of ``S_1``. A
       positive map with ``T(X) >= r X``, ``X >= 0``, ``X != 0`` has ``rho(T) >= r`` (Collatz-Wielandt),
       so ``p c >= 1`` makes every ``rho(H(K)) >= 1``: ``p min_K rho(H(K)) >= 1``, the LMI is infeasible.
       For Example II this is the parity bound (``p c = pq|lambda|^4 / (1 - (|lambda|^2 (1-q))^2)``).

    Parameters
    ----------
    A, C : array_like
        System and output matrices (``l_o = 2``: one gain).
    p, q : float
        Failure and recovery rates.
    margin : float
        Violated only when the bound exceeds ``1 + margin`` (rounding of the Stein solution, ~1e-12).

    Returns
    -------
    (bool, str)
        Whether a necessary condition is violated, and the numbers.
    """
    A, C = np.atleast_2d(np.asarray(A, float)), np.atleast_2d(np.asarray(C, float))
    lam = float(np.max(np.abs(np.linalg.eigvals(A))))
    loss = lam ** 2 * (1.0 - q)
    if loss >= 1.0 + margin:
        return True, f"|lambda_A|^2 (1-q) = {loss:.12g} >= 1"
    if loss >= 1.0 - 1e-6:
        return False, f"|lambda_A|^2 (1-q) = {loss:.12g} (too close to 1 to use the kernel bound)"
    c = kernel_rate(A, C, q)
    if not np.isfinite(c):
        return False, "no kernel bound (C has a trivial kernel, or its vector is outside the range of S_1)"
    bound = p * c
    return bool(bound >= 1.0 + margin), f"p min_K rho(H(K)) >= {bound:.12g} (kernel/Collatz-Wielandt bound)"


def kernel_rate(A, C, q):
    """``c(q)`` with ``rho(H(K)) >= p c(q)`` for every ``K`` (see :func:`lmi_necessary_condition`), or ``nan``.

    Parameters
    ----------
    A, C : array_like
        System and output matrices.
    q : float
        Recovery rate with ``|lambda_A|^2 (1-q) < 1``.

    Returns
    -------
    float
        ``c = 1 / (v' S_1^+ v)`` for the kernel vector ``v`` of ``C``; ``1 / c`` is an upper bound on
        Theorem 5's ``p_underline(q)`` (equal to it for both examples).
    """
    from scipy.linalg import solve_discrete_lyapunov

    A, C = np.atleast_2d(np.asarray(A, float)), np.atleast_2d(np.asarray(C, float))
    _, s, vt = np.linalg.svd(C)
    if C.shape[0] >= A.shape[0] and s.min() > 1e-12 * s.max():
        return np.nan
    v = vt[-1]
    Av = A @ v
    Z = solve_discrete_lyapunov(np.sqrt(1.0 - q) * A, np.outer(Av, Av))  # sum_m (1-q)^m A^m Av Av' A^m'
    S1 = q * A @ Z @ A.T
    S1 = 0.5 * (S1 + S1.T)
    w, U = np.linalg.eigh(S1)
    keep = w > 1e-12 * w.max()
    coef = U[:, keep].T @ v
    if np.linalg.norm(v - U[:, keep] @ coef) > 1e-9:
        return np.nan
    return 1.0 / float(np.sum(coef ** 2 / w[keep]))


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
    (float, int, CertifiedBracket)
        The certified-feasible end (the upper bound on ``lambda_c``), the number of LMI solves and
        the bracket (both ends certified when ``certified``).
    """
    from ...engines.lmi import MareStabilizabilityLMI

    from ...engines.certify import bisect_certified

    lmi = MareStabilizabilityLMI(A, [None, C])
    br = bisect_certified(lambda lam: lmi.certify([1 - lam, lam]), 1e-6, 1.0, tol=tol, feasible_above=True)
    return br.feasible_end, lmi.n_solves, br


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

