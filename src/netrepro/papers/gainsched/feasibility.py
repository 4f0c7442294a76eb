r"""Certified feasibility for the `gainsched` LMIs: the plant LMI, the necessary condition, sigma^2 brackets.

Every decision goes through the shared solve-and-certify engine
(:mod:`netrepro.engines.certify`, issue 16 section 1) and is never read off a solver status:

``feasible``
    The returned point satisfies every block strictly by the engine's own eigenvalue check
    (margin: eigensolver backward error plus the rounding of evaluating the blocks).
``infeasible``
    A checked dual certificate of the engine, or the independent necessary condition of this
    module: any of Theorems 1-3 (and the plant LMI) implies that (10) (resp. the plant (1)) is
    mean-square stable for every f in the sector (3), in particular for every linear f = K z
    whose gain K meets (3); so if the plant's second-moment operator
    :math:`\mathcal L_K = (A+BKZ)\otimes(A+BKZ) + \sigma^2 D\otimes D` has spectral radius
    :math:`\ge 1 + 10^{-9}` for such a K (a 4 x 4 eigenvalue problem of a nonnegative operator,
    computed to about 1e-15, radius nondecreasing in sigma^2), no certificate exists. The gains
    searched are the worst of :func:`worst_sector_gain` (K = (F1+F2)/2 + U(F2-F1)/2, U orthogonal,
    which meets (3) with equality) and the diagonal vertices of :func:`.model.sector_cases`.
``undecided``
    Neither: recorded, never counted either way.

Two classes of nonlinearities are told apart (issue 27):

* the paper's class, condition (3): one vector inequality
  :math:`[f - F_1 z]^T[f - F_2 z] \le 0`. It admits coupled gains; for it the plant's
  quadratic-Lyapunov limit is the *scalar*-multiplier LMI (:class:`PlantLMI`,
  ``multiplier="scalar"``): the S-procedure is lossless for one quadratic constraint
  (Yakubovich 1971; Boyd, El Ghaoui, Feron, Balakrishnan 1994, section 2.6.3);
* componentwise sectors: each :math:`f_i` in its own sector :math:`[F_{1,ii}, F_{2,ii}]`, for
  which a diagonal multiplier is valid (``multiplier="diagonal"``), with the diagonal vertices
  as its necessary condition.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from .model import System, sector_cases

__all__ = [
    "RADIUS_MARGIN",
    "sector_gain",
    "linear_gain_radius",
    "linear_gain_limit",
    "worst_sector_gain",
    "sector_class_radius",
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
        The plant.
    sigma2 : float
        The new variance of w(k) of (1).

    Returns
    -------
    System
        A copy of ``sys`` with ``sigma2`` replaced.
    """
    return dataclasses.replace(sys, sigma2=float(sigma2))


def sector_gain(sys: System, U) -> np.ndarray:
    """The linear gain K = (F1 + F2)/2 + U (F2 - F1)/2 of condition (3) for an orthogonal U.

    With F = F2 - F1, K - F1 = (I + U) F/2 and K - F2 = (U - I) F/2, so
    :math:`(K - F_1)^T (K - F_2) = F (U - U^T) F / 4` is skew-symmetric: f(z) = K z meets (3)
    with equality for every z. For U = diag(+-1) K is a vertex of the diagonal sector.

    Parameters
    ----------
    sys : System
        The plant (1), (2), (6) with its sector (3), noise variance and bounds of p(k).
    U : array_like (..., nz, nz)
        Orthogonal matrices (a stack is allowed).

    Returns
    -------
    ndarray (..., nz, nz)
        The linear gains K, one per U.
    """
    U = np.asarray(U, dtype=float)
    return 0.5 * (sys.F1 + sys.F2) + U @ (0.5 * sys.F)


def linear_gain_radius(sys: System, K, sigma2: float):
    """Spectral radius of the plant's second-moment operator with f = K z (1), for one gain or a stack.

    .. math:: \\rho\\big((A + BKZ)\\otimes(A + BKZ) + \\sigma^2 D\\otimes D\\big)

    is below 1 iff x(k+1) = (A + BKZ) x + w D x is exponentially mean-square stable.

    Parameters
    ----------
    sys : System
        The plant (1), (2), (6) with its sector (3), noise variance and bounds of p(k).
    K : array_like (..., nz, nz)
        Linear gains of f(z) = K z (a stack is allowed).
    sigma2 : float
        Variance of the multiplicative noise w(k) of (1) (replaces ``sys.sigma2``).

    Returns
    -------
    float or ndarray (...)
        The spectral radius, one per gain (a float for a single gain).
    """
    K = np.asarray(K, dtype=float)
    AK = sys.A + sys.B @ K @ sys.Z
    n = sys.n
    op = (AK[..., :, None, :, None] * AK[..., None, :, None, :]).reshape(K.shape[:-2] + (n * n, n * n))
    op = op + float(sigma2) * np.kron(sys.D, sys.D)
    rho = np.max(np.abs(np.linalg.eigvals(op)), axis=-1)
    return float(rho) if K.ndim == 2 else rho


def linear_gain_limit(sys: System, K):
    """The sigma^2 at which :func:`linear_gain_radius` reaches 1, in closed form (one gain or a stack).

    For the nonnegative (cone-preserving) operators :math:`\\mathcal A = A_K\\otimes A_K` and
    :math:`\\mathcal D = D\\otimes D`, :math:`\\rho(\\mathcal A + s\\mathcal D) < 1` iff
    :math:`\\rho(\\mathcal A) < 1` and :math:`s\\,\\rho((I - \\mathcal A)^{-1}\\mathcal D) < 1`
    (Perron-Frobenius for positive operators, as for the mean-square stability of systems with
    multiplicative noise; Boyd et al. 1994, section 9.1.1). So the limit is
    :math:`1/\\rho((I - \\mathcal A)^{-1}\\mathcal D)`.

    Parameters
    ----------
    sys : System
        The plant (1), (2), (6) with its sector (3), noise variance and bounds of p(k). Its own ``sigma2``
        is not used.
    K : array_like (..., nz, nz)
        Linear gains of f(z) = K z (a stack is allowed).

    Returns
    -------
    float or ndarray (...)
        0 where :math:`\\rho(\\mathcal A) \\ge 1`; inf where the noise never destabilises.
    """
    K = np.asarray(K, dtype=float)
    AK = sys.A + sys.B @ K @ sys.Z
    n = sys.n
    A2 = (AK[..., :, None, :, None] * AK[..., None, :, None, :]).reshape(K.shape[:-2] + (n * n, n * n))
    stable = np.max(np.abs(np.linalg.eigvals(A2)), axis=-1) < 1.0
    M = np.linalg.solve(np.eye(n * n) - A2, np.broadcast_to(np.kron(sys.D, sys.D), A2.shape))
    r = np.max(np.abs(np.linalg.eigvals(M)), axis=-1)
    with np.errstate(divide="ignore"):
        out = np.where(stable, np.where(r > 0, 1.0 / np.where(r > 0, r, 1.0), np.inf), 0.0)
    return float(out) if K.ndim == 2 else out


def _orthogonal_2x2(theta, reflect: bool) -> np.ndarray:
    """Rotations [[c, -s], [s, c]] (reflect False) or reflections [[c, s], [s, -c]] for angles ``theta``."""
    c, s = np.cos(theta), np.sin(theta)
    if reflect:
        return np.stack([np.stack([c, s], -1), np.stack([s, -c], -1)], -2)
    return np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2)


def worst_sector_gain(sys: System, sigma2: float | None = None, n_grid: int = 720) -> dict:
    """The worst linear gain K = (F1+F2)/2 + U(F2-F1)/2, U in O(2), for the plant's mean-square stability.

    Every such K meets condition (3) (:func:`sector_gain`), so a K whose second-moment radius
    reaches 1 shows that the plant is not mean-square stable for some f of the paper's class
    (that linear one): a necessary condition. O(2) is two circles (rotations and reflections by an angle); each is
    searched on ``n_grid`` angles (the diagonal vertices U = diag(+-1) among them), then refined
    around the best angle by a bounded scalar minimisation. Any K found is valid; the search only
    decides how strong the condition is.

    Parameters
    ----------
    sys : System
        With nz = 2 (the example).
    sigma2 : float or None
        Maximise the radius at this sigma^2; None: minimise :func:`linear_gain_limit`.
    n_grid : int
        Angles per circle, a multiple of 4 (so that the diagonal vertices are on the grid).

    Returns
    -------
    dict
        ``K``, ``U``, ``theta``, ``reflect`` and ``value`` (the radius, or the limit sigma^2).

    Raises
    ------
    GainschedError
        If nz != 2 or ``n_grid`` is not a positive multiple of 4.
    """
    from scipy.optimize import minimize_scalar

    from .model import GainschedError

    if sys.nz != 2:
        raise GainschedError(f"worst_sector_gain searches O(2): needs nz = 2, got nz = {sys.nz}")
    if n_grid < 4 or n_grid % 4:
        raise GainschedError(f"worst_sector_gain: n_grid must be a positive multiple of 4, got {n_grid}")
    if sigma2 is None:
        def cost(theta, reflect):
            return linear_gain_limit(sys, sector_gain(sys, _orthogonal_2x2(theta, reflect)))
    else:
        def cost(theta, reflect):
            return -linear_gain_radius(sys, sector_gain(sys, _orthogonal_2x2(theta, reflect)), sigma2)
    thetas = 2 * np.pi * np.arange(n_grid) / n_grid
    best = None
    step = 2 * np.pi / n_grid
    for reflect in (False, True):
        Ks = sector_gain(sys, _orthogonal_2x2(thetas, reflect))
        vals = linear_gain_limit(sys, Ks) if sigma2 is None else -linear_gain_radius(sys, Ks, sigma2)
        i = int(np.argmin(vals))
        res = minimize_scalar(lambda t, r=reflect: cost(t, r), bounds=(thetas[i] - step, thetas[i] + step),
                              method="bounded", options={"xatol": 1e-12})
        theta, val = (float(res.x), float(res.fun)) if res.fun < vals[i] else (float(thetas[i]), float(vals[i]))
        if best is None or val < best[2]:
            best = (theta, reflect, val)
    theta, reflect, val = best
    U = _orthogonal_2x2(theta, reflect)
    return {"K": sector_gain(sys, U), "U": U, "theta": theta, "reflect": reflect,
            "value": val if sigma2 is None else -val}


def sector_class_radius(sys: System, sigma2: float) -> float:
    """Largest plant second-moment radius over the linear gains searched for the paper's class (3).

    The diagonal vertices of :func:`.model.sector_cases` (:func:`plant_vertex_radius`) and, for
    nz = 2, the worst K of :func:`worst_sector_gain` at this sigma^2. Every gain meets (3), so
    a value >= 1 means the plant is not mean-square stable for some f of the class.

    Parameters
    ----------
    sys : System
        The plant (1), (2), (6) with its sector (3), noise variance and bounds of p(k). The search over O(2)
        is made only when nz = 2.
    sigma2 : float
        Variance of the multiplicative noise w(k) of (1) at which the radius is computed.

    Returns
    -------
    float
        The largest radius found; >= 1 means the class (3) holds an f that is not mean-square stable.
    """
    rho = plant_vertex_radius(sys, sigma2)
    if sys.nz == 2:
        rho = max(rho, worst_sector_gain(sys, sigma2)["value"])
    return float(rho)


def plant_vertex_radius(sys: System, sigma2: float) -> float:
    """max over diagonal sector vertices F of rho((A+BFZ) (x) (A+BFZ) + sigma^2 D (x) D), plant (1).

    Parameters
    ----------
    sys : System
        The plant (1), (2), (6) and its sector (3) (its ``sigma2`` is replaced where a ``sigma2`` is given).
    sigma2 : float
        Variance of the multiplicative noise w(k) of (1).

    Returns
    -------
    float
        The largest spectral radius (>= 1: no quadratic mean-square decay at some vertex).
    """
    rho = 0.0
    for F in sector_cases(sys).values():
        AF = sys.A + sys.B @ F @ sys.Z
        op = np.kron(AF, AF) + float(sigma2) * np.kron(sys.D, sys.D)
        rho = max(rho, float(np.max(np.abs(np.linalg.eigvals(op)))))
    return rho


def _radius_function(sector: str):
    """The plant radius of a class: ``"condition3"`` (:func:`sector_class_radius`) or ``"componentwise"``."""
    from .model import GainschedError

    if sector == "condition3":
        return sector_class_radius, "worst sector-gain second-moment radius (class (3))"
    if sector == "componentwise":
        return plant_vertex_radius, "plant vertex second-moment radius"
    raise GainschedError(f"sector must be 'condition3' or 'componentwise', got {sector!r}")


def plant_necessary_fails(sys: System, sigma2: float, sector: str = "condition3") -> bool:
    """True when the necessary condition for mean-square stability under the sector fails (certified).

    Parameters
    ----------
    sys : System
        The plant (1), (2), (6) and its sector (3) (its ``sigma2`` is replaced where a ``sigma2`` is given).
    sigma2 : float
        Variance of the multiplicative noise w(k) of (1).
    sector : {"condition3", "componentwise"}
        The paper's class (3) (:func:`sector_class_radius`) or componentwise sectors
        (:func:`plant_vertex_radius`).

    Returns
    -------
    bool
        ``radius >= 1 + RADIUS_MARGIN`` (the plant is not mean-square stable for some f of the class).
    """
    radius, _ = _radius_function(sector)
    return radius(sys, sigma2) >= 1.0 + RADIUS_MARGIN


def necessary_condition(sys: System, sigma2: float, sector: str = "condition3"):
    """The necessary condition as the engine's callable ``() -> (violated, evidence)``.

    Parameters
    ----------
    sys : System
        The plant (1), (2), (6) and its sector (3) (its ``sigma2`` is replaced where a ``sigma2`` is given).
    sigma2 : float
        Variance of the multiplicative noise w(k) of (1).
    sector : {"condition3", "componentwise"}
        Which class the criterion is for (Theorems 1-3: the paper's class (3)).

    Returns
    -------
    callable
        ``violated`` is :func:`plant_necessary_fails`; the evidence names the radius.
    """
    radius, label = _radius_function(sector)

    def check():
        rho = radius(sys, sigma2)
        return rho >= 1.0 + RADIUS_MARGIN, f"{label} {rho:.12g} at sigma2 = {sigma2:.12g}"

    return check


class PlantLMI:
    """Lyapunov-S-procedure LMI for the plant (1) alone under a sector condition (3)-(5).

    With V = x^T P x and f = F1 Z x + f_s, E V(x+) - V(x) - 2 f_s^T L (f_s - F Z x) < 0 for a
    multiplier L >= 0 reads

    .. math::

        \\begin{bmatrix} A_1^T P A_1 + \\sigma^2 D^T P D - P & A_1^T P B + Z^T F L \\\\
        B^T P A_1 + L F Z & B^T P B - 2L \\end{bmatrix} \\prec 0,\\quad P \\succ 0,\\quad A_1 = A + B F_1 Z.

    ``multiplier="scalar"`` (L = lambda I): f_s^T (f_s - F Z x) <= 0 is condition (5), i.e. the
    paper's class (3); with one quadratic constraint the S-procedure is lossless (Yakubovich
    1971; Boyd, El Ghaoui, Feron, Balakrishnan 1994, section 2.6.3), so this LMI is feasible iff
    a quadratic V decreases for every f of the class: the plant's own limit for (3) with a
    quadratic Lyapunov function. ``multiplier="diagonal"`` (L diagonal) is valid only when each
    component f_i satisfies its own sector (componentwise sectors), a smaller class.
    Either way E V decreases geometrically: the plant is exponentially mean-square stable for
    every f of the class. Built once with sigma^2 a parameter; decided by
    :class:`netrepro.engines.certify.CertifiedLMI` (blocks: the matrix, P and the entries of L,
    all strict), with the necessary condition of the same class.

    Parameters
    ----------
    sys : System
        The plant (1), (2), (6) and its sector (3) (its ``sigma2`` is replaced where a ``sigma2`` is given).
    margin_cap : float
        The solver maximises t (blocks <= -t I, P >= t I, L >= t) with t <= margin_cap.
    bound : float
        Entry-wise bound on P and L (scale fixing; not part of the question).
    multiplier : {"scalar", "diagonal"}
        The S-procedure multiplier: class (3), or componentwise sectors.

    Returns
    -------
    PlantLMI

    Raises
    ------
    GainschedError
        On an unknown ``multiplier``.
    """

    def __init__(self, sys: System, margin_cap: float = 0.1, bound: float = 100.0, multiplier: str = "scalar"):
        from ...engines.certify import CertifiedLMI
        from ...engines.cvx import cp
        from .model import GainschedError

        if multiplier not in ("scalar", "diagonal"):
            raise GainschedError(f"PlantLMI multiplier must be 'scalar' or 'diagonal', got {multiplier!r}")
        self.sys = sys
        self.multiplier = multiplier
        self.sector = "condition3" if multiplier == "scalar" else "componentwise"
        n, nz = sys.n, sys.nz
        self.sigma2 = cp.Parameter(nonneg=True, value=sys.sigma2, name="sigma2")
        self.P = cp.Variable((n, n), symmetric=True, name="P")
        self.lam = cp.Variable(1 if multiplier == "scalar" else nz, name="lambda")
        L = self.lam[0] * np.eye(nz) if multiplier == "scalar" else cp.diag(self.lam)
        self.t = cp.Variable(name="t")
        M = self.matrix(self.P, L, self.sigma2)
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
        from ...engines.cvx import cp

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
        return self.certifier.solve(necessary=necessary_condition(self.sys, sigma2, self.sector))


def necessary_limit(sys: System, lo: float, hi: float, tol: float = 1e-6, sector: str = "condition3") -> tuple:
    """Bracket of the sigma^2 where the plant's second-moment radius of a class reaches 1 + RADIUS_MARGIN.

    The radius of each linear gain is nondecreasing in sigma^2 (the operator is a nonnegative
    combination of positive maps), and so is a maximum over gains: plain bisection applies.

    Parameters
    ----------
    sys : System
        The plant (1), (2), (6) and its sector (3) (its ``sigma2`` is replaced where a ``sigma2`` is given).
    lo, hi : float
        The radius must be below the threshold at ``lo`` and at or above it at ``hi``.
    tol : float
        Stop when the bracket is narrower than ``tol``.
    sector : {"condition3", "componentwise"}
        The class whose linear gains are searched (see :func:`plant_necessary_fails`).

    Returns
    -------
    tuple of float
        ``(below, above)``: necessary condition holds at ``below``, fails (certified infeasible) at ``above``;
        ``(nan, nan)`` if ``hi`` does not reach the threshold.
    """
    if not plant_necessary_fails(sys, hi, sector):
        return np.nan, np.nan
    a, b = float(lo), float(hi)
    while b - a > tol:
        mid = 0.5 * (a + b)
        if plant_necessary_fails(sys, mid, sector):
            b = mid
        else:
            a = mid
    return a, b
