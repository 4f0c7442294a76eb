r"""Certified LMI decisions: every verdict is checked in numpy, never read off a solver status.

A system of linear matrix inequalities in the variables :math:`u \in \mathbb R^m`

.. math::

    F_j(u) = F_{j0} + \sum_{i=1}^m u_i F_{ji} \succ 0, \qquad j = 1, \dots, J,

is decided as one of three verdicts:

``feasible``
    The returned point :math:`\hat u` satisfies every block strictly, checked by our own
    eigenvalue computation (numpy, symmetrised, float64): for every block
    :math:`\lambda_{\min}(\mathrm{sym} \hat F_j) > \tau_j` with the margin
    :math:`\tau_j = c\, n_j \varepsilon \|\hat F_j\|_F + \gamma_{m+2} \|\, |F_{j0}| + \sum_i |\hat u_i| |F_{ji}|\,\|_F
    + \varepsilon \|\hat F_j\|_F`
    (``c = safety``, 10 by default; :math:`\varepsilon` the float64 unit roundoff,
    :math:`\gamma_k = k\varepsilon/(1 - k\varepsilon)`). The first term bounds the backward error of LAPACK's
    symmetric eigensolver (computed eigenvalues are exact for a matrix within
    :math:`p(n)\varepsilon\|F\|_2` of the one given, :math:`p(n)` a modest function of ``n``;
    Demmel, *Applied Numerical Linear Algebra*, 5.2), the second the rounding of evaluating
    :math:`F_j(\hat u)` itself, the third the symmetrisation. The solver's status plays no part.
    The point is the float64 variable values as returned; the data are the float64
    coefficients as cvxpy builds them.
``infeasible``
    Backed by a certificate checked in numpy: a dual (theorem-of-alternatives) certificate,
    see :func:`check_dual_certificate`, or a caller-supplied independent necessary condition
    that fails, see :meth:`CertifiedLMI.certify`.
``undecided``
    Neither holds. Recorded, never counted either way.

The coefficient matrices :math:`F_{ji}` are extracted from the cvxpy expressions with cvxpy's
own canonicalisation (the sparse parameter-to-coefficient tensor it compiles for DPP
problems), once per system: each later call only multiplies that tensor by the current
parameter values, so a sweep keeps the "build once, update parameters" speed of the problem
it certifies. Symmetric variables count their independent entries once. The tensor comes from
``cvxpy.cvxcore.python.canonInterface.get_problem_matrix``, an internal cvxpy function (the one
cvxpy's own DPP and gradient code call); ``tests/engines/test_certify.py`` checks the extracted
coefficients against the expressions' values, so a cvxpy upgrade that changes it fails there.

The rounding-error bounds are the standard a priori bounds of floating-point error analysis
(Higham, *Accuracy and Stability of Numerical Algorithms*, 3.1 and 3.5), not interval
arithmetic; every bound used is stated where it is used.
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np
import scipy.sparse as sp

from ..errors import LMIError

__all__ = [
    "FEASIBLE",
    "INFEASIBLE",
    "UNDECIDED",
    "LMICoefficients",
    "PointCheck",
    "DualCertificate",
    "DualCheck",
    "Verdict",
    "CertifiedLMI",
    "check_point",
    "check_dual_certificate",
    "find_dual_certificate",
    "CertifiedBracket",
    "bisect_certified",
]

FEASIBLE = "feasible"
INFEASIBLE = "infeasible"
UNDECIDED = "undecided"
EPS = float(np.finfo(float).eps) / 2.0  # unit roundoff of float64


def _gamma(k: float) -> float:
    """:math:`\\gamma_k = k u / (1 - k u)`, the relative error bound of a sum or dot product of length ``k``."""
    return k * EPS / (1.0 - k * EPS)


# ----------------------------------------------------------------------------- coefficients
@dataclass
class LMICoefficients:
    r"""The affine data :math:`F_j(u) = F_{j0} + \sum_i u_i F_{ji}` of a system of LMI blocks.

    Attributes
    ----------
    F0 : list of ndarray (n_j, n_j)
        The constant terms, one per block.
    F : list of ndarray (m, n_j, n_j)
        The coefficient of each independent variable coordinate, one stack per block.
    names : list of str
        A name per block (for messages).
    coordinates : list of str
        A name per coordinate, e.g. ``"Y[0,1]"`` (symmetric variables: upper triangle only).
    """

    F0: list
    F: list
    names: list
    coordinates: list

    @property
    def n_coordinates(self) -> int:
        """Number ``m`` of independent variable coordinates."""
        return len(self.coordinates)

    @property
    def homogeneous(self) -> bool:
        """True when every constant term is exactly zero (the feasible set is a cone)."""
        return all(not np.any(F0) for F0 in self.F0)

    def evaluate(self, u) -> list:
        """The blocks :math:`F_j(u)` at coordinates ``u`` (length ``m``); a list of ndarrays."""
        u = np.asarray(u, dtype=float)
        return [F0 + np.tensordot(u, F, axes=1) for F0, F in zip(self.F0, self.F)]


def _affine_tensor(blocks, variables, parameters):
    """cvxpy's sparse tensor mapping (parameters, 1) to the stacked coefficients of ``blocks``."""
    from .cvx import cp  # noqa: F401  (imports cvxpy without scipy.stats before its submodules)
    from cvxpy.cvxcore.python import canonInterface
    from cvxpy.lin_ops import lin_op

    id_to_col, offset = {}, 0
    for v in variables:
        id_to_col[v.id] = offset
        offset += v.size
    param_to_size, param_to_col, poff = {}, {}, 0
    for p in parameters:
        param_to_size[p.id] = p.size
        param_to_col[p.id] = poff
        poff += p.size
    param_to_size[lin_op.CONSTANT_ID] = 1
    param_to_col[lin_op.CONSTANT_ID] = poff
    linops = []
    for b in blocks:
        lin, aux = b.canonical_form
        if aux:
            raise LMIError("an LMI block must be affine in the variables (its canonical form needs "
                           f"auxiliary constraints): {b}")
        linops.append(lin)
    total = int(sum(b.size for b in blocks))
    tensor = canonInterface.get_problem_matrix(linops, offset, id_to_col, param_to_size, param_to_col, total)
    return sp.csr_matrix(tensor), offset, total


def _reduction(variables, dropped=frozenset()):
    """Duplication matrix ``D`` (full entries x independent coordinates) and the coordinate names.

    Variables whose id is in ``dropped`` get no coordinate (they are evaluated at zero).
    """
    rows, cols, names, col = [], [], [], 0
    offset = 0
    for v in variables:
        if v.id in dropped:
            offset += v.size
            continue
        bad = [k for k, on in v.attributes.items() if on and k != "symmetric"]
        if bad:
            raise LMIError(f"variable {v.name()} has attribute(s) {bad}; only plain and symmetric variables "
                           "are supported (state sign or PSD conditions as LMI blocks)")
        shape = v.shape if len(v.shape) == 2 else (v.size, 1)
        if v.attributes.get("symmetric"):
            n = shape[0]
            for c in range(n):
                for r in range(c + 1):
                    for (a, b) in {(r, c), (c, r)}:
                        rows.append(offset + a + b * n)  # column-major entry index
                        cols.append(col)
                    names.append(f"{v.name()}[{r},{c}]")
                    col += 1
        else:
            for k in range(v.size):
                rows.append(offset + k)
                cols.append(col)
                r, c = k % shape[0], k // shape[0]
                names.append(f"{v.name()}[{r},{c}]" if len(v.shape) == 2 else f"{v.name()}[{k}]")
                col += 1
        offset += v.size
    D = sp.csr_matrix((np.ones(len(rows)), (rows, cols)), shape=(offset, col))
    return D, names


# ----------------------------------------------------------------------------- point check
@dataclass
class PointCheck:
    """Our eigenvalue check of a candidate point, block by block.

    Attributes
    ----------
    feasible : bool
        Every block has ``min_eig > tolerance``.
    min_eig : ndarray (J,)
        Smallest eigenvalue of each symmetrised block at the point.
    tolerance : ndarray (J,)
        The margin each ``min_eig`` must exceed (floating-point error of the check).
    worst_block : str
        Name of the block with the smallest ``min_eig - tolerance``.
    """

    feasible: bool
    min_eig: np.ndarray
    tolerance: np.ndarray
    worst_block: str

    @property
    def slack(self) -> float:
        """``min(min_eig - tolerance)`` over the blocks: positive iff the point is certified."""
        return float(np.min(self.min_eig - self.tolerance)) if self.min_eig.size else np.inf


def check_point(coeffs: LMICoefficients, u, safety: float = 10.0) -> PointCheck:
    r"""Check in numpy that :math:`F_j(u) \succ 0` for every block, with a rounding-error margin.

    Parameters
    ----------
    coeffs : LMICoefficients
        The system.
    u : array_like (m,)
        The candidate point in independent coordinates.
    safety : float
        The constant ``c`` of the eigensolver term of the margin (see the module docstring).

    Returns
    -------
    PointCheck
        ``feasible`` is True iff :math:`\lambda_{\min}(\mathrm{sym}\,\hat F_j) > \tau_j` for all ``j``.

    Raises
    ------
    LMIError
        If ``u`` has the wrong length or is not finite.
    """
    u = np.asarray(u, dtype=float).ravel()
    m = coeffs.n_coordinates
    if u.shape != (m,) or not np.all(np.isfinite(u)):
        raise LMIError(f"point must be {m} finite numbers, got shape {u.shape}")
    mins, tols = [], []
    g = _gamma(m + 2)
    for F0, F in zip(coeffs.F0, coeffs.F):
        n = F0.shape[0]
        Fu = F0 + np.tensordot(u, F, axes=1)
        S = 0.5 * (Fu + Fu.T)
        lam = float(np.linalg.eigvalsh(S)[0]) if n > 1 else float(S[0, 0])
        absF = np.abs(F0) + np.tensordot(np.abs(u), np.abs(F), axes=1)
        tol = safety * n * EPS * float(np.linalg.norm(S)) * (n > 1) + g * float(np.linalg.norm(absF)) + \
            EPS * float(np.linalg.norm(S))
        mins.append(lam)
        tols.append(tol)
    mins, tols = np.array(mins), np.array(tols)
    worst = coeffs.names[int(np.argmin(mins - tols))] if mins.size else ""
    return PointCheck(bool(np.all(mins > tols)), mins, tols, worst)


# ----------------------------------------------------------------------------- dual certificates
@dataclass
class DualCertificate:
    r"""A candidate theorem-of-alternatives certificate :math:`Z_j = V_j V_j^T \succeq 0`.

    Held as factors, so that positive semidefiniteness holds by construction (exactly, for
    the matrices the factors define) and needs no floating-point eigenvalue test.

    Attributes
    ----------
    factors : list of ndarray (n_j, r_j)
        One factor per block.
    route : str
        How it was found: ``"exact"`` or ``"box"`` (see :func:`find_dual_certificate`).
    solver_status : str
        Status of the auxiliary SDP that proposed it (information only).
    """

    factors: list
    route: str = ""
    solver_status: str = ""


@dataclass
class DualCheck:
    """Outcome of :func:`check_dual_certificate`.

    Attributes
    ----------
    valid : bool
        The certificate proves the statement in ``scope``.
    scope : str
        ``"exact"``: no point at all satisfies the system; ``"box"``: no point of the stated
        box does (for a homogeneous system: no point with ``|u_i| <= R_i min_j lambda_min(F_j(u))``).
    bound : float
        The checked quantity that must be negative (``"box"``: the upper bound of
        ``sum_j tr(F_j(u) Z_j)`` over the box; ``"exact"``: the repaired dual value plus the
        repair's size minus the certificate's smallest eigenvalue, see the function).
    detail : dict
        The numbers behind the decision (residuals, error bounds, eigenvalue bounds).
    """

    valid: bool
    scope: str
    bound: float
    detail: dict = field(default_factory=dict)


def _products(coeffs: LMICoefficients, factors):
    """``g0 = sum_j tr(V_j^T F_j0 V_j)``, ``g_i = sum_j tr(V_j^T F_ji V_j)`` and their rounding-error bounds."""
    m = coeffs.n_coordinates
    g0, e0 = 0.0, 0.0
    g, e = np.zeros(m), np.zeros(m)
    for F0, F, V in zip(coeffs.F0, coeffs.F, factors):
        V = np.asarray(V, dtype=float).reshape(F0.shape[0], -1)
        n, r = V.shape
        k = _gamma(2 * n + r + len(coeffs.F0) + 2)
        W = V @ V.T
        aW = np.abs(V) @ np.abs(V).T
        g0 += float(np.sum(F0 * W))
        e0 += k * float(np.sum(np.abs(F0) * aW))
        if m:
            g += np.tensordot(F, W, axes=([1, 2], [0, 1]))
            e += k * np.tensordot(np.abs(F), aW, axes=([1, 2], [0, 1]))
    return g0, e0, g, e


def check_dual_certificate(coeffs: LMICoefficients, cert: DualCertificate, box=None) -> DualCheck:
    r"""Check a dual certificate in numpy; valid only if it proves infeasibility.

    The theorem of alternatives for strict LMIs: if :math:`Z_j \succeq 0`, not all zero, with
    :math:`\sum_j \mathrm{tr}(F_{ji} Z_j) = 0` for all ``i`` and :math:`\sum_j \mathrm{tr}(F_{j0} Z_j) \le 0`,
    then no ``u`` has :math:`F_j(u) \succ 0` for all ``j``: otherwise
    :math:`0 < \sum_j \mathrm{tr}(F_j(u) Z_j) = \sum_j \mathrm{tr}(F_{j0} Z_j) \le 0`. Computed residuals
    :math:`g_i` are never exactly zero, so the exact zero is replaced by one of two rigorous arguments:

    ``box`` (when ``box`` is given: :math:`|u_i| \le R_i`)
        For ``u`` in the box :math:`\sum_j \mathrm{tr}(F_j(u) Z_j) = g_0 + \sum_i u_i g_i \le
        g_0 + e_0 + \sum_i R_i(|g_i| + e_i) =: U`, with :math:`e` the rounding-error bounds of the
        computed :math:`g`. ``U < 0`` proves that no point of the box satisfies even
        :math:`F_j(u) \succeq 0`. For a *homogeneous* system (all :math:`F_{j0} = 0`) the feasible
        set is a cone and :math:`\lambda_{\min} \ge 1` is a normalisation without loss of
        generality, so :math:`F_{j0}` is replaced by :math:`-I`: then ``U < 0`` proves that no
        point has :math:`|u_i| \le R_i \min_j \lambda_{\min}(F_j(u))`, i.e. every strictly feasible
        point, if any, is worse conditioned than the box states.
    ``exact`` (no box needed)
        If :math:`Z = \mathrm{diag}(Z_j) \succeq \mu I` with :math:`\mu > 0` and the linear map
        :math:`\mathcal A(W)_i = \sum_j \langle \mathrm{sym} F_{ji}, W_j\rangle` is onto (Gram matrix
        :math:`G = \mathcal A \mathcal A^* \succeq \lambda_G I`, :math:`\lambda_G > 0`), the least-norm
        :math:`\Delta` with :math:`\mathcal A(\Delta) = -g` has :math:`\|\Delta\|_2 \le \|\Delta\|_F \le
        \delta := \|g\|_2 / \sqrt{\lambda_G}`. If :math:`\delta < \mu` and
        :math:`g_0 + \|F_0\|_F\,\delta \le 0`, then :math:`Z + \Delta` is an exact certificate:
        the system has no solution at all. All quantities are used with their rounding-error
        bounds (lower bounds for :math:`\mu, \lambda_G`, upper bounds for :math:`g`).

    Parameters
    ----------
    coeffs : LMICoefficients
        The system.
    cert : DualCertificate
        The factors :math:`V_j` of :math:`Z_j = V_j V_j^T`.
    box : ndarray (m,) or None
        Bounds :math:`R_i > 0` (``inf`` allowed where :math:`g_i` is exactly zero); None: only the
        ``exact`` argument is tried.

    Returns
    -------
    DualCheck
        ``valid`` True iff one of the arguments above succeeds (``exact`` tried first).

    Raises
    ------
    LMIError
        If the factors do not match the blocks.
    """
    if len(cert.factors) != len(coeffs.F0):
        raise LMIError(f"certificate has {len(cert.factors)} factors for {len(coeffs.F0)} blocks")
    g0, e0, g, e = _products(coeffs, cert.factors)
    detail = {"g0": g0, "g0_err": e0, "residual_norm": float(np.linalg.norm(g)), "residual_err": float(np.linalg.norm(e))}
    exact = _check_exact(coeffs, cert.factors, g0, e0, g, e, detail)
    if exact.valid or box is None:
        return exact
    R = np.broadcast_to(np.asarray(box, dtype=float), g.shape)
    if coeffs.homogeneous:  # normalisation lambda_min >= 1: F_j0 -> -I
        g0 = -sum(float(np.sum(np.asarray(V) ** 2)) for V in cert.factors)
        e0 = _gamma(max(np.asarray(V).size for V in cert.factors) + 2) * abs(g0)
    with np.errstate(invalid="ignore"):  # inf * 0 where a coordinate is unbounded but does not enter
        terms = np.where((g == 0) & (e == 0), 0.0, R * (np.abs(g) + e))
    U = g0 + e0 + float(np.sum(terms))
    scale = sum(float(np.sum(np.asarray(V) ** 2)) for V in cert.factors)  # tr Z
    detail.update({"box_bound": U, "trace_Z": scale, "normalised": coeffs.homogeneous})
    return DualCheck(bool(U < 0), "box", U, detail)


def _check_exact(coeffs, factors, g0, e0, g, e, detail) -> DualCheck:
    """The ``exact`` argument of :func:`check_dual_certificate` (repair by the least-norm correction)."""
    m = coeffs.n_coordinates
    mu = np.inf
    for V in factors:  # lower bound of lambda_min(V V^T) for every block
        V = np.asarray(V, dtype=float)
        n, r = V.shape
        if r < n:
            mu = 0.0
            break
        W = V @ V.T
        lam = float(np.linalg.eigvalsh(0.5 * (W + W.T))[0]) if n > 1 else float(W[0, 0])
        nrm = float(np.linalg.norm(W))
        mu = min(mu, lam - 10 * n * EPS * nrm - _gamma(r + 2) * float(np.linalg.norm(np.abs(V) @ np.abs(V).T)))
    if m == 0:
        lamG, delta = np.inf, 0.0
    else:
        L = np.concatenate([0.5 * (F + np.swapaxes(F, 1, 2)).reshape(m, -1) for F in coeffs.F], axis=1)
        G = L @ L.T
        norms2 = np.sum(L * L, axis=1)
        lamG = float(np.linalg.eigvalsh(G)[0]) - 10 * m * EPS * float(np.linalg.norm(G)) \
            - _gamma(L.shape[1] + 4) * float(np.sum(norms2))
        delta = (float(np.linalg.norm(g)) + float(np.linalg.norm(e))) / np.sqrt(lamG) if lamG > 0 else np.inf
    normF0 = float(np.sqrt(sum(np.sum(F0 * F0) for F0 in coeffs.F0)))
    const = g0 + e0 + normF0 * delta if np.isfinite(delta) else np.inf
    ok = mu > 0 and np.isfinite(delta) and delta < mu and const <= 0
    detail.update({"min_eig_Z_lower": mu, "gram_min_eig_lower": lamG, "repair_norm": delta, "repaired_g0_upper": const})
    bound = (delta - mu if const <= 0 else const) if np.isfinite(delta) and np.isfinite(mu) else np.inf
    return DualCheck(bool(ok), "exact", float(bound), detail)


def _svec_index(n):
    """Row/column indices of Clarabel's svec order (upper triangle, column by column) and the sqrt(2) scale."""
    r, c = np.triu_indices(n)
    order = np.lexsort((r, c))
    r, c = r[order], c[order]
    scale = np.where(r == c, 1.0, np.sqrt(2.0))
    return r, c, scale


def _svec(M, idx):
    """svec of the symmetric part of ``M`` (batched over leading axes) in Clarabel's order."""
    r, c, scale = idx
    S = 0.5 * (M + np.swapaxes(M, -1, -2))
    return S[..., r, c] * scale


def _smat(x, n, idx):
    """Inverse of :func:`_svec` for one vector."""
    r, c, scale = idx
    M = np.zeros((n, n))
    M[r, c] = x / scale
    M[c, r] = x / scale
    return M


def find_dual_certificate(coeffs: LMICoefficients, route: str = "exact", box=None, settings: dict | None = None):
    r"""Propose a dual certificate: the dual of a margin problem solved with Clarabel (never trusted: check it).

    The margin problem is: maximise ``t`` subject to :math:`F_j(u) \succeq tI` for all ``j`` and
    ``t <= 1`` (``route="exact"`` on a non-homogeneous system: its homogenisation, with
    :math:`\lambda F_{j0}` in place of :math:`F_{j0}` and the block :math:`\lambda \ge t`); with ``route="box"`` also :math:`|u_i| \le R_i`, and for a homogeneous system
    :math:`F_{j0}` replaced by :math:`-I` (the normalisation of :func:`check_dual_certificate`).
    Its dual is: minimise :math:`\sum_j \mathrm{tr}(F_{j0} Z_j) + \sum_i R_i |\sum_j \mathrm{tr}(F_{ji} Z_j)| + \nu`
    over :math:`Z_j \succeq 0`, :math:`\nu \ge 0`, :math:`\sum_j \mathrm{tr} Z_j + \nu = 1` (without a box:
    :math:`\sum_j \mathrm{tr}(F_{ji} Z_j) = 0`), so when the system is infeasible the dual
    variables of the blocks are a candidate certificate (an interior-point method ends near the
    analytic centre of the optimal face: the largest rank available, which the ``exact``
    argument needs). Solving the margin problem (``m + 1`` variables) rather than the dual
    SDP (one variable per entry of every :math:`Z_j`) keeps the KKT system small.

    Parameters
    ----------
    coeffs : LMICoefficients
        The system.
    route : {"exact", "box"}
        Which margin problem to solve.
    box : array_like (m,) or None
        The bounds :math:`R_i` (required for ``route="box"``; ``inf``: unbounded).
    settings : dict or None
        Clarabel settings to override.

    Returns
    -------
    DualCertificate or None
        The proposed factors (``Z_j`` split by an eigendecomposition, negative eigenvalues
        dropped), or None if Clarabel returned no usable dual point.

    Raises
    ------
    LMIError
        If ``route`` is unknown or ``box`` is missing for ``route="box"``.
    """
    import clarabel

    if route not in ("exact", "box"):
        raise LMIError(f"route must be 'exact' or 'box', got {route!r}")
    m = coeffs.n_coordinates
    sizes = [F0.shape[0] for F0 in coeffs.F0]
    idxs = [_svec_index(n) for n in sizes]
    lens = [n * (n + 1) // 2 for n in sizes]
    normalise = route == "box" and coeffs.homogeneous
    # rows of A x + s = b with x = [u, t]: s_j = svec(F_j0) + sum_i u_i svec(F_ji) - t svec(I)
    b_psd = np.concatenate([_svec(-np.eye(n) if normalise else F0, ix) for F0, n, ix in zip(coeffs.F0, sizes, idxs)])
    Lu = np.concatenate([_svec(F, ix) for F, ix in zip(coeffs.F, idxs)], axis=1).T if m else np.zeros((sum(lens), 0))
    tr = np.concatenate([_svec(np.eye(n), ix) for n, ix in zip(sizes, idxs)])
    A_psd = sp.hstack([sp.csr_matrix(-Lu), sp.csr_matrix(tr[:, None])])
    A_top = sp.csr_matrix(np.append(np.zeros(m), 1.0)[None, :])  # t <= 1
    b_top = np.ones(1)
    n_box = 0
    if route == "box":
        if box is None:
            raise LMIError("route='box' needs the box bounds R")
        R = np.broadcast_to(np.asarray(box, dtype=float), (m,))
        fin = np.flatnonzero(np.isfinite(R))
        n_box = 2 * fin.size
        E = sp.csr_matrix((np.ones(fin.size), (np.arange(fin.size), fin)), shape=(fin.size, m + 1))
        A_top = sp.vstack([A_top, E, -E])
        b_top = np.concatenate([b_top, R[fin], R[fin]])
    A = sp.csc_matrix(sp.vstack([A_top, A_psd]))
    b = np.concatenate([b_top, b_psd])
    cones = [clarabel.NonnegativeConeT(1 + n_box)]
    cones += [clarabel.PSDTriangleConeT(n) if n > 1 else clarabel.NonnegativeConeT(1) for n in sizes]
    q = np.append(np.zeros(m), -1.0)
    from .cvx import clarabel_settings

    st = clarabel_settings(clarabel.DefaultSettings())
    st.verbose = False
    for k, v in (settings or {}).items():
        setattr(st, k, v)
    if route == "exact" and not coeffs.homogeneous:
        # homogenise: F_j(u) > 0 is feasible iff lam F_j0 + sum_i u_i F_ji > 0, lam > 0 is. Then every
        # certificate is dual-optimal (t* = 0), and the interior-point method returns one near the
        # centre of that set (full rank when the set allows it), not a singular optimal face of
        # min tr(F0 Z); the block lam >= t carries tr(F0 Z) = -z_lam < 0.
        A_psd = sp.hstack([sp.csr_matrix(-Lu), sp.csr_matrix(-b_psd[:, None]), sp.csr_matrix(tr[:, None])])
        A_top = sp.csr_matrix(np.array([[0.0] * m + [0.0, 1.0], [0.0] * m + [-1.0, 1.0]]))  # t <= 1, lam >= t
        A = sp.csc_matrix(sp.vstack([A_top, A_psd]))
        b = np.concatenate([np.array([1.0, 0.0]), np.zeros(b_psd.size)])
        cones[0] = clarabel.NonnegativeConeT(2)
        q = np.append(np.zeros(m + 1), -1.0)
        n_box = 1  # one more leading row before the blocks' duals
    nx = q.size
    sol = clarabel.DefaultSolver(sp.csc_matrix((nx, nx)), q, A, b, cones, st).solve()
    z = np.asarray(sol.z, dtype=float)
    if z.size != b.size or not np.all(np.isfinite(z)):
        return None
    factors, start = [], 1 + n_box
    for n, ln, ix in zip(sizes, lens, idxs):
        Z = _smat(z[start:start + ln], n, ix)
        lam, U = np.linalg.eigh(Z)
        keep = lam > 0
        factors.append(U[:, keep] * np.sqrt(lam[keep]) if np.any(keep) else np.zeros((n, 1)))
        start += ln
    return DualCertificate(factors, route, str(sol.status))


# ----------------------------------------------------------------------------- verdicts
@dataclass
class Verdict:
    """A certified decision about an LMI system.

    Attributes
    ----------
    verdict : str
        ``"feasible"``, ``"infeasible"`` or ``"undecided"``.
    solver_status : str
        Status of the solve that proposed the point (information only; never decides).
    evidence : str
        One line saying what backs the verdict.
    point : PointCheck or None
        The eigenvalue check of the returned point (None when there was no point).
    dual : DualCheck or None
        The check of a dual certificate, when one was tried.
    necessary : Any
        The evidence returned by a necessary-condition callable, when one was given.
    values : dict
        Variable values at the point (name -> ndarray), when there was a point.
    seconds : float
        Time spent certifying (not solving).
    """

    verdict: str
    solver_status: str = ""
    evidence: str = ""
    point: PointCheck | None = None
    dual: DualCheck | None = None
    necessary: Any = None
    values: dict = field(default_factory=dict)
    seconds: float = 0.0

    @property
    def feasible(self) -> bool:
        """Certified feasible."""
        return self.verdict == FEASIBLE

    @property
    def infeasible(self) -> bool:
        """Certified infeasible."""
        return self.verdict == INFEASIBLE

    @property
    def decided(self) -> bool:
        """Certified either way."""
        return self.verdict != UNDECIDED


def _as_block(expr):
    """A square cvxpy expression, or the 1x1 blocks of a scalar/vector expression (each entry > 0).

    A cvxpy constraint stands for its expression: ``PSD`` (``A >> B``) for ``A - B``,
    ``Inequality`` (``a <= b``) for ``b - a``.
    """
    from .cvx import cp

    PSD, Inequality = cp.constraints.PSD, cp.constraints.Inequality

    if isinstance(expr, PSD):
        expr = expr.args[0]
    elif isinstance(expr, Inequality):
        expr = -expr.expr
    elif isinstance(expr, cp.constraints.constraint.Constraint):
        raise LMIError(f"only PSD (>>, <<) and inequality (<=, >=) constraints can be blocks, got {type(expr).__name__}")

    if expr.ndim == 2 and expr.shape[0] == expr.shape[1]:
        return [expr]
    if expr.ndim <= 1 or 1 in expr.shape:
        flat = cp.reshape(expr, (expr.size,), order="F") if expr.ndim else cp.reshape(expr, (1,), order="F")
        return [cp.reshape(flat[k], (1, 1), order="F") for k in range(expr.size)]
    raise LMIError(f"an LMI block must be square, a scalar or a vector, got shape {expr.shape}")


class CertifiedLMI:
    r"""A system of strict LMIs :math:`F_j(u) \succ 0` built from cvxpy expressions, and its certifier.

    Build it once, beside the cvxpy problem that searches for a point (typically: maximise a
    margin ``t`` with :math:`F_j(u) \succeq t I` and a normalisation); after each solve,
    :meth:`certify` decides from the variables' values, our own eigenvalue check, dual
    certificates and optional necessary conditions. The solver status is carried along as
    information only. Coefficients follow the current values of the cvxpy Parameters.

    Parameters
    ----------
    blocks : sequence of cvxpy.Expression, cvxpy constraint, or (str, either)
        The blocks whose strict positivity is the question: square, affine, symmetric
        (only the symmetric part is used); a scalar or vector expression stands for "every entry
        > 0". A constraint of the problem may be passed instead (``Psi >> t*I`` stands for
        ``Psi - t I``; ``a <= b`` for ``b - a``), with its margin variable ``t`` in ``drop``.
        Normalisations (``Y << I``, entry bounds, ``t <= cap``) are not part of the question:
        leave them out (a bound belongs in ``box``). A non-strict block of the
        paper (``>= 0``) is checked strictly for ``feasible`` (sufficient), and a dual
        certificate proves even the non-strict system infeasible (``box``) or the strict one
        (``exact``). Every expression must be DPP (parameters enter affinely).
    problem : cvxpy.Problem or None
        The problem :meth:`solve` solves to propose a point.
    box : float, dict or None
        Bounds :math:`|u_i| \le R_i` stating the variable box of the ``box`` argument of
        :func:`check_dual_certificate`: one number for every coordinate, or a dict
        ``{variable: bound}`` (missing variables: unbounded). For a homogeneous system the box
        applies after the normalisation :math:`\min_j \lambda_{\min}(F_j(u)) = 1`.
    dual_routes : tuple of str
        Auxiliary SDPs tried, in order, for an infeasibility certificate when the point is not
        certified (``"exact"``, ``"box"``; ``"box"`` is skipped without a box). ``()``: none.
    safety : float
        The constant of the eigensolver error term of :func:`check_point`.
    drop : sequence of cvxpy.Variable
        Margin variables evaluated at zero (e.g. the ``t`` of ``Psi >> t*I``): the blocks are
        the question without the margin.

    Attributes
    ----------
    variables : list of cvxpy.Variable
        The variables of the blocks, in coordinate order.
    parameters : list of cvxpy.Parameter
        The parameters the coefficients depend on.
    names : list of str
        Block names.
    n_certify : int
        Number of :meth:`certify` calls.

    Raises
    ------
    LMIError
        If a block is not affine, not square/vector, not DPP, or a variable has an attribute
        other than ``symmetric``.
    """

    def __init__(self, blocks, problem=None, box=None, dual_routes=("exact", "box"), safety: float = 10.0,
                 drop=()):
        named = []
        for k, b in enumerate(blocks):
            name, expr = b if isinstance(b, tuple) else (f"block{k}", b)
            parts = _as_block(expr)
            for q, part in enumerate(parts):
                named.append((name if len(parts) == 1 else f"{name}[{q}]", part))
        if not named:
            raise LMIError("CertifiedLMI needs at least one block")
        for name, expr in named:
            if not expr.is_affine():
                raise LMIError(f"LMI block {name} is not affine in the variables")
            if not expr.is_dpp():
                raise LMIError(f"LMI block {name} is not DPP (parameters must enter affinely)")
        self.names = [n for n, _ in named]
        exprs = [e for _, e in named]
        self._exprs = exprs
        seen, variables, parameters = set(), [], []
        for e in exprs:
            for v in e.variables():
                if v.id not in seen:
                    seen.add(v.id)
                    variables.append(v)
            for p in e.parameters():
                if p.id not in seen:
                    seen.add(p.id)
                    parameters.append(p)
        dropped = frozenset(v.id for v in drop)
        self._all_variables = variables
        self.variables = [v for v in variables if v.id not in dropped]
        self.parameters = parameters
        self.problem = problem
        self.safety = float(safety)
        self.dual_routes = tuple(dual_routes)
        self._tensor, self._n_full, self._total = _affine_tensor(exprs, variables, parameters)
        self._D, self.coordinate_names = _reduction(variables, dropped)
        D = self._D.tocsc()  # an independent coordinate reads the first full entry it stands for
        self._first = np.array([D.indices[D.indptr[c]:D.indptr[c + 1]].min() for c in range(D.shape[1])], dtype=int)
        self._sizes = [e.shape[0] for e in exprs]
        self._box = self._box_vector(box)
        self.n_certify = 0

    def _box_vector(self, box):
        """The box as one bound per independent coordinate (inf: unbounded), or None."""
        if box is None:
            return None
        m = self._D.shape[1]
        if np.isscalar(box):
            if not box > 0:
                raise LMIError(f"box must be positive, got {box}")
            return np.full(m, float(box))
        R = np.full(m, np.inf)
        col = 0
        for v in self.variables:
            k = v.size if not v.attributes.get("symmetric") else v.shape[0] * (v.shape[0] + 1) // 2
            for var, bound in box.items():
                if var.id == v.id:
                    R[col:col + k] = float(bound)
            col += k
        return R

    def coefficients(self) -> LMICoefficients:
        """The coefficients at the current parameter values.

        Returns
        -------
        LMICoefficients
            One ``(F0, F)`` per block, ``F`` in independent coordinates.

        Raises
        ------
        LMIError
            If a parameter has no value.
        """
        vals = []
        for p in self.parameters:
            if p.value is None:
                raise LMIError(f"parameter {p.name()} has no value")
            vals.append(np.asarray(p.value, dtype=float).ravel(order="F"))
        pvec = np.concatenate(vals + [np.ones(1)])
        flat = np.asarray(self._tensor @ pvec).ravel()
        M = flat.reshape((self._total, self._n_full + 1), order="F")  # rows: stacked column-major entries
        m = self._D.shape[1]
        lin = np.asarray(self._D.T @ M[:, :-1].T).T  # (total, m): one column per independent coordinate
        F0s, Fs, start = [], [], 0
        for n in self._sizes:
            rows = slice(start, start + n * n)
            F0s.append(M[rows, -1].reshape((n, n), order="F"))
            Fs.append(lin[rows].T.reshape((m, n, n)).transpose(0, 2, 1))  # C-order rows of F-order entries
            start += n * n
        return LMICoefficients(F0s, Fs, list(self.names), list(self.coordinate_names))

    def point(self):
        """The current variable values as independent coordinates, or None if any value is missing.

        Returns
        -------
        ndarray (m,) or None
            The coordinates (symmetric variables: upper triangle, from the value as given).
        """
        parts = []
        kept = {v.id for v in self.variables}
        for v in self._all_variables:
            if v.id not in kept:  # dropped: evaluated at zero
                parts.append(np.zeros(v.size))
                continue
            if v.value is None:
                return None
            parts.append(np.asarray(v.value, dtype=float).ravel(order="F"))
        full = np.concatenate(parts) if parts else np.zeros(0)
        u = full[self._first]
        if not np.all(np.isfinite(u)):
            return None
        return u

    def certify(self, solver_status: str = "", necessary: Callable[[], tuple] | None = None,
                coeffs: LMICoefficients | None = None) -> Verdict:
        """Decide the system at the current parameter values (:meth:`decide`), counted for the step.

        Each verdict is counted (:func:`netrepro.engines.cvx.record_decision`): a step whose
        certificates decide nothing fails at its end naming the solver's statuses, instead of
        writing tables that a later step would find empty.

        Parameters
        ----------
        solver_status : str
            As :meth:`decide`.
        necessary : callable, optional
            As :meth:`decide`.
        coeffs : LMICoefficients, optional
            As :meth:`decide`.

        Returns
        -------
        Verdict
            The certified verdict.
        """
        from .cvx import record_decision

        verdict = self.decide(solver_status, necessary, coeffs)
        record_decision(verdict.verdict)
        return verdict

    def decide(self, solver_status: str = "", necessary: Callable[[], tuple] | None = None,
               coeffs: LMICoefficients | None = None) -> Verdict:
        """Decide the system at the current parameter values from the current variable values.

        Order: (1) our eigenvalue check of the point (:func:`check_point`): ``feasible``;
        (2) ``necessary()``: a caller-supplied independent necessary condition for feasibility,
        returning ``(violated, evidence)`` with ``violated`` a checked boolean (e.g.
        ``p * min_K rho(H(K)) >= 1`` computed without the LMI): ``infeasible`` when violated;
        (3) the dual certificate routes (:func:`find_dual_certificate`, each proposal checked by
        :func:`check_dual_certificate`): ``infeasible``; otherwise ``undecided``.
        A symmetric variable's value is read from its upper triangle.

        Parameters
        ----------
        solver_status : str
            Status of the solve that set the values (recorded only).
        necessary : callable or None
            ``necessary() -> (violated: bool, evidence)``.
        coeffs : LMICoefficients or None
            Precomputed coefficients (default: :meth:`coefficients`).

        Returns
        -------
        Verdict
            The certified verdict with its evidence.
        """
        start = time.perf_counter()
        self.n_certify += 1
        coeffs = self.coefficients() if coeffs is None else coeffs
        u = self.point()
        pc = None
        values = {}
        if u is not None:
            pc = check_point(coeffs, u, self.safety)
            values = {v.name(): np.array(v.value, dtype=float) for v in self.variables}
            if pc.feasible:
                return Verdict(FEASIBLE, solver_status, f"eigenvalue check: min slack {pc.slack:.3g} > 0", pc,
                               values=values, seconds=time.perf_counter() - start)
        nec = None
        if necessary is not None:
            violated, nec = necessary()
            if bool(violated):
                return Verdict(INFEASIBLE, solver_status, f"necessary condition violated: {nec}", pc, None, nec,
                               values, time.perf_counter() - start)
        dc = None
        for route in self.dual_routes:
            if route == "box" and self._box is None:
                continue
            cert = find_dual_certificate(coeffs, route, self._box)
            if cert is None:
                continue
            dc = check_dual_certificate(coeffs, cert, self._box)
            if dc.valid:
                return Verdict(INFEASIBLE, solver_status, f"dual certificate ({dc.scope}), bound {dc.bound:.3g} < 0",
                               pc, dc, nec, values, time.perf_counter() - start)
        why = "no certificate" if pc is None else f"point not certified (slack {pc.slack:.3g}), no certificate"
        return Verdict(UNDECIDED, solver_status, why, pc, dc, nec, values, time.perf_counter() - start)

    def solve(self, necessary: Callable[[], tuple] | None = None, **solve_kwargs) -> Verdict:
        """Solve :attr:`problem` (Clarabel unless ``solver=`` is given) and :meth:`certify` the result.

        Parameters
        ----------
        necessary : callable or None
            Passed to :meth:`certify`.
        **solve_kwargs
            Passed to :meth:`cvxpy.Problem.solve`.

        Returns
        -------
        Verdict
            The certified verdict; ``solver_status`` holds the solver's status or error.

        Raises
        ------
        LMIError
            If the certifier was built without a problem.
        """
        from .cvx import cp

        if self.problem is None:
            raise LMIError("CertifiedLMI.solve needs the problem= it was built with")
        from .cvx import solve_problem

        for v in self.variables:
            v.value = None
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", UserWarning)
                status = solve_problem(self.problem, **solve_kwargs)
        except cp.error.SolverError as exc:
            status = f"solver_error: {exc}"
        return self.certify(status, necessary)


# ----------------------------------------------------------------------------- bisection
@dataclass
class CertifiedBracket:
    """A threshold bracket whose two ends are both certified.

    Attributes
    ----------
    infeasible_end : float
        The certified-infeasible lattice point next to the threshold (nan: none found).
    feasible_end : float
        The certified-feasible lattice point next to the threshold (nan: none found).
    certified : bool
        Both ends exist.
    undecided : list of float
        Points evaluated as undecided (recorded, never used as an end).
    history : list of (float, str)
        ``(x, verdict)`` in evaluation order.
    n_evals : int
        Number of evaluations.
    verdicts : dict
        ``x -> Verdict`` for every evaluated point (the ends' evidence included).
    """

    infeasible_end: float
    feasible_end: float
    certified: bool
    undecided: list
    history: list
    n_evals: int
    verdicts: dict

    @property
    def lower(self) -> float:
        """The smaller end (nan if either end is missing)."""
        return min(self.infeasible_end, self.feasible_end) if self.certified else np.nan

    @property
    def upper(self) -> float:
        """The larger end (nan if either end is missing)."""
        return max(self.infeasible_end, self.feasible_end) if self.certified else np.nan


def _outward_from_guess(v, n: int, c: int, half: int):
    """The lattice indices a warm-started :func:`bisect_certified` evaluates first: outward from the guess
    index ``c`` in doubling steps (as ``bisect_bracketed``), up until a feasible point or ``n``, then down
    until an infeasible point or 0.

    Parameters
    ----------
    v : callable
        ``v(k)``: the verdict at lattice index ``k`` (evaluated and cached by the caller).
    n, c, half : int
        The last index, the guess's index, the first step.

    Returns
    -------
    up, down : list of int
        The indices visited going up, then going down.
    """
    up, down = [], []
    k, step = min(n, c + half), half
    while True:
        up.append(k)
        if v(k) == FEASIBLE or k == n:
            break
        step *= 2
        k = min(n, k + step)
    k, step = max(0, min(c - half, up[-1] - 1)), half
    while True:
        down.append(k)
        if v(k) == INFEASIBLE or k == 0:
            break
        step *= 2
        k = max(0, k - step)
    return up, down


def _bisect_lattice(v, a: int, b: int, verdict: str):
    """Bisect the lattice indices ``a < b`` to adjacent ones, keeping ``verdict`` on its side: with
    ``FEASIBLE`` the feasible end is ``b`` (feasible above), with ``INFEASIBLE`` the infeasible end is ``a``.

    Parameters
    ----------
    v : callable
        ``v(k)``: the verdict at lattice index ``k``.
    a, b : int
        The bracket.
    verdict : str
        ``FEASIBLE`` or ``INFEASIBLE``.

    Returns
    -------
    a, b : int
        ``b = a + 1`` (or the bracket if already adjacent).
    """
    while b - a > 1:
        mid = (a + b) // 2
        if (v(mid) == verdict) == (verdict == FEASIBLE):
            b = mid
        else:
            a = mid
    return a, b


def bisect_certified(decide: Callable[[float], Verdict], lo: float, hi: float, tol: float = 1e-4,
                     max_evals: int = 80, feasible_above: bool = True, guess: float | None = None,
                     width: float = 0.0) -> CertifiedBracket:
    """Certified bisection of a monotone feasibility threshold on the lattice of ``bisect_monotone``.

    ``decide(x)`` returns a :class:`Verdict`. With ``feasible_above`` the truth is infeasible
    below and feasible above the threshold (``False``: the mirror). Along the lattice
    ``lo + (hi - lo) j / n`` of :func:`netrepro.engines.lmi.bisect_monotone`, sound certificates
    and a monotone truth give verdicts reading ``I...I U...U F...F`` (from the infeasible side).
    The answer is defined by the lattice alone: the feasible end is the certified-feasible
    point nearest the infeasible side, the infeasible end the certified-infeasible point
    nearest the feasible side; every point between them is undecided. Two monotone bisections
    find them ("is feasible", "is infeasible"; an undecided point is "not feasible" for one and
    "not infeasible" for the other), sharing evaluations. A ``guess`` (with ``width``) only
    changes where the search starts (outward doubling steps as in ``bisect_bracketed``), so
    it changes the number of solves, never the answer (for verdicts of that pattern).

    Parameters
    ----------
    decide : callable
        ``decide(x) -> Verdict``.
    lo, hi : float
        The search interval, ``lo <= hi``.
    tol : float
        Lattice spacing target (as ``bisect_monotone``).
    max_evals : int
        Caps the lattice depth (as ``bisect_monotone``).
    feasible_above : bool
        Orientation of the threshold.
    guess, width : float or None, float
        Optional warm start.

    Returns
    -------
    CertifiedBracket
        Both ends certified when ``certified``; undecided points recorded.

    Raises
    ------
    LMIError
        If ``lo > hi``, or a certified-feasible point lies on the infeasible side of a
        certified-infeasible one (contradicting monotonicity).
    """
    from .lmi import _lattice

    if not lo <= hi:
        raise LMIError(f"bisect_certified needs lo <= hi, got lo={lo}, hi={hi}")
    n, point = _lattice(lo, hi, tol, max_evals)
    # index k counts from the infeasible side: k = 0 is lo when feasible_above, hi otherwise
    at = (lambda k: point(k)) if feasible_above else (lambda k: point(n - k))
    cache, history, verdicts = {}, [], {}

    def v(k):
        if k not in cache:
            x = float(at(k))
            out = decide(x)
            cache[k] = out.verdict
            history.append((x, out.verdict))
            verdicts[x] = out
        return cache[k]

    def result(a, b):
        ie = float(at(a)) if a is not None else np.nan
        fe = float(at(b)) if b is not None else np.nan
        F = [k for k, s in cache.items() if s == FEASIBLE]
        I_ = [k for k, s in cache.items() if s == INFEASIBLE]
        if F and I_ and min(F) < max(I_):
            raise LMIError(f"certified feasible at {float(at(min(F)))} but certified infeasible at "
                           f"{float(at(max(I_)))}: the predicate is not monotone")
        und = sorted(float(at(k)) for k, s in cache.items() if s == UNDECIDED)
        return CertifiedBracket(ie, fe, a is not None and b is not None, und, history, len(history), verdicts)

    # starting points: the two ends, or outward from the guess
    if guess is None or not np.isfinite(guess) or n == 0:
        up, down = [n], [0]
    else:
        cell = (hi - lo) / n
        c = int(round((min(max(float(guess), lo), hi) - lo) / cell))
        c = c if feasible_above else n - c
        half = max(1, int(np.ceil(float(width) / cell))) if cell > 0 else 1
        up, down = _outward_from_guess(v, n, c, half)
    for k in up + down:
        v(k)
    # bounds from everything known so far
    F = [k for k, s in cache.items() if s == FEASIBLE]
    I_ = [k for k, s in cache.items() if s == INFEASIBLE]
    hiF = min(F) if F else None  # smallest known feasible
    loI = max(I_) if I_ else None  # largest known infeasible
    if hiF is not None and hiF == 0:
        return result(None, 0)
    if loI is not None and loI == n:
        return result(n, None)
    if hiF is not None:
        notF = [k for k, s in cache.items() if s != FEASIBLE and k < hiF]
        a = max(notF) if notF else None
        if a is None:  # nothing known below the smallest feasible point: evaluate the infeasible end
            if v(0) == FEASIBLE:
                return result(None, 0)
            a = 0
        a, hiF = _bisect_lattice(v, a, hiF, FEASIBLE)
        I_ = [k for k, s in cache.items() if s == INFEASIBLE]  # the search above may have found more
        loI = max(I_) if I_ else None
    if loI is not None:
        notI = [k for k, s in cache.items() if s != INFEASIBLE and k > loI]
        b = min(notI) if notI else None
        if b is None:
            if v(n) == INFEASIBLE:
                return result(n, None)
            b = n
        loI, b = _bisect_lattice(v, loI, b, INFEASIBLE)
    return result(loI, hiF)
