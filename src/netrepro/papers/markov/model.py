"""The equations of the `markov` paper (Wu, Shi, Anderson, Johansson): system, observability,
Proposition 1 (eq. 8), the operators of Theorems 1-2 (eqs. 7, 9), the Riccati maps (eqs. 4-5)
and closed forms for the two examples.

Channel convention (eq. 3): ``gamma_k`` is the state of a two-state Markov chain,
``p = P(gamma_{k+1}=0 | gamma_k=1)`` (failure rate), ``q = P(gamma_{k+1}=1 | gamma_k=0)``
(recovery rate), and ``gamma_1 = 1``. ``P_k`` is the prediction covariance ``P_{k|k-1}``;
``P_{k+1} = g(P_k)`` when ``gamma_k = 1`` and ``h(P_k)`` otherwise (eqs. 4-5).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...engines.channels import gilbert_elliott_stationary
from ...errors import InputError

__all__ = [
    "LinearSystem", "spectral_abs", "observability_index", "stacked_output", "prop1_bound", "loss_factor",
    "H_matrix", "h_radius", "phi_lyapunov", "L_operator", "riccati_h", "riccati_g", "sym_norm", "batched_trace",
    "gilbert_elliott_stationary_loss", "parity_bound_example2", "parity_ceiling",
    "prop1_closed_form", "defective_unit_circle_eigenvalues",
]


# ----------------------------------------------------------------------------- system
@dataclass(frozen=True)
class LinearSystem:
    """``x_{k+1} = A x_k + w_k``, ``y_k = C x_k + v_k`` (eqs. 1-2) with ``Q = cov w``, ``R = cov v``.

    Parameters
    ----------
    A, C, Q, R : array_like
        System matrix ``(n, n)``, output matrix ``(m, n)``, process noise covariance ``(n, n)`` and
        measurement noise covariance ``(m, m)`` of eqs. (1)-(2).

    Raises
    ------
    InputError
        If the shapes are inconsistent.
    """

    A: np.ndarray
    C: np.ndarray
    Q: np.ndarray
    R: np.ndarray

    def __post_init__(self):
        for name in ("A", "C", "Q", "R"):
            object.__setattr__(self, name, np.atleast_2d(np.asarray(getattr(self, name), dtype=float)))
        n, m = self.A.shape[0], self.C.shape[0]
        if self.A.shape != (n, n) or self.C.shape[1] != n or self.Q.shape != (n, n) or self.R.shape != (m, m):
            raise InputError(f"inconsistent shapes A{self.A.shape} C{self.C.shape} Q{self.Q.shape} R{self.R.shape}")

    @property
    def n(self):
        """The state dimension.

        Returns
        -------
        int
            The state dimension ``n``.
        """
        return self.A.shape[0]

    @classmethod
    def from_config(cls, cfg: dict) -> "LinearSystem":
        """Build the system from a configuration example.

        Parameters
        ----------
        cfg : dict
            A configuration example with keys ``A, C, Q, R``.

        Returns
        -------
        LinearSystem
        """
        return cls(cfg["A"], cfg["C"], cfg["Q"], cfg["R"])


def spectral_abs(A) -> float:
    """``|lambda_A|``: the largest eigenvalue magnitude of ``A`` (paper's notation).

    Parameters
    ----------
    A : array_like
        Square matrix.

    Returns
    -------
    float
        ``max_i |lambda_i(A)|``.
    """
    return float(np.max(np.abs(np.linalg.eigvals(np.atleast_2d(A)))))


def defective_unit_circle_eigenvalues(A, tol: float = 1e-6) -> int:
    """Number of distinct defective eigenvalues of ``A`` on the unit circle (Definition 4; Theorem 3's assumption).

    An eigenvalue is defective when its algebraic multiplicity exceeds its geometric multiplicity
    ``n - rank(A - lambda I)``. Computed eigenvalues of a Jordan block of size ``m`` scatter by about
    ``eps^(1/m)`` around the true one, so eigenvalues within ``tol`` form one cluster (the algebraic multiplicity
    is its size, ``lambda`` its mean) and the rank is taken with the same tolerance.

    Parameters
    ----------
    A : array_like
        Square matrix.
    tol : float
        Cluster radius, distance of ``|lambda|`` from 1, and rank tolerance (relative to ``max(1, ||A||)``);
        the default covers Jordan blocks up to size 2 (scatter ~1.5e-8) and 3 (~6e-6) of well-scaled matrices.

    Returns
    -------
    int
        How many eigenvalue clusters with ``||lambda| - 1| <= tol`` are defective (0: Theorem 3 applies).
    """
    A = np.atleast_2d(np.asarray(A, dtype=complex))
    n = A.shape[0]
    eig = np.linalg.eigvals(A)
    clusters, left = [], list(eig)
    while left:
        seed = left.pop(0)
        members = [seed] + [x for x in left if abs(x - seed) <= tol]
        left = [x for x in left if abs(x - seed) > tol]
        clusters.append(members)
    scale = max(1.0, float(np.linalg.norm(A, 2)))
    count = 0
    for members in clusters:
        lam = np.mean(members)
        if abs(abs(lam) - 1.0) > tol:
            continue
        geometric = n - int(np.linalg.matrix_rank(A - lam * np.eye(n), tol=tol * scale))
        count += len(members) > geometric
    return count


def observability_index(A, C) -> int:
    """Observability index ``l_o`` (Definition 2).

    The smallest ``l`` with ``rank [C; CA; ...; CA^{l-1}] = n``.

    Raises
    ------
    InputError
        If ``(C, A)`` is not observable.

    Parameters
    ----------
    A : array_like
        ``(n, n)`` system matrix.
    C : array_like
        ``(m, n)`` output matrix.

    Returns
    -------
    int
        ``l_o``, between 1 and ``n``.
    """
    A, C = np.atleast_2d(A), np.atleast_2d(C)
    n = A.shape[0]
    for ell in range(1, n + 1):
        if np.linalg.matrix_rank(stacked_output(A, C, ell)) == n:
            return ell
    raise InputError("(C, A) is not observable")


def stacked_output(A, C, i: int) -> np.ndarray:
    """``C^{(i)} = [C; CA; ...; CA^{i-1}]`` (``m i x n``), our reading of the undefined ``C^{(i)}`` in eqs. 7, 9, 11.

    With ``i`` consecutive receptions starting at a peak time, a (sub-optimal) linear
    estimator gives the error map ``A^i + K^{(i)} C^{(i)}`` for any gain ``K^{(i)}``.

    Parameters
    ----------
    A : array_like
        ``(n, n)`` system matrix.
    C : array_like
        ``(m, n)`` output matrix.
    i : int
        Number of stacked blocks.

    Returns
    -------
    ndarray
        ``(m i, n)`` matrix ``[C; CA; ...; CA^{i-1}]``.
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

    Parameters
    ----------
    lam_abs : float
        ``|lambda_A|``.
    q : array_like
        Recovery rates.
    l_o : int
        Observability index (Definition 2).
    p_max : float
        Upper end of the bisection for ``l_o > 2``.
    tol : float
        Bisection tolerance for ``l_o > 2``.

    Returns
    -------
    ndarray
        The bound on ``p`` for each ``q`` (``inf`` for ``l_o = 1``, ``nan`` where eq. 8 cannot hold).
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
    """``q [(A (x) A)^{-1} - (1-q) I]^{-1} = sum_{j>=1} q (1-q)^{j-1} (A (x) A)^j`` (first factor of eq. 7).

    Parameters
    ----------
    A : array_like
        ``(n, n)`` system matrix with ``|lambda_A|^2 (1-q) < 1``.
    q : float
        Recovery rate.

    Returns
    -------
    ndarray
        ``(n^2, n^2)`` matrix.
    """
    A = np.atleast_2d(A)
    AA = np.kron(A, A)
    return q * np.linalg.inv(np.linalg.inv(AA) - (1.0 - q) * np.eye(AA.shape[0]))


def H_matrix(A, C, K, p, q) -> np.ndarray:
    r"""``H(K)`` of Theorem 1, eq. (7).

    .. math::
        H(K) = qp[(A\otimes A)^{-1} - (1-q)I]^{-1} \sum_{i=1}^{l_o-1}
               \overline{(A^i + K^{(i)}C^{(i)})} \otimes (A^i + K^{(i)}C^{(i)}) (1-p)^{i-1}

    Parameters
    ----------
    A : array_like
        System matrix, ``(n, n)``.
    C : array_like
        Output matrix, ``(m, n)``.
    K : list of arrays
        ``K[i-1]`` is ``K^{(i)}`` of shape ``(n, m i)``, ``i = 1 .. l_o - 1``.
    p : float
        Failure rate ``P(gamma_{k+1}=0 | gamma_k=1)``.
    q : float
        Recovery rate ``P(gamma_{k+1}=1 | gamma_k=0)``.

    Returns
    -------
    ndarray
        Complex ``(n^2, n^2)`` matrix ``H(K)``.
    """
    A = np.atleast_2d(A)
    total = np.zeros((A.shape[0] ** 2,) * 2, dtype=complex)
    for i, Ki in enumerate(K, start=1):
        M = np.linalg.matrix_power(A, i) + np.asarray(Ki) @ stacked_output(A, C, i)
        total = total + (1.0 - p) ** (i - 1) * np.kron(np.conj(M), M)
    return p * loss_factor(A, q) @ total


def h_radius(A, C, K, p, q) -> float:
    """Spectral radius ``|lambda_{H(K)}|`` of eq. (7): the independent certificate of Theorems 1-2.

    Parameters
    ----------
    A, C : array_like
        System and output matrices.
    K : list of arrays
        Gains ``K^{(i)}``, as in :func:`H_matrix`.
    p, q : float
        Failure and recovery rates.

    Returns
    -------
    float
        ``rho(H(K))``; the filter is mean-square stable with these gains if it is below 1 (Theorem 1).
    """
    return float(np.max(np.abs(np.linalg.eigvals(H_matrix(A, C, K, p, q)))))


def phi_lyapunov(A, X, q) -> np.ndarray:
    """``Phi_X``: solution of ``(1-q) A' Phi A + q A' X A = Phi`` (below eq. 9), needs ``|lambda_A|^2 (1-q) < 1``.

    Parameters
    ----------
    A : array_like
        ``(n, n)`` system matrix.
    X : array_like
        ``(n, n)`` symmetric matrix.
    q : float
        Recovery rate.

    Returns
    -------
    ndarray
        ``Phi_X``, ``(n, n)``.
    """
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

    Parameters
    ----------
    A, C : array_like
        System and output matrices.
    K : list of arrays
        Gains ``K^{(i)}``, as in :func:`H_matrix`.
    p, q : float
        Failure and recovery rates.
    X : array_like
        ``(n, n)`` symmetric matrix.

    Returns
    -------
    ndarray
        ``L_K(X)``, ``(n, n)``.
    """
    A = np.atleast_2d(A)
    phi = phi_lyapunov(A, X, q)
    out = np.zeros_like(phi)
    for i, Ki in enumerate(K, start=1):
        M = np.linalg.matrix_power(A, i) + np.asarray(Ki) @ stacked_output(A, C, i)
        out = out + p * (1.0 - p) ** (i - 1) * M.conj().T @ phi @ M
    return out


# ----------------------------------------------------------------------------- Riccati maps
def riccati_h(P, A, Q):
    """``h(X) = A X A' + Q`` (eq. 4), batched over leading axes.

    Parameters
    ----------
    P : ndarray
        ``(..., n, n)`` covariances.
    A, Q : ndarray
        System matrix and process noise covariance.

    Returns
    -------
    ndarray
        ``(..., n, n)``.
    """
    return A @ P @ A.T + Q


def riccati_g(P, A, C, Q, R):
    """``g(X) = A X A' + Q - A X C' (C X C' + R)^{-1} C X A'`` (eq. 5), batched over leading axes.

    Parameters
    ----------
    P : ndarray
        ``(..., n, n)`` covariances.
    A, C, Q, R : ndarray
        System matrices of eqs. (1)-(2).

    Returns
    -------
    ndarray
        ``(..., n, n)``, symmetrised.
    """
    PCt = P @ C.T
    S = C @ PCt + R
    if S.shape[-1] == 1:  # one output: a division, not a batched LAPACK solve of 1 x 1 systems
        post = P - PCt @ (np.swapaxes(PCt, -1, -2) / S)
    else:
        post = P - PCt @ np.linalg.solve(S, np.swapaxes(PCt, -1, -2))
    out = A @ post @ A.T + Q
    return 0.5 * (out + np.swapaxes(out, -1, -2))


def sym_norm(P) -> np.ndarray:
    """Induced 2-norm of symmetric PSD matrices (largest eigenvalue), batched; ``inf`` stays ``inf``.

    Parameters
    ----------
    P : array_like
        ``(..., n, n)`` symmetric matrices (non-finite entries allowed).

    Returns
    -------
    ndarray
        ``(...)`` largest eigenvalues; ``inf`` where a matrix has a non-finite entry.
    """
    P = np.asarray(P, dtype=float)
    n = P.shape[-1]
    if n == 2:
        return _sym_norm_2x2(P)
    bad = ~np.isfinite(P).all(axis=(-1, -2))
    Pf = np.where(bad[..., None, None], 0.0, P)
    if n == 3:
        val = _largest_eigenvalue_3x3(0.5 * (Pf + np.swapaxes(Pf, -1, -2)))
    else:
        val = np.linalg.eigvalsh(Pf)[..., -1]
    return np.where(bad, np.inf, val)


def batched_trace(P) -> np.ndarray:
    """Traces of a stack of square matrices: ``np.trace(P, axis1=-2, axis2=-1)``, bit for bit.

    ``np.trace`` sums the diagonal from ``0.0`` (so a diagonal of ``-0.0`` gives ``0.0``); for 1 x 1 and
    2 x 2 matrices that is written out, ``(0.0 + P_00) + P_11``, the same additions in the same order
    without numpy's reduction over a short axis (~4x faster on the 2^22 paths of the exact moments).
    Larger matrices and other dtypes: ``np.trace``.

    Parameters
    ----------
    P : array_like
        ``(..., n, n)``.

    Returns
    -------
    ndarray
        ``(...)`` the traces.
    """
    P = np.asarray(P)
    if P.dtype == np.float64 and P.shape[-1] == 1:
        return 0.0 + P[..., 0, 0]
    if P.dtype == np.float64 and P.shape[-1] == 2:
        return (0.0 + P[..., 0, 0]) + P[..., 1, 1]
    return np.trace(P, axis1=-2, axis2=-1)


def _sym_norm_2x2(P) -> np.ndarray:
    """:func:`sym_norm` of 2 x 2 matrices: ``(a + d) / 2 + sqrt((a - d)^2 / 4 + b^2)``, ``b`` the mean of the
    off-diagonal entries, and ``inf`` where an entry is not finite.

    Evaluated on the entries as given, with the non-finite test only where the value is not finite: a
    non-finite entry always gives a non-finite value (``a`` or ``d``: through ``a + d``; ``b``: through ``b^2``,
    which no finite term cancels), so the rows with a finite value are exactly those of the zeroed-and-masked
    form (``np.where(bad, 0, P)``, then ``np.where(bad, inf, value)``), the same operations on the same numbers,
    and the rows with a non-finite value get ``inf`` where an entry is not finite and keep their value (an
    overflow) elsewhere, as there. Bit for bit that form (tested), without its copy of ``P`` and its
    reduction over the two small axes (~7x faster on the 2^22 paths of the exact moments).
    """
    a, d = P[..., 0, 0], P[..., 1, 1]
    with np.errstate(invalid="ignore"):  # inf - inf in the rows that the mask replaces by inf
        b = 0.5 * (P[..., 0, 1] + P[..., 1, 0])
        val = 0.5 * (a + d) + np.sqrt(0.25 * (a - d) ** 2 + b * b)
    off = ~np.isfinite(val)
    if off.any():
        bad = np.zeros(val.shape, dtype=bool)
        bad[off] = ~np.isfinite(P[off]).all(axis=(-1, -2))
        val = np.where(bad, np.inf, val)
    return np.asarray(val)


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


# ----------------------------------------------------------------------------- i.i.d. line, analytic helpers
def gilbert_elliott_stationary_loss(p, q) -> float:
    """Stationary loss probability ``P(gamma = 0) = p / (p + q)`` of the chain (3).

    Parameters
    ----------
    p, q : float
        Failure and recovery rates of eq. (3).

    Returns
    -------
    float
    """
    return gilbert_elliott_stationary(p, q)[1]


def parity_bound_example2(lam_abs: float, q):
    """Closed-form ``p`` at which ``p q |lambda|^4 / (1 - (|lambda|^2 (1-q))^2) = 1`` (Example II).

    For ``A = |lambda| diag(1, 1, -1)`` with ``C`` of eq. (13): ``A^2 = |lambda|^2 I`` and
    ``C v = 0`` for ``v = (1, 1, -1)``, so receptions separated by even gaps never observe ``v``.
    Summing over gaps of ``j`` losses (``j`` odd) gives this renewal ratio; our derivation (see the
    report) shows it is also the value of Theorem 5's ``p_underline(q)`` for this system (gain with
    range ``span(S v)`` and ``M S v = 0``), so it is the analytic check of the bisection.

    Parameters
    ----------
    lam_abs : float
        ``|lambda_A|`` of Example II (1.2 in eq. 13).
    q : array_like
        Recovery rates.

    Returns
    -------
    ndarray
        The critical ``p`` for each ``q`` (may exceed 1).
    """
    q = np.asarray(q, dtype=float)
    l2 = lam_abs ** 2
    return (1.0 - (l2 * (1.0 - q)) ** 2) / (l2 * l2 * q)


def parity_ceiling(lam_abs: float) -> dict:
    """The largest critical failure rate of Example II over all recovery rates, and its ends.

    With ``L = |lambda|^4`` the critical curve (:func:`parity_bound_example2`, the zero set of the
    parity growth ``L (pq + (1-q)^2) = 1``) is ``p_c(q) = (1 - L (1-q)^2) / (L q)``. With
    ``u = 1 - q``, ``d p_c / d u = 0`` gives ``L u^2 - 2 L u + 1 = 0``, so ``q* = sqrt(1 - 1/L)`` and,
    using ``1 - L u^2 = 2 (1 - L u)``, ``max_q p_c(q) = 2 (1 - q*) = 2 (1 - sqrt(1 - |lambda|^-4))``
    (a maximum: ``p_c`` is concave in ``q`` on ``(0, 1]``, ``p_c'' = -2 / (L q^3) < 0``). At ``q -> 1``
    the curve ends at ``1 / L``; it reaches 0 at ``q = 1 - 1/|lambda|^2``, the necessary condition
    ``|lambda|^2 (1-q) < 1`` of [18]. Since ``max_q p_c < 1``, every ``p`` above it is mean-square
    unstable at every ``q`` (the parity lower bound grows: :func:`~.certificates.parity_growth` > 0).

    Parameters
    ----------
    lam_abs : float
        ``|lambda|`` of Example II (1.2 in eq. 13); ``|lambda| > 1``.

    Returns
    -------
    dict
        ``p_max`` (``max_q p_c(q)``), ``q_star`` (its argmax), ``p_at_q1`` (``p_c(1) = |lambda|^-4``),
        ``q_zero`` (``1 - |lambda|^-2``, where ``p_c = 0``).

    Raises
    ------
    InputError
        If ``|lambda| <= 1`` (no critical curve: stable for every ``(p, q)``).
    """
    lam_abs = float(lam_abs)
    if not lam_abs > 1.0:
        raise InputError(f"parity_ceiling needs |lambda| > 1, got {lam_abs}")
    L = lam_abs ** 4
    q_star = float(np.sqrt(1.0 - 1.0 / L))
    return {"p_max": 2.0 * (1.0 - q_star), "q_star": q_star, "p_at_q1": 1.0 / L, "q_zero": 1.0 - 1.0 / lam_abs ** 2}


def prop1_closed_form(lam_abs: float, q):
    """The closed form printed in Section 5.1: ``(1 - |lambda|^2 (1-q)) / (|lambda|^4 q)``.

    Eq. (8) with ``l_o = 2`` as printed in the text (compared with :func:`prop1_bound`).

    Parameters
    ----------
    lam_abs : float
        ``|lambda_A|``.
    q : array_like
        Recovery rates.

    Returns
    -------
    ndarray
        The printed bound on ``p``.
    """
    q = np.asarray(q, dtype=float)
    return (1.0 - lam_abs ** 2 * (1.0 - q)) / (lam_abs ** 4 * q)


