"""Mathematics of the `markov` paper (Wu, Shi, Anderson, Johansson): Kalman filtering over
Gilbert-Elliott channels.

Channel convention (eq. 3): ``gamma_k`` is the state of a two-state Markov chain,
``p = P(gamma_{k+1}=0 | gamma_k=1)`` (failure rate), ``q = P(gamma_{k+1}=1 | gamma_k=0)``
(recovery rate), and ``gamma_1 = 1``. ``P_k`` is the prediction covariance ``P_{k|k-1}``;
``P_{k+1} = g(P_k)`` when ``gamma_k = 1`` and ``h(P_k)`` otherwise (eqs. 4-5).

Contents

* :func:`observability_index` (Definition 2), :func:`stacked_output` (``C^{(i)}``, undefined in
  the paper; we read it as the i-step observability matrix ``[C; CA; ...; CA^{i-1}]``).
* :func:`prop1_bound` (eq. 8), :func:`H_matrix` and :func:`h_radius` (eq. 7, Theorem 1),
  :func:`L_operator` (eq. 9), :func:`phi_lyapunov` (the Lyapunov equation below eq. 9).
* :class:`GilbertElliottLMI`: the LMI (10)-(11) of Theorem 2 (iv) with cvxpy Parameters
  (compiled once per system), every feasible answer certified by ``rho(H(K)) < 1``.
* :func:`thm5_lower_bound`: Theorem 5's ``p_underline(q)`` (eq. 12) by bisection.
* :func:`exact_moments`: exact ``E||P_k||`` and ``E tr P_k`` over *all* channel paths, as
  polynomials in ``(p, 1-p, q, 1-q)`` (binary tree, aggregated by transition counts).
* :func:`rb_mean_norm`: the conditional (Rao-Blackwellised) Monte Carlo estimator that
  integrates the trailing loss run exactly.
* :func:`sinopoli_lmi_threshold`: the i.i.d. LMI upper bound on lambda_c (Sinopoli et al.).
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass, field

import numpy as np

from ..engines.channels import gilbert_elliott_arrivals, gilbert_elliott_stationary
from ..engines.riccati import Sensor, covariance_paths

# cvxpy (and the shared LMI engine, which imports it) are imported lazily: the simulation
# steps do not need them, and importing cvxpy costs seconds per pipeline job.
SOLVER = "CLARABEL"
# statuses whose answer is a *candidate*: it becomes a result only after the independent certificate
CANDIDATE_STATUSES = ("optimal", "optimal_inaccurate")


def _cp():
    import cvxpy

    return cvxpy


def bisect_monotone(*args, **kwargs):
    """:func:`netrepro.engines.lmi.bisect_monotone` (imported lazily)."""
    from ..engines.lmi import bisect_monotone as _bisect

    return _bisect(*args, **kwargs)

__all__ = [
    "LinearSystem", "observability_index", "stacked_output", "spectral_abs", "prop1_bound", "loss_factor",
    "H_matrix", "h_radius", "phi_lyapunov", "L_operator", "GilbertElliottLMI", "LMIResult", "thm5_lower_bound",
    "rebuild_solve", "riccati_g", "riccati_h", "covariance_paths_ge", "exact_moments", "ExactMoments", "rb_mean_norm", "rb_mean_trace", "rb_trace_grid", "plain_mc",
    "sym_norm", "sinopoli_lmi_threshold", "gilbert_elliott_stationary_loss", "parity_bound_example2", "norm_relaxation_bound",
]


# ----------------------------------------------------------------------------- system
@dataclass(frozen=True)
class LinearSystem:
    """``x_{k+1} = A x_k + w_k``, ``y_k = C x_k + v_k`` (eqs. 1-2) with ``Q = cov w``, ``R = cov v``."""

    A: np.ndarray
    C: np.ndarray
    Q: np.ndarray
    R: np.ndarray

    def __post_init__(self):
        for name in ("A", "C", "Q", "R"):
            object.__setattr__(self, name, np.atleast_2d(np.asarray(getattr(self, name), dtype=float)))
        n, m = self.A.shape[0], self.C.shape[0]
        if self.A.shape != (n, n) or self.C.shape[1] != n or self.Q.shape != (n, n) or self.R.shape != (m, m):
            raise ValueError(f"inconsistent shapes A{self.A.shape} C{self.C.shape} Q{self.Q.shape} R{self.R.shape}")

    @property
    def n(self):
        return self.A.shape[0]

    @classmethod
    def from_config(cls, cfg: dict) -> "LinearSystem":
        return cls(cfg["A"], cfg["C"], cfg["Q"], cfg["R"])


def spectral_abs(A) -> float:
    """``|lambda_A|``: the largest eigenvalue magnitude of ``A`` (paper's notation)."""
    return float(np.max(np.abs(np.linalg.eigvals(np.atleast_2d(A)))))


def observability_index(A, C) -> int:
    """Observability index ``l_o`` (Definition 2).

    The smallest ``l`` with ``rank [C; CA; ...; CA^{l-1}] = n``.

    Raises
    ------
    ValueError
        If ``(C, A)`` is not observable.
    """
    A, C = np.atleast_2d(A), np.atleast_2d(C)
    n = A.shape[0]
    for ell in range(1, n + 1):
        if np.linalg.matrix_rank(stacked_output(A, C, ell)) == n:
            return ell
    raise ValueError("(C, A) is not observable")


def stacked_output(A, C, i: int) -> np.ndarray:
    """``C^{(i)} = [C; CA; ...; CA^{i-1}]`` (``m i x n``), our reading of the undefined ``C^{(i)}`` in eqs. 7, 9, 11.

    With ``i`` consecutive receptions starting at a peak time, a (sub-optimal) linear
    estimator gives the error map ``A^i + K^{(i)} C^{(i)}`` for any gain ``K^{(i)}``.
    """
    A, C = np.atleast_2d(A), np.atleast_2d(C)
    return np.vstack([C @ np.linalg.matrix_power(A, j) for j in range(i)])


# ----------------------------------------------------------------------------- Prop 1, eq (7), eq (9)
def prop1_bound(lam_abs: float, q, l_o: int, p_max: float = 1.0, tol: float = 1e-12):
    """Largest ``p`` satisfying Proposition 1, eq. (8).

    .. math:: p q |\\lambda_A|^2 \\sum_{i=1}^{l_o-1} |\\lambda_A|^{2i} (1-p)^{i-1} < 1 - |\\lambda_A|^2 (1-q)

    For ``l_o = 2`` this is ``p < (1 - |lambda|^2 (1-q)) / (|lambda|^4 q)`` (Section 5.1); the
    value may exceed 1 (returned uncapped). For ``l_o > 2`` the left side is solved by bisection
    on ``[0, p_max]``. Vectorised over ``q``; ``nan`` where ``|lambda|^2 (1-q) >= 1``.
    """
    q = np.asarray(q, dtype=float)
    l2 = lam_abs ** 2
    rhs = 1.0 - l2 * (1.0 - q)
    out = np.full(q.shape, np.nan)
    ok = rhs > 0
    if l_o < 2:
        out[ok] = np.inf  # one-step observable: no constraint on p
        return out
    if l_o == 2:
        out[ok] = rhs[ok] / (l2 * l2 * q[ok])
        return out

    def lhs(p, qq):
        return p * qq * l2 * sum(l2 ** i * (1 - p) ** (i - 1) for i in range(1, l_o))

    lo, hi = np.zeros(q.shape), np.full(q.shape, p_max)
    while np.max(hi - lo) > tol:
        mid = 0.5 * (lo + hi)
        bad = lhs(mid, q) >= rhs
        hi = np.where(bad, mid, hi)
        lo = np.where(bad, lo, mid)
    out[ok] = lo[ok]
    return out


def loss_factor(A, q) -> np.ndarray:
    """``q [(A (x) A)^{-1} - (1-q) I]^{-1} = sum_{j>=1} q (1-q)^{j-1} (A (x) A)^j`` (first factor of eq. 7)."""
    A = np.atleast_2d(A)
    AA = np.kron(A, A)
    return q * np.linalg.inv(np.linalg.inv(AA) - (1.0 - q) * np.eye(AA.shape[0]))


def H_matrix(A, C, K, p, q) -> np.ndarray:
    """``H(K)`` of Theorem 1, eq. (7).

    .. math::
        H(K) = qp[(A\\otimes A)^{-1} - (1-q)I]^{-1} \\sum_{i=1}^{l_o-1}
               \\overline{(A^i + K^{(i)}C^{(i)})} \\otimes (A^i + K^{(i)}C^{(i)}) (1-p)^{i-1}

    Parameters
    ----------
    K : list of arrays
        ``K[i-1]`` is ``K^{(i)}`` of shape ``(n, m i)``, ``i = 1 .. l_o - 1``.
    """
    A = np.atleast_2d(A)
    total = np.zeros((A.shape[0] ** 2,) * 2, dtype=complex)
    for i, Ki in enumerate(K, start=1):
        M = np.linalg.matrix_power(A, i) + np.asarray(Ki) @ stacked_output(A, C, i)
        total = total + (1.0 - p) ** (i - 1) * np.kron(np.conj(M), M)
    return p * loss_factor(A, q) @ total


def h_radius(A, C, K, p, q) -> float:
    """Spectral radius ``|lambda_{H(K)}|`` of eq. (7): the independent certificate of Theorems 1-2."""
    return float(np.max(np.abs(np.linalg.eigvals(H_matrix(A, C, K, p, q)))))


def phi_lyapunov(A, X, q) -> np.ndarray:
    """``Phi_X``: solution of ``(1-q) A' Phi A + q A' X A = Phi`` (below eq. 9), needs ``|lambda_A|^2 (1-q) < 1``."""
    A = np.atleast_2d(A)
    n = A.shape[0]
    rhs = q * A.T @ X @ A
    # vec(A' Phi A) = (A' (x) A') vec(Phi) with row-major vec of a matrix (symmetric case: either works)
    op = np.eye(n * n) - (1.0 - q) * np.kron(A.T, A.T)
    return np.linalg.solve(op, rhs.reshape(-1)).reshape(n, n)


def L_operator(A, C, K, p, q, X) -> np.ndarray:
    """The operator ``L_K`` of eq. (9).

    .. math:: \\mathcal{L}_K(X) = p \\sum_{i=1}^{l_o-1} (1-p)^{i-1} (A^i + K^{(i)}C^{(i)})^* \\Phi_X (A^i + K^{(i)}C^{(i)})

    It is the adjoint of ``vec^{-1} H(K) vec`` (eq. 7) under ``<X, P> = tr(XP)``, so the two share
    their spectral radius (Theorem 2, (i) <=> (ii)).
    """
    A = np.atleast_2d(A)
    phi = phi_lyapunov(A, X, q)
    out = np.zeros_like(phi)
    for i, Ki in enumerate(K, start=1):
        M = np.linalg.matrix_power(A, i) + np.asarray(Ki) @ stacked_output(A, C, i)
        out = out + p * (1.0 - p) ** (i - 1) * M.conj().T @ phi @ M
    return out


# ----------------------------------------------------------------------------- Theorem 2 LMI (10)-(11)
@dataclass
class LMIResult:
    """One solve of (10)-(11): solver status, margin, and the independent certificate."""

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
    """

    def __init__(self, A, C, l_o: int | None = None, margin_tol: float = 1e-7):
        cp = _cp()
        self.A = np.atleast_2d(np.asarray(A, dtype=float))
        self.C = np.atleast_2d(np.asarray(C, dtype=float))
        n, m = self.A.shape[0], self.C.shape[0]
        self.l_o = observability_index(self.A, self.C) if l_o is None else int(l_o)
        if self.l_o < 2:
            raise ValueError("one-step observable system: the sum in (9) is empty (l_o = 1)")
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
        """Solve at ``(p, q)``; recover ``K^{(i)} = Y^{-1} F_i'`` and certify ``rho(H(K)) < 1``."""
        if not (0 < q <= 1) or p < 0 or (self.l_o > 2 and p > 1):
            raise ValueError(f"need 0 < q <= 1 and 0 <= p (<= 1 when l_o > 2), got p={p}, q={q}")
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
    """Independent check of a solver answer: ``rho(H(K)) < 1`` (eq. 7) and ``X - L_K(X) > 0`` (Thm 2 (iii))."""
    margin = float(t) if t is not None else np.nan
    feasible = status in CANDIDATE_STATUSES and margin > margin_tol
    if not feasible or Y is None or any(f is None for f in F):
        return LMIResult(p, q, status, margin, False, False, np.nan, np.nan)
    K = [np.linalg.solve(Y, f.T) for f in F]
    rho = h_radius(A, C, K, p, q)
    lyap = float(np.min(np.linalg.eigvalsh(X - L_operator(A, C, K, p, q, X))))
    return LMIResult(p, q, status, margin, True, bool(rho < 1.0), rho, lyap, K)


def rebuild_solve(A, C, p, q, l_o=None, margin_tol=1e-7) -> LMIResult:
    """The same LMI (10)-(11) built from scratch with constants (benchmark baseline: no Parameters)."""
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


# ----------------------------------------------------------------------------- Riccati maps
def riccati_h(P, A, Q):
    """``h(X) = A X A' + Q`` (eq. 4), batched over leading axes."""
    return A @ P @ A.T + Q


def riccati_g(P, A, C, Q, R):
    """``g(X) = A X A' + Q - A X C' (C X C' + R)^{-1} C X A'`` (eq. 5), batched over leading axes."""
    PCt = P @ C.T
    S = C @ PCt + R
    if S.shape[-1] == 1:  # one output: a division, not a batched LAPACK solve of 1 x 1 systems
        post = P - PCt @ (np.swapaxes(PCt, -1, -2) / S)
    else:
        post = P - PCt @ np.linalg.solve(S, np.swapaxes(PCt, -1, -2))
    out = A @ post @ A.T + Q
    return 0.5 * (out + np.swapaxes(out, -1, -2))


def sym_norm(P) -> np.ndarray:
    """Induced 2-norm of symmetric PSD matrices (largest eigenvalue), batched; ``inf`` stays ``inf``."""
    P = np.asarray(P, dtype=float)
    bad = ~np.isfinite(P).all(axis=(-1, -2))
    Pf = np.where(bad[..., None, None], 0.0, P)
    n = P.shape[-1]
    if n == 2:
        a, b, d = Pf[..., 0, 0], 0.5 * (Pf[..., 0, 1] + Pf[..., 1, 0]), Pf[..., 1, 1]
        val = 0.5 * (a + d) + np.sqrt(0.25 * (a - d) ** 2 + b * b)
    elif n == 3:
        val = _largest_eigenvalue_3x3(0.5 * (Pf + np.swapaxes(Pf, -1, -2)))
    else:
        val = np.linalg.eigvalsh(Pf)[..., -1]
    return np.where(bad, np.inf, val)


def _largest_eigenvalue_3x3(S) -> np.ndarray:
    """Largest eigenvalue of symmetric 3 x 3 matrices in closed form (trigonometric solution of the
    characteristic cubic), batched; LAPACK's ``eigvalsh`` costs ~20 us per small matrix, this a few
    vectorised operations. With ``q = tr S / 3``, ``p = ||S - q I||_F / sqrt(6)`` and
    ``r = det((S - q I) / p) / 2``: ``lambda_max = q + 2 p cos(arccos(r) / 3)`` (``q`` where ``p = 0``).
    """
    q = np.trace(S, axis1=-2, axis2=-1) / 3.0
    D = S - q[..., None, None] * np.eye(3)
    p = np.sqrt(np.sum(D * D, axis=(-2, -1)) / 6.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        B = D / p[..., None, None]
        b00, b11, b22 = B[..., 0, 0], B[..., 1, 1], B[..., 2, 2]
        b01, b02, b12 = B[..., 0, 1], B[..., 0, 2], B[..., 1, 2]
        det = b00 * (b11 * b22 - b12 * b12) - b01 * (b01 * b22 - b12 * b02) + b02 * (b01 * b12 - b11 * b02)
        r = det / 2.0
    phi = np.arccos(np.clip(np.nan_to_num(r), -1.0, 1.0)) / 3.0
    return np.where(p > 0, q + 2.0 * p * np.cos(phi), q)


# ----------------------------------------------------------------------------- exact moments
@dataclass
class ExactMoments:
    """``E||P_k||`` and ``E tr P_k`` for ``k = 1..depth+1`` as polynomials in the transition probabilities.

    ``coef[d]`` has rows ``(n11, n10, n01, n00, sum_norm, sum_trace)``: over all channel paths
    ``gamma_1 = 1, gamma_2..gamma_d`` with the given transition counts, the sum of ``||P_{d+1}||``
    and ``tr P_{d+1}``. The path probability is ``(1-p)^{n11} p^{n10} q^{n01} (1-q)^{n00}``.
    """

    coef: list
    P1_norm: float
    P1_trace: float

    @property
    def depth(self):
        return len(self.coef)

    def mean(self, p, q, which="norm") -> np.ndarray:
        """``E||P_k||`` (``which="norm"``) or ``E tr P_k``, ``k = 1..depth+1``, for scalar or array ``p, q``.

        Returns an array of shape ``broadcast(p, q).shape + (depth + 1,)``.
        """
        p, q = np.broadcast_arrays(np.asarray(p, dtype=float), np.asarray(q, dtype=float))
        col = 4 if which == "norm" else 5
        out = [np.full(p.shape, self.P1_norm if which == "norm" else self.P1_trace)]
        base = np.stack([1 - p, p, q, 1 - q], axis=-1)  # (..., 4)
        for c in self.coef:
            counts = c[:, :4]
            prob = np.prod(base[..., None, :] ** counts, axis=-1)  # (..., n_keys); 0**0 = 1
            out.append(prob @ c[:, col])
        return np.stack(out, axis=-1)


def exact_moments(system: LinearSystem, Sigma0, depth: int) -> ExactMoments:
    """Exact ``E||P_k||`` over all ``2^{k-2}`` channel paths (``gamma_1 = 1``), ``k <= depth + 1``.

    The covariance along a path does not depend on ``(p, q)``; only the path probabilities do.
    The binary tree of covariances is built level by level (batched), and each level is summed by
    transition counts, which yields the expectation as a polynomial in ``(p, q)`` that is then
    evaluated on any grid at negligible cost. Exact (no sampling), so heavy tails are included.
    """
    A, C, Q, R = system.A, system.C, system.Q, system.R
    P = np.asarray(Sigma0, dtype=float)[None]
    P1 = P[0]
    # level d = 1: gamma_1 = 1 -> P_2 = g(P_1)
    P = riccati_g(P, A, C, Q, R)
    state = np.ones(1, dtype=bool)
    counts = np.zeros((1, 4), dtype=np.int16)
    coef = []
    for d in range(1, depth + 1):
        if d > 1:
            n_par = len(P)
            with np.errstate(over="ignore", invalid="ignore"):
                P_recv = riccati_g(P, A, C, Q, R)
                P_loss = riccati_h(P, A, Q)
            P = np.concatenate([P_recv, P_loss])
            new_state = np.concatenate([np.ones(n_par, bool), np.zeros(n_par, bool)])
            old = np.concatenate([state, state])
            counts = np.concatenate([counts, counts])
            # transition index: 11 -> 0, 10 -> 1, 01 -> 2, 00 -> 3
            idx = np.where(old, np.where(new_state, 0, 1), np.where(new_state, 2, 3))
            counts[np.arange(len(idx)), idx] += 1
            state = new_state
        key = ((counts[:, 0].astype(np.int64) * (d + 1) + counts[:, 1]) * (d + 1) + counts[:, 2]) * (d + 1) + counts[:, 3]
        uniq, first, inv = np.unique(key, return_index=True, return_inverse=True)
        s_norm = np.bincount(inv, weights=sym_norm(P), minlength=len(uniq))
        s_tr = np.bincount(inv, weights=np.trace(P, axis1=-2, axis2=-1), minlength=len(uniq))
        coef.append(np.column_stack([counts[first].astype(float), s_norm, s_tr]))
    return ExactMoments(coef, float(sym_norm(P1[None])[0]), float(np.trace(P1)))


# ----------------------------------------------------------------------------- Monte Carlo estimators
def covariance_paths_ge(system, Sigma0, arrivals) -> np.ndarray:
    """``P_1..P_{T+1}`` along each path, shape ``(N, T+1, n, n)``: ``P_{k+1} = g(P_k)`` if ``gamma_k = 1``
    else ``h(P_k)`` (eqs. 4-5), batched over paths: the shared engine's recursion with one sensor (C, R).
    """
    return covariance_paths(Sigma0, system.A, system.Q, [Sensor(system.C, system.R)], arrivals, keep="all")


def plain_mc(system, Sigma0, p, q, n_paths, horizon, rng):
    """Plain sample mean of ``||P_k||`` over ``n_paths`` Gilbert-Elliott paths (``gamma_1 = 1``).

    Returns ``(norms, arrivals)`` with ``norms`` of shape ``(N, horizon + 1)`` (``k = 1..horizon+1``).
    """
    arrivals = gilbert_elliott_arrivals(rng, n_paths, horizon, p, q, initial=1)
    P = covariance_paths_ge(system, Sigma0, arrivals)
    return sym_norm(P), arrivals


def rb_mean_norm(system, Sigma0, p, q, arrivals, P=None, which="norm"):
    """Conditional (Rao-Blackwellised) estimator of ``E||P_k||`` integrating the trailing loss run.

    With ``l = max{i <= k-1 : gamma_i = 1}`` the last reception before ``k``,
    ``P_k = h^{k-1-l}(P_{l+1})`` (eq. 4) and, by the Markov property (eq. 3),
    ``P(l = i | gamma_1..gamma_i, gamma_i = 1) = p (1-q)^{k-2-i}`` for ``i < k-1`` (1 for ``i = k-1``). So

    .. math:: E\\|P_k\\| = \\sum_{i=1}^{k-1} E\\big[1\\{\\gamma_i = 1\\}\\, w_{k,i}\\, \\|h^{k-1-i}(P_{i+1})\\|\\big]

    and the per-path sum is an unbiased estimator whose loss-run tail (the growth
    ``|lambda_A|^{2j} (1-q)^j``) is computed exactly instead of sampled. ``gamma_1 = 1`` is required.

    Parameters
    ----------
    arrivals : bool array ``(N, T)`` with ``arrivals[:, 0]`` all True.
    P : optional ``(N, T+1, n, n)`` covariances ``P_1..P_{T+1}`` along the same paths.

    Returns
    -------
    ndarray ``(N, T+1)``: per-path estimator values for ``k = 1..T+1`` (average over axis 0).
    """
    arrivals = np.asarray(arrivals, dtype=bool)
    if not arrivals[:, 0].all():
        raise ValueError("rb_mean_norm needs gamma_1 = 1 on every path")
    A, Q = system.A, system.Q
    if P is None:
        P = covariance_paths_ge(system, Sigma0, arrivals)
    N, T = arrivals.shape
    normf = sym_norm if which == "norm" else (lambda M: np.trace(M, axis1=-2, axis2=-1))
    out = np.empty((N, T + 1))
    out[:, 0] = normf(P[:, 0])
    # H[:, i] = h^{k-1-i}(P_{i+1}) for the current k, for i = 1..k-1 (0-based column i-1)
    H = np.empty((N, 0) + A.shape)
    for k in range(2, T + 2):
        with np.errstate(over="ignore", invalid="ignore"):
            H = riccati_h(H, A, Q) if H.shape[1] else H
            H = np.concatenate([H, P[:, k - 1][:, None]], axis=1)  # P_k = h^0(P_k), i = k-1
        i = np.arange(1, k)
        w = np.where(i < k - 1, p * (1.0 - q) ** np.maximum(k - 2 - i, 0), 1.0)
        g = arrivals[:, :k - 1]  # gamma_1..gamma_{k-1}
        with np.errstate(over="ignore", invalid="ignore"):
            vals = normf(H)
            out[:, k - 1] = np.sum(np.where(g, w * vals, 0.0), axis=1)
    return out


def rb_mean_trace(system, Sigma0, p, q, arrivals, n_batches: int = 20):
    """Conditional estimator of ``E tr P_k`` for long horizons, with batch means.

    Same decomposition as :func:`rb_mean_norm`, but for the trace, which is *linear* in the
    covariance at the last reception: ``tr h^j(P) = <W_j, P> + c_j`` with ``W_j = (A^j)' A^j`` and
    ``c_j = tr sum_{t<j} A^t Q (A^t)'`` (eq. 4). So only the batch means of
    ``1{gamma_i = 1} P_{i+1}`` are needed and the cost is ``O(N T)`` instead of ``O(N T^2)``.

    Returns
    -------
    (mean, low, high): arrays of length ``T + 1`` (``k = 1..T+1``), 95% batch-means interval.
    """
    arrivals = np.asarray(arrivals, dtype=bool)
    if not arrivals[:, 0].all():
        raise ValueError("rb_mean_trace needs gamma_1 = 1 on every path")
    A, Q = system.A, system.Q
    N, T = arrivals.shape
    P = covariance_paths_ge(system, Sigma0, arrivals)  # (N, T+1, n, n)
    batches = np.array_split(np.arange(N), n_batches)
    g = arrivals.astype(float)  # gamma_1..gamma_T
    S = np.stack([np.einsum("ni,nixy->ixy", g[b], P[b, 1:]) / len(b) for b in batches])  # (B, T, n, n)
    f = np.stack([g[b].mean(axis=0) for b in batches])  # (B, T)
    W, c = [np.eye(A.shape[0])], [0.0]
    Aj, Qsum = np.eye(A.shape[0]), np.zeros_like(A)
    for _ in range(1, T + 1):
        Qsum = A @ Qsum @ A.T + Q
        Aj = A @ Aj
        W.append(Aj.T @ Aj)
        c.append(float(np.trace(Qsum)))
    W, c = np.array(W), np.array(c)
    with np.errstate(over="ignore", invalid="ignore"):
        inner = np.einsum("bixy,jxy->bij", S, W)  # <W_j, S_b[i]>
        vals = np.empty((len(batches), T + 1))
        vals[:, 0] = np.trace(np.asarray(Sigma0, float))
        for k in range(2, T + 2):
            i = np.arange(1, k)  # last reception time (1-based) -> column i-1
            j = k - 1 - i
            w = np.where(i < k - 1, p * (1.0 - q) ** np.maximum(k - 2 - i, 0), 1.0)
            vals[:, k - 1] = np.sum(w * (inner[:, i - 1, j] + c[j] * f[:, i - 1]), axis=1)
    mean = vals.mean(axis=0)
    half = 1.96 * vals.std(axis=0, ddof=1) / np.sqrt(len(batches))
    return mean, mean - half, mean + half


def rb_trace_grid(system, Sigma0, ps, qs, n_paths: int, horizon: int, rng, n_batches: int = 10):
    """:func:`rb_mean_trace` for many ``(p, q)`` points at once (all paths of all points in one batch).

    Memory is ``O(points x paths)``: the batch sums of ``1{gamma_i = 1} P_{i+1}`` are accumulated
    during the time loop, the covariances themselves are not stored.

    Returns
    -------
    (mean, half): arrays ``(n_points, horizon + 1)``, the estimate of ``E tr P_k`` and the 95%
    batch-means half-width.
    """
    ps, qs = np.atleast_1d(np.asarray(ps, float)), np.atleast_1d(np.asarray(qs, float))
    npts, B, T = len(ps), n_batches, horizon
    per = -(-n_paths // B)  # paths per batch
    A, C, Q, R = system.A, system.C, system.Q, system.R
    n = A.shape[0]
    arr = np.concatenate([gilbert_elliott_arrivals(rng, B * per, T, p, q, initial=1) for p, q in zip(ps, qs)])
    starts = np.arange(0, npts * B * per, per)  # contiguous (point, batch) groups
    P = np.broadcast_to(np.asarray(Sigma0, float), (len(arr), n, n)).copy()
    S = np.empty((npts * B, T, n, n))
    with np.errstate(over="ignore", invalid="ignore"):
        for k in range(T):
            P = np.where(arr[:, k, None, None], riccati_g(P, A, C, Q, R), riccati_h(P, A, Q))
            S[:, k] = np.add.reduceat(np.where(arr[:, k, None, None], P, 0.0), starts, axis=0) / per
    f = np.add.reduceat(arr.astype(float), starts, axis=0) / per  # (npts*B, T)
    W, c = [np.eye(n)], [0.0]
    Aj, Qsum = np.eye(n), np.zeros_like(A)
    for _ in range(T):
        Qsum = A @ Qsum @ A.T + Q
        Aj = A @ Aj
        W.append(Aj.T @ Aj)
        c.append(float(np.trace(Qsum)))
    W, c = np.array(W), np.array(c)
    vals = np.empty((npts * B, T + 1))
    vals[:, 0] = np.trace(np.asarray(Sigma0, float))
    pr = np.repeat(ps, B)[:, None]
    qr = np.repeat(qs, B)[:, None]
    with np.errstate(over="ignore", invalid="ignore"):
        inner = np.einsum("bixy,jxy->bij", S, W)
        for k in range(2, T + 2):
            i = np.arange(1, k)
            j = k - 1 - i
            w = np.where(i < k - 1, pr * (1.0 - qr) ** np.maximum(k - 2 - i, 0), 1.0)
            vals[:, k - 1] = np.sum(w * (inner[:, i - 1, j] + c[j] * f[:, i - 1]), axis=1)
    vals = vals.reshape(npts, B, T + 1)
    mean = vals.mean(axis=1)
    half = 1.96 * vals.std(axis=1, ddof=1) / np.sqrt(B)
    return mean, half


# ----------------------------------------------------------------------------- i.i.d. line, analytic helpers
def gilbert_elliott_stationary_loss(p, q) -> float:
    """Stationary loss probability ``P(gamma = 0) = p / (p + q)`` of the chain (3)."""
    return gilbert_elliott_stationary(p, q)[1]



def sinopoli_lmi_threshold(A, C, tol: float = 1e-5):
    """Sinopoli et al. (2004, Thm 5) LMI upper bound on the critical arrival rate ``lambda_c`` (i.i.d. losses).

    Smallest ``lambda`` with a certified-feasible ``Y > (1-lambda) A'YA + lambda (A+KC)'Y(A+KC)`` (shared
    :class:`~netrepro.engines.lmi.MareStabilizabilityLMI`, certified by the second-moment radius).
    """
    from ..engines.lmi import MareStabilizabilityLMI

    lmi = MareStabilizabilityLMI(A, [None, C])
    res = bisect_monotone(lambda lam: lmi.solve([1 - lam, lam]).certified, 1e-6, 1.0, tol=tol)
    return res.threshold, lmi.n_solves


def parity_bound_example2(lam_abs: float, q):
    """Closed-form ``p`` at which ``p q |lambda|^4 / (1 - (|lambda|^2 (1-q))^2) = 1`` (Example II).

    For ``A = |lambda| diag(1, 1, -1)`` with ``C`` of eq. (13): ``A^2 = |lambda|^2 I`` and
    ``C v = 0`` for ``v = (1, 1, -1)``, so receptions separated by even gaps never observe ``v``.
    Summing over gaps of ``j`` losses (``j`` odd) gives this renewal ratio; our derivation (see the
    report) shows it is also the value of Theorem 5's ``p_underline(q)`` for this system (gain with
    range ``span(S v)`` and ``M S v = 0``), so it is the analytic check of the bisection.
    """
    q = np.asarray(q, dtype=float)
    l2 = lam_abs ** 2
    return (1.0 - (l2 * (1.0 - q)) ** 2) / (l2 * l2 * q)


def norm_relaxation_bound(A, q, K=None, i_max: int = 4000):
    """Largest ``p`` with ``q sum_j (1-q)^{j-1} ||A^j||^2 * p ||A + K C||^2 < 1`` (last line after eq. 8, l_o = 2).

    The norm relaxation by which the paper says its Theorem 1 covers the criteria of [15-17];
    with ``K = 0`` it is our proxy for the criterion of [16] (which we cannot recompute from the text).
    """
    A = np.atleast_2d(A)
    M = A if K is None else A + K
    s, Aj = 0.0, np.eye(A.shape[0])
    for j in range(1, i_max + 1):
        Aj = Aj @ A
        term = q * (1 - q) ** (j - 1) * np.linalg.norm(Aj, 2) ** 2
        s += term
        if term < 1e-14 * s:
            break
    return 1.0 / (s * np.linalg.norm(M, 2) ** 2)
