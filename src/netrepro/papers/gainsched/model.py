"""Model, analysis LMI, second moments and simulation of the `gainsched` paper.

G. Wei, Z. Wang, B. Shen, M. Li, *Probability-Dependent Gain-Scheduled Filtering
for Stochastic Systems with Missing Measurements*. This module holds the plant
(1)-(7), the filter (8)-(9), the augmented system (10)-(11), the sector
decomposition (3)-(5), the Theorem 1 analysis LMI (12) for given gains, the
second-moment operator used as an independent stability check, and the
vectorised Monte Carlo simulation of Algorithm 1.

Notation: ``p`` is ``Prob{xi(k) = 1}`` of (7), i.e. the probability that the
measurement *arrives* (the paper calls it the "missing probability").
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...errors import InputError

# cvxpy (and the engine that imports it) are imported where needed: steps that only
# simulate or plot do not pay for the import.

__all__ = [
    "GainschedError",
    "System",
    "Gains",
    "system_from_config",
    "gains_from_dict",
    "augmented",
    "sector_nonlinearity",
    "sector_split",
    "sector_cases",
    "p_schedule",
    "theorem1_matrix",
    "theorem1_lmi",
    "theorem1_grid_check",
    "second_moment_operator",
    "frozen_radius",
    "scheduled_growth_rate",
    "simulate",
    "draw_noise",
    "simulate_draws",
    "Theorem1Result",
    "zero_gains",
    "realisation",
    "augmented_initial_moment",
   
    "lyapunov_difference_bounds",
]


class GainschedError(InputError):
    """Bad argument to a `gainsched` function; the message names the argument.

    Parameters
    ----------
    message : str
        What is wrong, naming the argument.
    """


@dataclass(frozen=True)
class System:
    """Plant (1), (2), (6) with the sector (3) and the bounds of p(k) in (7).

    Attributes are the paper's matrices: ``A, B, C, D, Z`` (n x n, n x nz,
    m x n, n x n, nz x n), the sector bounds ``F1, F2`` (nz x nz), the variance
    ``sigma2`` of the scalar multiplicative noise w(k) and ``p1 <= p(k) <= p2``.

    Parameters
    ----------
    A, B, C, D, Z : ndarray
        Matrices of (1), (2), (6).
    F1, F2 : ndarray (nz, nz)
        Sector bounds of (3).
    sigma2 : float
        E{w(k)^2} of (1).
    p1, p2 : float
        Bounds of p(k) in (7).

    Returns
    -------
    System
        A frozen record; ``n``, ``m``, ``nz``, ``F = F2 - F1`` and ``N = [I 0]`` (11) as properties.
    """

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    Z: np.ndarray
    F1: np.ndarray
    F2: np.ndarray
    sigma2: float
    p1: float
    p2: float

    @property
    def n(self) -> int:
        """Plant order n (rows of A)."""
        return self.A.shape[0]

    @property
    def m(self) -> int:
        """Number of outputs m (rows of C)."""
        return self.C.shape[0]

    @property
    def nz(self) -> int:
        """Dimension nz of z = Zx (columns of B)."""
        return self.Z.shape[0]

    @property
    def F(self) -> np.ndarray:
        """F = F2 - F1 of (3) (symmetric positive definite)."""
        return self.F2 - self.F1

    @property
    def N(self) -> np.ndarray:
        """N = [I 0] of (11): picks x out of the augmented state [x; x_f]."""
        return np.hstack([np.eye(self.n), np.zeros((self.n, self.n))])


@dataclass(frozen=True)
class Gains:
    """Constant filter parameters of (9): G(p) = G0 + p Gf, H(p) = H0 + p Hf.

    Parameters
    ----------
    G0, Gf : ndarray (n, n)
        G(p) = G0 + p Gf, the filter's state matrix (9).
    H0, Hf : ndarray (n, m)
        H(p) = H0 + p Hf, the filter's measurement gain (9).

    Returns
    -------
    Gains
        A frozen record with the scheduled gains ``G(p)``, ``H(p)`` of (9).
    """

    G0: np.ndarray
    Gf: np.ndarray
    H0: np.ndarray
    Hf: np.ndarray

    def G(self, p: float) -> np.ndarray:
        """G(p) = G0 + p Gf of (9).

        Parameters
        ----------
        p : float

        Returns
        -------
        ndarray (n, n)
        """
        return self.G0 + p * self.Gf

    def H(self, p: float) -> np.ndarray:
        """H(p) = H0 + p Hf of (9).

        Parameters
        ----------
        p : float

        Returns
        -------
        ndarray (n, m)
        """
        return self.H0 + p * self.Hf

    def as_dict(self) -> dict:
        """The four matrices by name.

        Returns
        -------
        dict
            ``{"G0": ..., "Gf": ..., "H0": ..., "Hf": ...}``.
        """
        return {"G0": self.G0, "Gf": self.Gf, "H0": self.H0, "Hf": self.Hf}


def _mat(name, value, shape=None):
    arr = np.atleast_2d(np.asarray(value, dtype=float))
    if shape is not None and arr.shape != tuple(shape):
        raise GainschedError(f"{name} has shape {arr.shape}; expected {tuple(shape)}")
    if not np.all(np.isfinite(arr)):
        raise GainschedError(f"{name} must be finite, got {value!r}")
    return arr


def system_from_config(cfg: dict) -> System:
    """The example of Section IV from the ``system`` config section.

    ``F1``, ``F2`` are given as diagonals (the paper prints ``diag{...}``);
    ``C`` as one row per output.

    Parameters
    ----------
    cfg : dict
        Keys ``A, B, C, D, Z, F1_diag, F2_diag, sigma2, p1, p2``.

    Returns
    -------
    System

    Raises
    ------
    GainschedError
        On shapes that disagree, F2 - F1 not positive, p bounds outside (0, 1), sigma2 < 0.
    """
    A = _mat("A", cfg["A"])
    n = A.shape[0]
    if A.shape != (n, n):
        raise GainschedError(f"A must be square, got shape {A.shape}")
    B = _mat("B", cfg["B"])
    if B.shape[0] != n:
        raise GainschedError(f"B must have {n} rows, got shape {B.shape}")
    nz = B.shape[1]
    C = _mat("C", cfg["C"])
    if C.shape[1] != n:
        raise GainschedError(f"C must have {n} columns, got shape {C.shape}")
    D = _mat("D", cfg["D"], (n, n))
    Z = _mat("Z", cfg["Z"], (nz, n))
    F1 = np.diag(np.asarray(cfg["F1_diag"], dtype=float))
    F2 = np.diag(np.asarray(cfg["F2_diag"], dtype=float))
    if F1.shape != (nz, nz) or F2.shape != (nz, nz):
        raise GainschedError(f"F1_diag and F2_diag must have {nz} entries")
    if np.any(np.diag(F2 - F1) <= 0):
        raise GainschedError("F2 - F1 must be positive definite (sector (3))")
    p1, p2 = float(cfg["p1"]), float(cfg["p2"])
    if not 0.0 < p1 <= p2 < 1.0:
        raise GainschedError(f"need 0 < p1 <= p2 < 1, got p1={p1}, p2={p2}")
    sigma2 = float(cfg["sigma2"])
    if sigma2 < 0:
        raise GainschedError(f"sigma2 must be >= 0, got {sigma2}")
    return System(A, B, C, D, Z, F1, F2, sigma2, p1, p2)


def gains_from_dict(d: dict, sys: System | None = None) -> Gains:
    """Gains (9) from a mapping with keys G0, Gf, H0, Hf (H as column vectors or nested lists).

    Parameters
    ----------
    d : dict
        The four matrices as nested lists.
    sys : System, optional
        If given, the shapes are checked against it.

    Returns
    -------
    Gains

    Raises
    ------
    GainschedError
        On a shape that does not match ``sys``.
    """
    G0, Gf = _mat("G0", d["G0"]), _mat("Gf", d["Gf"])
    H0 = np.asarray(d["H0"], dtype=float).reshape(G0.shape[0], -1)
    Hf = np.asarray(d["Hf"], dtype=float).reshape(G0.shape[0], -1)
    if sys is not None:
        n, m = sys.n, sys.m
        for name, arr, shape in (("G0", G0, (n, n)), ("Gf", Gf, (n, n)), ("H0", H0, (n, m)), ("Hf", Hf, (n, m))):
            if arr.shape != shape:
                raise GainschedError(f"{name} has shape {arr.shape}; expected {shape}")
    return Gains(G0, Gf, H0, Hf)


def augmented(sys: System, gains: Gains, p: float):
    """The augmented system (10)-(11) at probability ``p``.

    .. math::

        \\bar z(k+1) = \\mathcal A(p)\\bar z + \\bar B f(ZN\\bar z) + (\\xi - p)\\bar C(p) N \\bar z
                       + \\bar D N \\bar z\\, w,

        \\mathcal A(p) = \\begin{bmatrix} A & 0 \\\\ p H(p) C & G(p) \\end{bmatrix},\\;
        \\bar C(p) = \\begin{bmatrix} 0 \\\\ H(p) C \\end{bmatrix},\\;
        \\bar B = \\begin{bmatrix} B \\\\ 0 \\end{bmatrix},\\;
        \\bar D = \\begin{bmatrix} D \\\\ 0 \\end{bmatrix},\\; N = [I\\;0].

    Parameters
    ----------
    sys : System
        The plant (1), (2), (6), its sector (3) and the bounds of p(k) (7).
    gains : Gains
        Filter parameters G0, Gf, H0, Hf of (9).
    p : float
        p(k).

    Returns
    -------
    dict
        Keys ``A`` (2n x 2n), ``B`` (2n x nz), ``C`` (2n x n), ``D`` (2n x n), ``N`` (n x 2n).
    """
    n = sys.n
    Ga, Ha = gains.G(p), gains.H(p)
    A_aug = np.block([[sys.A, np.zeros((n, n))], [p * Ha @ sys.C, Ga]])
    C_aug = np.vstack([np.zeros((n, n)), Ha @ sys.C])
    B_aug = np.vstack([sys.B, np.zeros((n, sys.nz))])
    D_aug = np.vstack([sys.D, np.zeros((n, n))])
    return {"A": A_aug, "B": B_aug, "C": C_aug, "D": D_aug, "N": sys.N}


def sector_nonlinearity(z, F1, F2, kind: str = "sine_mid"):
    """A nonlinearity f(z) in the sector [F1, F2] of (3), applied row-wise.

    ``kind``:

    * ``"sine_mid"``: :math:`f(z) = \\tfrac{F_1+F_2}{2} z + \\tfrac{F_2-F_1}{2}\\sin(z)`
      componentwise (diagonal F1, F2). Since :math:`|\\sin z_i| \\le |z_i|`,
      :math:`(f-F_1z)_i (f-F_2z)_i = \\tfrac{(F_2-F_1)_{ii}^2}{4}(\\sin^2 z_i - z_i^2) \\le 0`.
    * ``"lower"`` / ``"upper"``: the linear extremes F1 z, F2 z.

    Parameters
    ----------
    z : ndarray (..., nz)
        Arguments Z x, one per row.
    F1, F2 : ndarray (nz, nz), diagonal
        Sector bounds of (3); only their diagonals are used.
    kind : str
        One of ``"sine_mid"`` (default), ``"lower"``, ``"upper"``.

    Returns
    -------
    ndarray (..., nz)
        f(z).

    Raises
    ------
    GainschedError
        On an unknown ``kind``.
    """
    z = np.asarray(z, dtype=float)
    d1, d2 = np.diag(F1), np.diag(F2)
    if kind == "sine_mid":
        return 0.5 * (d1 + d2) * z + 0.5 * (d2 - d1) * np.sin(z)
    if kind == "lower":
        return d1 * z
    if kind == "upper":
        return d2 * z
    raise GainschedError(f"nonlinearity kind must be 'sine_mid', 'lower' or 'upper', got {kind!r}")


def sector_split(f, z, F1, F2):
    """Decomposition (4) f = F1 z + f_s and the sector value of (5).

    Parameters
    ----------
    f, z : ndarray (..., nz)
        Values of the nonlinearity and its argument.
    F1, F2 : ndarray (nz, nz)
        Sector bounds of (3); F = F2 - F1.

    Returns
    -------
    tuple
        ``(f_s, s)`` with ``f_s = f - F1 z`` and ``s = f_s^T (f_s - F z)``
        (per row), which (5) says is ``<= 0`` for f in the sector [F1, F2].
    """
    z = np.asarray(z, dtype=float)
    fs = np.asarray(f, dtype=float) - z @ F1.T
    s = np.einsum("...i,...i->...", fs, fs - z @ (F2 - F1).T)
    return fs, s


def sector_cases(sys: System) -> dict:
    """Linear sector extremes of (3): every diagonal F with F_ii in {F1_ii, F2_ii}.

    Parameters
    ----------
    sys : System
        The plant (1), (2), (6), its sector (3) and the bounds of p(k) (7).

    Returns
    -------
    dict
        Name (``"F11"``, ``"F12"``, ...; digit i = which bound for z_i) -> diagonal F.
    """
    d1, d2 = np.diag(sys.F1), np.diag(sys.F2)
    cases = {}
    nz = sys.nz
    for mask in range(2 ** nz):
        bits = [(mask >> i) & 1 for i in range(nz)]
        name = "F" + "".join("2" if b else "1" for b in bits)
        cases[name] = np.diag([d2[i] if b else d1[i] for i, b in enumerate(bits)])
    return cases


def p_schedule(k, p1: float, p2: float, omega: float):
    """Scheduling sequence of Section IV: :math:`p(k) = p_1 + (p_2 - p_1)|\\sin(\\omega k)|`.

    The argument of the sine is illegible in the source; ``omega`` is the
    reconstruction (config key ``simulation.sine_omega``).

    Parameters
    ----------
    k : array_like
        Time indices.
    p1, p2 : float
        Bounds of (7).
    omega : float
        Angular frequency of the sine, per time step (radians).

    Returns
    -------
    ndarray
        p(k), same shape as ``k``.
    """
    k = np.asarray(k, dtype=float)
    return p1 + (p2 - p1) * np.abs(np.sin(omega * k))


# ----------------------------------------------------------------------------- Theorem 1
def theorem1_matrix(sys: System, gains: Gains, Q_now, Q_next, S, p: float, multiplier: float = 1.0):
    """The matrix of Theorem 1 (12), evaluated numerically (or as a cvxpy expression).

    .. math::

        \\begin{bmatrix}
        -Q(p(k)) & * & * & * & * \\\\
        FZN & -2I & * & * & * \\\\
        \\Omega_1(k) & S^T\\bar B & -\\Lambda(k) & * & * \\\\
        \\Omega_2(k) & 0 & 0 & -\\Theta(k)\\Lambda(k) & * \\\\
        \\sigma^2 S^T \\bar D N & 0 & 0 & 0 & -\\sigma^2\\Lambda(k)
        \\end{bmatrix} < 0,

    :math:`\\Lambda(k) = -Q(p(k+1)) + S + S^T`, :math:`\\Theta(k) = p(k)(1-p(k))`,
    :math:`\\Omega_1 = S^T(\\mathcal A(p(k)) + \\bar B F_1 Z N)`,
    :math:`\\Omega_2 = \\Theta(k) S^T \\bar C(p(k)) N` (13).

    Parameters
    ----------
    sys : System
        The plant (1), (2), (6), its sector (3) and the bounds of p(k) (7).
    gains : Gains
        Filter parameters G0, Gf, H0, Hf of (9).
    Q_now, Q_next : ndarray or cvxpy expression (2n, 2n)
        Q(p(k)) and Q(p(k+1)).
    S : ndarray or cvxpy expression (2n, 2n)
        The slack variable of (12).
    p : float
        p(k).
    multiplier : float
        The S-procedure multiplier λ > 0 of the sector term (5): the second block row is
        [λ FZN, -2λ I]; 1 as printed in (12) (a free λ is used by the performance designs).

    Returns
    -------
    ndarray or cvxpy expression (8n + nz, 8n + nz)
        The matrix of (12) (a cvxpy ``bmat`` if any argument is a cvxpy expression; not symmetrised).
    """
    aug = augmented(sys, gains, p)
    N = aug["N"]
    theta = p * (1.0 - p)
    s2 = sys.sigma2
    nn, nz = 2 * sys.n, sys.nz
    use_cp = any(type(x).__module__.startswith("cvxpy") for x in (Q_now, Q_next, S))
    T = (lambda X: X.T)
    ST = T(S)  # one transpose shared by the blocks (the same expression tree as transposing each time)
    Lam = -Q_next + S + ST
    Om1 = ST @ (aug["A"] + aug["B"] @ sys.F1 @ sys.Z @ N)
    Om2 = theta * (ST @ aug["C"] @ N)
    SB = ST @ aug["B"]
    SD = s2 * (ST @ aug["D"] @ N)
    FZN = float(multiplier) * (sys.F @ sys.Z @ N)
    O = np.zeros
    rows = [
        [-Q_now, T(FZN), T(Om1), T(Om2), T(SD)],
        [FZN, -2 * float(multiplier) * np.eye(nz), T(SB), O((nz, nn)), O((nz, nn))],
        [Om1, SB, -Lam, O((nn, nn)), O((nn, nn))],
        [Om2, O((nn, nz)), O((nn, nn)), -theta * Lam, O((nn, nn))],
        [SD, O((nn, nz)), O((nn, nn)), O((nn, nn)), -s2 * Lam],
    ]
    if use_cp:
        from ...engines.cvx import cp

        return cp.bmat(rows)
    return np.block(rows)


@dataclass
class Theorem1Result:
    """Outcome of the Theorem 1 test (12) of given gains.

    Parameters
    ----------
    status : str
        Solver status (information).
    margin : float
        Maximised t.
    solver_feasible : bool
        The solver's own opinion (information; the verdict decides).
    Q0, Qp, S : ndarray or None
        The certificate candidate Q(p) = Q0 + p Qp (27) and S.
    n_pairs : int
        Number of (p, p+) pairs imposed.
    verdict : str
        The shared engine's decision on the gridded system (``feasible`` / ``infeasible`` / ``undecided``).
    evidence : str
        What backs the verdict.

    Returns
    -------
    Theorem1Result
    """

    status: str
    margin: float  # maximised t with (12) <= -t I and Q(p) >= t I on the solve pairs
    solver_feasible: bool
    Q0: np.ndarray | None
    Qp: np.ndarray | None
    S: np.ndarray | None
    n_pairs: int
    verdict: str = ""
    evidence: str = ""


def theorem1_lmi(sys: System, gains: Gains, n_grid: int = 3, margin_tol: float = 1e-7, bound: float = 1e3,
                 margin_cap: float = 0.1):
    """Search Q(p) = Q0 + p Qp (27) and S satisfying Theorem 1 (12) for fixed gains.

    (12) is not affine in (p(k), p(k+1)) for fixed gains (p H(p), Theta Lambda),
    so the constraints are imposed on an ``n_grid`` x ``n_grid`` grid of pairs
    that includes the four vertices; :func:`theorem1_grid_check` then checks the
    certificate on a much finer grid. Maximises t subject to (12) <= -t I,
    Q(p) >= t I, t <= ``margin_cap``, with entries of S and Q bounded by
    ``bound`` (scale fixing; an uncapped margin drives the solver to
    ``optimal_inaccurate``).

    Parameters
    ----------
    sys : System
        The plant (1), (2), (6), its sector (3) and the bounds of p(k) (7).
    gains : Gains
        Filter parameters G0, Gf, H0, Hf of (9).
    n_grid : int
        Grid points per axis of (p(k), p(k+1)) in [p1, p2]^2.
    margin_tol : float
        Margin above which an ``optimal`` answer counts as feasible.
    bound : float
        Entry-wise bound on Q0, Qp, S.
    margin_cap : float
        Upper bound on t.

    Returns
    -------
    Theorem1Result
        ``verdict`` is the shared engine's certified decision on the gridded system
        (:mod:`netrepro.engines.certify`); ``solver_feasible`` is the solver's opinion (information).
    """
    from ...engines.certify import CertifiedLMI
    from ...engines.cvx import cp
    from ...engines.cvx import solve_problem

    nn = 2 * sys.n
    Q0 = cp.Variable((nn, nn), symmetric=True, name="Q0")
    Qp = cp.Variable((nn, nn), symmetric=True, name="Qp")
    S = cp.Variable((nn, nn), name="S")
    t = cp.Variable(name="t")
    grid = np.linspace(sys.p1, sys.p2, max(2, n_grid))
    cons = [cp.abs(S) <= bound, cp.abs(Q0) <= bound, cp.abs(Qp) <= bound, t <= margin_cap]
    blocks = []
    # Q(p) of each grid point built once and shared by the blocks that use it (same solver data, less to compile)
    Qs = [Q0 + p * Qp for p in grid]
    for p, Qnow in zip(grid, Qs):
        cons.append(Qnow >> t * np.eye(nn))
        blocks.append((f"Q({p:.4g})", Qnow))
        for pn, Qnext in zip(grid, Qs):
            M = theorem1_matrix(sys, gains, Qnow, Qnext, S, p)
            size = M.shape[0]
            # M is structurally symmetric (upper blocks are transposes of the same expressions, diagonal
            # blocks symmetric): it equals 0.5 (M + M^T) exactly, with half the expression tree to compile
            cons.append(M << -t * np.eye(size))
            blocks.append((f"(12) at ({p:.4g}, {pn:.4g})", -M))
    prob = cp.Problem(cp.Maximize(t), cons)
    certifier = CertifiedLMI(blocks, problem=prob, drop=(t,))
    try:
        solve_problem(prob)
        status = str(prob.status)
    except cp.error.SolverError as exc:  # pragma: no cover - solver failure path
        return Theorem1Result(f"solver_error: {exc}", np.nan, False, None, None, None, len(grid) ** 2)
    margin = float(t.value) if t.value is not None else np.nan
    ok = status == cp.OPTIMAL and margin > margin_tol  # the solver's opinion, kept as information
    def necessary():
        # (12) for all admissible p(k) implies MS stability of (10) for every f in the sector, in particular for
        # constant p and linear f = F z at the sector vertices: the frozen second-moment radius must be < 1
        rho = max(frozen_radius(sys, gains, float(p), F) for p in grid for F in sector_cases(sys).values())
        return rho >= 1.0 + 1e-9, f"frozen second-moment radius of (10) {rho:.12g} >= 1 at a sector vertex"

    v = certifier.certify(status, necessary=necessary)
    if t.value is None:
        return Theorem1Result(status, margin, False, None, None, None, len(grid) ** 2, v.verdict, v.evidence)
    return Theorem1Result(status, margin, ok, Q0.value, Qp.value, S.value, len(grid) ** 2, v.verdict, v.evidence)


def theorem1_grid_check(sys: System, gains: Gains, Q0, Qp, S, n_fine: int = 41, performance: bool = False,
                        multiplier: float = 1.0):
    r"""Largest eigenvalue of (12) and smallest of Q(p) over an ``n_fine`` x ``n_fine`` grid of (p(k), p(k+1)).

    An independent numerical check (no solver) of a Theorem 1 certificate.
    With ``performance`` the (1,1) block carries :math:`+L^TL`, :math:`L = [I\; -I]`
    (the bound :math:`E\Delta V \le -E\|e\|^2` of the performance design).

    Parameters
    ----------
    sys : System
        The plant (1), (2), (6), its sector (3) and the bounds of p(k) (7).
    gains : Gains
        Filter parameters G0, Gf, H0, Hf of (9).
    Q0, Qp, S : ndarray (2n, 2n)
        Certificate of (12), (27).
    n_fine : int
        Grid points per axis.
    performance : bool
        Add L^T L to the (1,1) block.
    multiplier : float
        The S-procedure multiplier λ of the certificate (:func:`theorem1_matrix`; 1 as in (12)).

    Returns
    -------
    tuple of float
        ``(max_eig_12, min_eig_Q, max_eig_at_vertices)``.
    """
    L = np.hstack([np.eye(sys.n), -np.eye(sys.n)])
    grid = np.linspace(sys.p1, sys.p2, n_fine)
    worst, worst_vertex, qmin = -np.inf, -np.inf, np.inf
    for idx, p in enumerate(grid):
        Q_now = Q0 + p * Qp
        qmin = min(qmin, float(np.linalg.eigvalsh(0.5 * (Q_now + Q_now.T)).min()))
        # (12) is affine in p(k+1) (through Q(p(k+1)) in Λ): build it at p+ = 0 and 1, then batch
        M0 = theorem1_matrix(sys, gains, Q_now, Q0, S, p, multiplier)
        M1 = theorem1_matrix(sys, gains, Q_now, Q0 + Qp, S, p, multiplier)
        if performance:
            M0[: 2 * sys.n, : 2 * sys.n] += L.T @ L
            M1[: 2 * sys.n, : 2 * sys.n] += L.T @ L
        Ms = M0[None] + grid[:, None, None] * (M1 - M0)[None]
        eig = np.linalg.eigvalsh(0.5 * (Ms + np.swapaxes(Ms, 1, 2)))[:, -1]
        worst = max(worst, float(eig.max()))
        if idx in (0, len(grid) - 1):
            worst_vertex = max(worst_vertex, float(eig[0]), float(eig[-1]))
    return worst, qmin, worst_vertex


# ----------------------------------------------------------------------------- second moments
def second_moment_operator(sys: System, gains: Gains, p: float, F):
    """Matrices and weights of the second-moment recursion of (10) with f(z) = F z and p(k) = p.

    .. math::

        E\\bar z\\bar z^T(k+1) = M X M^T + p(1-p)\\,\\bar C N X N^T\\bar C^T + \\sigma^2 \\bar D N X N^T \\bar D^T,
        \\quad M = \\mathcal A(p) + \\bar B F Z N .

    Parameters
    ----------
    sys : System
        The plant (1), (2), (6), its sector (3) and the bounds of p(k) (7).
    gains : Gains
        Filter parameters G0, Gf, H0, Hf of (9).
    p : float
        Frozen p(k).
    F : ndarray (nz, nz)
        Linear gain of f(z) = F z (inside the sector).

    Returns
    -------
    tuple
        ``(loops, weights)`` for :func:`netrepro.engines.lmi.second_moment_radius`:
        ``[M, C̄N, D̄N]`` and ``[1, p(1-p), sigma^2]``.
    """
    aug = augmented(sys, gains, p)
    N = aug["N"]
    M = aug["A"] + aug["B"] @ F @ sys.Z @ N
    return [M, aug["C"] @ N, aug["D"] @ N], [1.0, p * (1.0 - p), sys.sigma2]


def frozen_radius(sys: System, gains: Gains, p: float, F) -> float:
    """Spectral radius of the second-moment operator of (10) at frozen p and linear f = F z (< 1: MS stable).

    Parameters
    ----------
    sys : System
        The plant (1), (2), (6), its sector (3) and the bounds of p(k) (7).
    gains : Gains
        Filter parameters G0, Gf, H0, Hf of (9).
    p : float
        Frozen p(k) = p(k+1) = p.
    F : ndarray (nz, nz)
        Linear gain of f(z) = F z (inside the sector).

    Returns
    -------
    float
        The spectral radius.
    """
    from ...engines.lmi import second_moment_radius

    loops, weights = second_moment_operator(sys, gains, p, F)
    return second_moment_radius(loops, weights)


def scheduled_growth_rate(sys: System, gains: Gains, p_seq, F) -> float:
    """Per-step growth rate of E||z(k)||^2 along a given p(k) sequence (f = F z, worst initial second moment).

    Product of the second-moment operators :math:`\\mathcal L_{p(k)} = M\\otimes M + p(1-p) \\bar CN\\otimes\\bar CN
    + \\sigma^2 \\bar DN\\otimes\\bar DN`, normalised each step; returns
    :math:`(\\|\\mathcal L_{p(K-1)}\\cdots\\mathcal L_{p(0)}\\|_2)^{1/K}`.

    Parameters
    ----------
    sys : System
        The plant (1), (2), (6), its sector (3) and the bounds of p(k) (7).
    gains : Gains
        Filter parameters G0, Gf, H0, Hf of (9).
    p_seq : array_like (K,)
        p(0..K-1).
    F : ndarray (nz, nz)
        Linear gain of f(z) = F z (inside the sector).

    Returns
    -------
    float
        The geometric-mean growth factor per step (< 1: E||z(k)||^2 decays).
    """
    nn = 2 * sys.n
    prod = np.eye(nn * nn)
    log_scale = 0.0
    for p in np.asarray(p_seq, dtype=float):
        loops, weights = second_moment_operator(sys, gains, float(p), F)
        op = sum(w * np.kron(L, L) for L, w in zip(loops, weights))
        prod = op @ prod
        s = np.linalg.norm(prod, 2)
        log_scale += np.log(s)
        prod /= s
    return float(np.exp(log_scale / len(p_seq)))


# ----------------------------------------------------------------------------- simulation
def simulate(sys: System, gains: Gains | None, p_seq, x0, rng: np.random.Generator, nonlinearity: str = "sine_mid",
             xf0=None):
    """Monte Carlo of plant (1), (6) and filter (8) under Algorithm 1, vectorised over runs.

    Each step draws xi(k) ~ Bernoulli(p(k)) (7) and w(k) ~ N(0, sigma^2), then

    .. math::

        x(k+1) = A x + B f(Zx) + D x w,\\quad y = \\xi C x,\\quad
        x_f(k+1) = G(p(k)) x_f + H(p(k)) y .

    Parameters
    ----------
    sys : System
        The plant (1), (2), (6), its sector (3) and the bounds of p(k) (7).
    gains : Gains or None
        ``None`` is the trivial estimate x_f = 0.
    p_seq : ndarray (K,)
        p(0..K-1); the result has K+1 time points.
    x0 : ndarray (runs, n)
        Initial states.
    rng : numpy.random.Generator
        Source of the draws, in the order of :func:`draw_noise`.
    nonlinearity : str
        Kind of :func:`sector_nonlinearity`.
    xf0 : ndarray (n,) or None
        Initial filter state (default 0); ignored for the trivial estimate.

    Returns
    -------
    ndarray (runs, K+1, n)
        The estimation errors e(k) = x(k) - x_f(k).
    """
    x = np.array(x0, dtype=float, copy=True)
    if x.ndim != 2 or x.shape[1] != sys.n:
        raise GainschedError(f"x0 must have shape (runs, {sys.n}), got {x.shape}")
    runs = x.shape[0]
    p_seq = np.asarray(p_seq, dtype=float)
    xf = np.zeros_like(x)
    if xf0 is not None and gains is not None:
        xf = xf + np.asarray(xf0, dtype=float)
    errs = np.empty((runs, len(p_seq) + 1, sys.n))
    errs[:, 0] = x - xf
    sd = np.sqrt(sys.sigma2)
    u, g = draw_noise(rng, len(p_seq), runs)
    for k, p in enumerate(p_seq):
        xi = (u[k] < p).astype(float)
        w = sd * g[k]
        y = xi[:, None] * (x @ sys.C.T)
        if gains is not None:
            xf = xf @ gains.G(p).T + y @ gains.H(p).T
        f = sector_nonlinearity(x @ sys.Z.T, sys.F1, sys.F2, nonlinearity)
        x = x @ sys.A.T + f @ sys.B.T + w[:, None] * (x @ sys.D.T)
        errs[:, k + 1] = x - xf
    return errs


def draw_noise(rng: np.random.Generator, n_steps: int, runs: int):
    """The draws of :func:`simulate` in its order: per step ``rng.random(runs)`` (xi of (7)), then ``rng.standard_normal(runs)``.

    Parameters
    ----------
    rng : numpy.random.Generator
        Source of the draws.
    n_steps : int
        K, the length of p(0..K-1).
    runs : int
        Number of Monte Carlo runs.

    Returns
    -------
    tuple of ndarray (K, runs)
        ``(u, g)``: xi(k) = [u(k) < p(k)], w(k) = sigma g(k).
    """
    u, g = np.empty((n_steps, runs)), np.empty((n_steps, runs))
    for k in range(n_steps):
        u[k] = rng.random(runs)
        g[k] = rng.standard_normal(runs)
    return u, g


def simulate_draws(sys: System, gains: Gains | None, p_seq, x0, draws, nonlinearity: str = "sine_mid", xf0=None):
    """:func:`simulate` with the random draws given (:func:`draw_noise`), by the compiled kernel of :mod:`.kernels`.

    Same recursion (1), (6), (8)-(9) and the same rounding as :func:`simulate` (the numpy
    reference): bit-identical with it for the draws of ``rng`` when ``runs >= 7`` on the reference
    platform (within rounding elsewhere). Common random numbers (the Nelder-Mead cost of
    :mod:`.tuning`) draw once and call this per evaluation.

    Parameters
    ----------
    sys : System
        The plant (1), (2), (6), its sector (3) and the bounds of p(k) (7).
    gains : Gains or None
        Filter (9); ``None`` is the trivial estimate x_f = 0.
    p_seq : ndarray (K,)
        p(0..K-1); the result has K+1 time points.
    x0 : ndarray (runs, n)
        Initial states.
    draws : tuple of ndarray (K, runs)
        ``(u, g)`` of :func:`draw_noise`.
    nonlinearity : str
        Kind of :func:`sector_nonlinearity`.
    xf0 : ndarray (n,) or None
        Initial filter state (default 0); ignored for the trivial estimate.

    Returns
    -------
    ndarray (runs, K+1, n)
        The estimation errors e(k) = x(k) - x_f(k).
    """
    from .kernels import KINDS, simulate_kernel, simulate_kernel_2x1

    x = np.ascontiguousarray(np.array(x0, dtype=float))
    if x.ndim != 2 or x.shape[1] != sys.n:
        raise GainschedError(f"x0 must have shape (runs, {sys.n}), got {x.shape}")
    if nonlinearity not in KINDS:
        raise GainschedError(f"nonlinearity kind must be 'sine_mid', 'lower' or 'upper', got {nonlinearity!r}")
    p_seq = np.ascontiguousarray(p_seq, dtype=float)
    u, g = (np.ascontiguousarray(d, dtype=float) for d in draws)
    if u.shape != (len(p_seq), x.shape[0]) or g.shape != u.shape:
        raise GainschedError(f"draws must have shape {(len(p_seq), x.shape[0])}")
    xf = np.zeros_like(x)
    if xf0 is not None and gains is not None:
        xf = xf + np.asarray(xf0, dtype=float)
    gg = gains if gains is not None else zero_gains(sys)
    c = np.ascontiguousarray
    # the paper's shapes (2 states, 1 output, 2 channels of f): the same recursion written out, the same numbers
    kernel = simulate_kernel_2x1 if (sys.n, sys.m, sys.nz) == (2, 1, 2) else simulate_kernel
    return kernel(c(sys.A), c(sys.B), c(sys.C), c(sys.D), c(sys.Z), np.diag(sys.F1).copy(),
                  np.diag(sys.F2).copy(), KINDS[nonlinearity], c(gg.G0, dtype=float), c(gg.Gf, dtype=float),
                  c(gg.H0, dtype=float), c(gg.Hf, dtype=float), gains is not None, p_seq, x,
                  np.ascontiguousarray(xf), u, g, float(np.sqrt(sys.sigma2)))


# ----------------------------------------------------------------------------- helpers of the steps
def zero_gains(sys: System) -> Gains:
    """All-zero gains of (9): the trivial estimate x_f = 0.

    Parameters
    ----------
    sys : System
        The plant (sets the shapes n x n and n x m).

    Returns
    -------
    Gains
        G0 = Gf = 0 (n x n), H0 = Hf = 0 (n x m).
    """
    return Gains(np.zeros((sys.n, sys.n)), np.zeros((sys.n, sys.n)), np.zeros((sys.n, sys.m)),
                 np.zeros((sys.n, sys.m)))


def realisation(gains: Gains, J) -> Gains:
    """The filter (9) in the state coordinates x_f' = J x_f: G' = J G J^{-1}, H' = J H.

    Algorithm 1 recovers the gains by (26) with any nonsingular S21, S22; two choices differ by
    such a J (= S22^{-1} S21 relative to S21 = S22), with the same Lyapunov certificate of (24)
    after the congruence diag(I, J^{-T}) of Q. Stability is unchanged, but the estimate
    x_f' differs, so the estimation error e = x - x_f' does. J = -I (H -> -H, G unchanged) is
    the opposite sign of the filter state.

    Parameters
    ----------
    gains : Gains
        The filter gains G0, Gf, H0, Hf of (9) in the original coordinates.
    J : array_like (n, n)
        Nonsingular.

    Returns
    -------
    Gains
        The same filter in the coordinates x_f' = J x_f.

    Raises
    ------
    GainschedError
        If J is not square of the filter's order or is singular.
    """
    J = np.asarray(J, dtype=float)
    n = gains.G0.shape[0]
    if J.shape != (n, n):
        raise GainschedError(f"realisation: J must be {n}x{n}, got shape {J.shape}")
    cond = np.linalg.cond(J)
    if not np.isfinite(cond) or cond > 1e12:
        raise GainschedError(f"realisation: J is singular (condition number {cond:.3g})")
    Jinv = np.linalg.inv(J)
    return Gains(J @ gains.G0 @ Jinv, J @ gains.Gf @ Jinv, J @ gains.H0, J @ gains.Hf)


def augmented_initial_moment(cov, n: int):
    """Second moment E z̄(0) z̄(0)^T of the augmented state (10) for E x0 x0^T = ``cov`` and x_f(0) = 0.

    Parameters
    ----------
    cov : array_like (n, n)
        Second moment of x(0).
    n : int
        Plant order.

    Returns
    -------
    ndarray (2n, 2n)
        ``[[cov, 0], [0, 0]]``.
    """
    cov = np.asarray(cov, dtype=float)
    X0 = np.zeros((2 * n, 2 * n))
    X0[:n, :n] = cov  # x_f(0) = 0
    return X0


def lyapunov_difference_bounds(sys: System, gains: Gains, Q0, Qp, p: float, pn: float, zbar, f):
    """E{ΔV} of (14) for given z̄ and f, and the right sides of (15) with '-' (corrected) and '+' (printed).

    With V = z̄^T Q(p) z̄, Q(p) = Q0 + p Qp (27),

    .. math::

        E\\{\\Delta V\\} = (\\mathcal A\\bar z + \\bar B f)^T Q^+ (\\cdot) + p(1-p)\\,\\bar z^T N^T\\bar C^T Q^+ \\bar C N\\bar z
        + \\sigma^2 \\bar z^T N^T\\bar D^T Q^+\\bar D N\\bar z - \\bar z^T Q \\bar z,

    and (15) subtracts :math:`2 f_s^T(f_s \\mp FZN\\bar z)` (sector term (5)).

    Parameters
    ----------
    sys : System
        The plant (1), (2), (6), its sector (3) and the bounds of p(k) (7).
    gains : Gains
        Filter parameters G0, Gf, H0, Hf of (9).
    Q0, Qp : ndarray (2n, 2n)
        The Lyapunov matrix Q(p) = Q0 + p Qp of (27).
    p, pn : float
        p(k) and p(k+1).
    zbar : ndarray (R, 2n)
        Augmented states, one per row.
    f : ndarray (R, nz)
        Values f(Z N z̄) of the nonlinearity, one per row.

    Returns
    -------
    tuple of ndarray (R,)
        ``(dv, corrected, printed)``: E{ΔV} and the two right sides of (15).
    """
    aug = augmented(sys, gains, p)
    N = aug["N"]
    Qn, Qc = Q0 + pn * Qp, Q0 + p * Qp
    nxt = zbar @ aug["A"].T + f @ aug["B"].T
    CN, DN = aug["C"] @ N, aug["D"] @ N
    quad = lambda X, M: np.einsum("ri,ij,rj->r", X, M, X)  # noqa: E731
    dv = (quad(nxt, Qn) + p * (1 - p) * quad(zbar @ CN.T, Qn) + sys.sigma2 * quad(zbar @ DN.T, Qn)
          - quad(zbar, Qc))
    z = zbar @ (sys.Z @ N).T
    fs, _ = sector_split(f, z, sys.F1, sys.F2)
    Fz = z @ sys.F.T
    corrected = dv - 2 * np.einsum("ri,ri->r", fs, fs - Fz)
    printed = dv - 2 * np.einsum("ri,ri->r", fs, fs + Fz)
    return dv, corrected, printed
