"""Theorem 3 of the `gainsched` paper: the 16 vertex LMIs (24)-(25) and the gain recovery (26).

Variables (all in the coordinates of the congruence T of the proof of Theorem 2):
Q̄0, Q̄p (2n x 2n, symmetric), S11, R1, R2 (n x n), Ḡ0, Ḡf (n x n), H̄0, H̄f (n x m).
The vertex of indices (i, j, r, l) in {1, 2}^4 is (24):

.. math::

    M^{ijrl} = \\begin{bmatrix}
    -\\bar Q^i & * & * & * & * \\\\
    FZN & -2I & * & * & * \\\\
    \\Gamma_1^{ij} & \\hat B & -\\Lambda^l & * & * \\\\
    \\Gamma_3^{ijr} & 0 & 0 & -\\Theta^{jr}\\Lambda^l & * \\\\
    \\Gamma_4 & 0 & 0 & 0 & -\\sigma^2\\Lambda^l
    \\end{bmatrix} < 0

with (25): :math:`\\bar Q^i = \\bar Q_0 + p_i \\bar Q_p`, :math:`\\Theta^{jr} = p_j(1-p_r)`,
:math:`\\bar H^i = \\bar H_0 + p_i\\bar H_f`, :math:`\\bar G^i = \\bar G_0 + p_i \\bar G_f`,

.. math::

    \\Gamma_1^{ij} = \\begin{bmatrix} S_{11}^T A + p_j \\bar H^i C + S_{11}^T B F_1 Z & \\bar G^i \\\\
                                   R_1^T A + p_j \\bar H^i C + R_1^T B F_1 Z & \\bar G^i \\end{bmatrix},\\;
    \\Lambda^l = \\begin{bmatrix} S_{11}+S_{11}^T & R_1 + R_2^T \\\\ R_1^T + R_2 & R_2 + R_2^T\\end{bmatrix} - \\bar Q^l,

.. math::

    \\Gamma_3^{ijr} = \\Theta^{jr}\\begin{bmatrix} \\bar H^i C \\\\ \\bar H^i C\\end{bmatrix} N,\\;
    \\Gamma_4 = \\sigma^2 \\begin{bmatrix} S_{11}^T D \\\\ R_1^T D\\end{bmatrix} N,\\;
    \\hat B = \\begin{bmatrix} S_{11}^T B \\\\ R_1^T B \\end{bmatrix}.

The transposes in Γ1, Λ and B̂, and the two equal rows of Γ3, are our reading
of the garbled print: they are what the congruence T = diag(I, S22^{-1} S21)
of S = [S_ij] produces, since T^T S^T C̄ N T = [[S21^T H C, 0], [S21^T H C, 0]]
(checked in the tests by rebuilding (12) from a recovered S). Reading Γ3 like
C̄ of (11), [0; H̄C]N, breaks that identity (``gamma3_top="zero"`` keeps this
reading: the other end of the range of reconstruction ``gamma3_rows``).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ...engines.cvx import cp, solve_problem
from .model import Gains, GainschedError, System

__all__ = ["Theorem3", "Theorem3Solution", "FixedGainsVertexLMI", "zero_diagonal_blocks", "recover_gains", "recover_output_gains", "certified_cost",
           "output_certificate",
           "certificate_from_solution", "congruence_residual", "REALISATIONS"]

REALISATIONS = ("identity_T", "S21_identity")


@dataclass
class Theorem3Solution:
    """One solve of Theorem 3 (24)-(25): status, margin/objective and the variable values.

    Parameters
    ----------
    status : str
        Solver status (information).
    margin : float
        Maximised t (feasibility problems) or eps (performance problems).
    objective : float
        t, or gamma of the performance design.
    solver_feasible : bool
        The solver's opinion (information): status ``optimal``, and for feasibility problems a
        margin above ``margin_tol``.
    values : dict
        Variable name -> ndarray (empty when the solver returned no point).
    solve_time_s : float
        Wall time of the solve, in seconds (NaN if not recorded).
    n_scalar_variables : int
        Number of scalar decision variables of the problem.

    Returns
    -------
    Theorem3Solution
    """

    status: str
    margin: float
    objective: float
    solver_feasible: bool
    values: dict = field(default_factory=dict)
    solve_time_s: float = np.nan
    n_scalar_variables: int = 0


class Theorem3:
    """The 16 vertex LMIs (24)-(25), built once with ``sigma2`` as a :class:`cvxpy.Parameter`.

    Parameters
    ----------
    sys : System
        The example; ``sys.sigma2`` is only the default value of the parameter.
    scheduled : bool
        ``False`` forces Ḡf = H̄f = 0 (a fixed-gain filter with the same machinery).
    performance : bool
        Add :math:`L^TL`, :math:`L = [I\\; -I]`, to the (1,1) block of every vertex
        (so that :math:`E\\Delta V \\le -E\\|e(k)\\|^2`) and minimise
        :math:`\\gamma \\ge \\mathrm{tr}(\\bar Q^l X_0)`, l = 1, 2: then
        :math:`\\sum_k E\\|e(k)\\|^2 \\le \\gamma` for :math:`E\\bar z(0)\\bar z(0)^T = X_0`
        and any admissible p(k), when the gains are recovered with the
        ``identity_T`` realisation (T = I, so Q = Q̄).
    qp_positive : bool
        Impose Q̄p > 0 as stated under (27) (the paper's reading).
    eps : float
        Strictness margin: vertices <= -eps I, Q̄0 >= eps I (and Q̄p >= eps I).
    bound : float
        Entry-wise bound on all variables (scale fixing in the feasibility problem).
    X0 : ndarray (2n, 2n) or None
        Second moment of the initial augmented state for the performance objective.
    margin_cap : float
        Feasibility problems maximise the margin t (vertices <= -t I) subject to
        t <= margin_cap; uncapped, Clarabel ends ``optimal_inaccurate``.
    gamma3_top : {"HC", "zero"}
        Upper row of Γ3: H̄^i C (what the congruence gives) or 0 (the misreading).
    zero_filter : bool
        Fix Ḡ0 = H̄0 = Ḡf = H̄f = 0: the LMIs for the trivial estimate x_f = 0 (design ``zero``).
    output_slack : bool
        With ``performance``: the full-slack performance design. The estimate is
        x̂ = L_f x_f with L_f free, so the error row of the congruence T = diag(I, J),
        [I, -L_f J], is linear in the new variable L̄ = L_f J; the bound term enters
        as the Schur complement [[M, E^T], [E, -I]] < 0, E = [I, -L̄, 0]. Unlike
        adding [I, -I]^T [I, -I] (which ties the estimate to S21 = S22), nothing is
        forced: recover with :func:`recover_output_gains`.
    fixed_gains : Gains or None
        Given gains instead of variables, in the realisation T = I (S21 = S22 = R2), where
        (26) inverts to Ḡ = R2^T G(p), H̄ = R2^T H(p): linear in R2. A restriction of the
        slack (S21 = S22), so a feasible point proves (24) for these gains, an infeasible
        verdict only for this family (:class:`FixedGainsVertexLMI` has the general slack).
    noise_row : bool
        Keep the last block row/column (Γ4, -σ²Λ) of (24). At σ² = 0 it is a zero
        block, so the strict LMI as printed is infeasible; ``False`` drops it
        (the correct noise-free condition).

    Returns
    -------
    Theorem3
        The cvxpy problem in ``problem``, variables in ``vars``; :meth:`solve` solves it.

    Raises
    ------
    GainschedError
        On a bad ``gamma3_top`` or ``X0`` shape.
    """

    def __init__(self, sys: System, scheduled: bool = True, performance: bool = False, qp_positive: bool = True,
                 eps: float = 1e-6, bound: float = 1e3, X0=None, margin_cap: float = 0.1,
                 gamma3_top: str = "HC", noise_row: bool = True, zero_filter: bool = False,
                 output_slack: bool = False, fixed_gains: Gains | None = None):
        self.noise_row = noise_row
        self.fixed_gains = fixed_gains
        if fixed_gains is not None:
            zero_filter, scheduled = False, True
        self.output_slack = bool(output_slack and performance)
        self.zero_filter = zero_filter
        if zero_filter:
            scheduled = False
        if gamma3_top not in ("HC", "zero"):
            raise GainschedError(f"gamma3_top must be 'HC' or 'zero', got {gamma3_top!r}")
        self.gamma3_top = gamma3_top
        self.sys = sys
        self.scheduled = scheduled
        self.performance = performance
        n, m, nz = sys.n, sys.m, sys.nz
        nn = 2 * n
        self.sigma2 = cp.Parameter(nonneg=True, name="sigma2", value=sys.sigma2)
        v = {
            "Q0": cp.Variable((nn, nn), symmetric=True, name="Qbar0"),
            "Qp": cp.Variable((nn, nn), symmetric=True, name="Qbarp"),
            "S11": cp.Variable((n, n), name="S11"),
            "R1": cp.Variable((n, n), name="R1"),
            "R2": cp.Variable((n, n), name="R2"),
        }
        if not zero_filter and fixed_gains is None:
            v["G0"] = cp.Variable((n, n), name="Gbar0")
            v["H0"] = cp.Variable((n, m), name="Hbar0")
        if scheduled and fixed_gains is None:
            v["Gf"] = cp.Variable((n, n), name="Gbarf")
            v["Hf"] = cp.Variable((n, m), name="Hbarf")
        if self.output_slack:
            v["Lbar"] = cp.Variable((n, n), name="Lbar")
        self.vars = v
        self.t = cp.Variable(name="t")
        ps = (sys.p1, sys.p2)
        cons = [cp.abs(x) <= bound for x in v.values()]
        cons.append(v["Q0"] >> eps * np.eye(nn))
        if qp_positive:
            cons.append(v["Qp"] >> eps * np.eye(nn))
        else:
            cons += [v["Q0"] + p * v["Qp"] >> eps * np.eye(nn) for p in ps]
        L = np.hstack([np.eye(n), -np.eye(n)])
        self.n_vertices = 0
        # sub-blocks shared by several vertices (Q̄^i, Λ^l, Γ1^{ij}, ...), built once: the same expression
        # trees as building them per vertex, so the solver data are identical, with less to canonicalise
        self._parts = {}
        self._vertices = []
        self._blocks = []
        self._certifier = None
        self._eps = eps
        self._qp_positive = qp_positive
        for i in range(2):
            for j in range(2):
                for r in range(2):
                    for l in range(2):
                        M = self.vertex(ps[i], ps[j], ps[r], ps[l])
                        size = M.shape[0]
                        # M is structurally symmetric (every upper block is the transpose of the expression
                        # below it, the diagonal blocks are symmetric), so it equals 0.5 (M + M^T) coefficient
                        # for coefficient, exactly: the solver data are the same, with half the expression tree
                        Msym = M
                        if self.output_slack:
                            # error row [I, -L̄] in T-coordinates, Schur complement of + [I, -L̄]^T [I, -L̄]
                            Erow = cp.hstack([np.eye(n), -v["Lbar"], np.zeros((n, size - nn))])
                            big = cp.bmat([[Msym, Erow.T], [Erow, -np.eye(n)]])  # structurally symmetric too
                            self._vertices.append(big)
                            self._blocks.append((f"vertex{i}{j}{r}{l}", -big))
                            cons.append(big << -eps * np.eye(size + n))
                            self.n_vertices += 1
                            continue
                        self._vertices.append(Msym)
                        if performance:
                            E = np.zeros((size, size))
                            E[:nn, :nn] = L.T @ L
                            self._blocks.append((f"vertex{i}{j}{r}{l}", -(Msym + E)))
                            cons.append(Msym + E << -eps * np.eye(size))
                        else:
                            self._blocks.append((f"vertex{i}{j}{r}{l}", -Msym))
                            cons.append(Msym << -self.t * np.eye(size))
                        self.n_vertices += 1
        if performance:
            X0 = np.asarray(X0, dtype=float)
            if X0.shape != (nn, nn):
                raise GainschedError(f"X0 must have shape {(nn, nn)}, got {X0.shape}")
            self.gamma = cp.Variable(name="gamma")
            cons += [cp.trace((v["Q0"] + p * v["Qp"]) @ X0) <= self.gamma for p in ps]
            self.problem = cp.Problem(cp.Minimize(self.gamma), cons)
        else:
            self.gamma = None
            cons.append(self.t <= margin_cap)
            self.problem = cp.Problem(cp.Maximize(self.t), cons)
        self.margin_tol = eps
        if qp_positive:
            self._blocks += [("Qbar0", v["Q0"]), ("Qbarp", v["Qp"])]
        else:
            self._blocks += [(f"Qbar(p{k + 1})", v["Q0"] + p * v["Qp"]) for k, p in enumerate(ps)]

    @property
    def certifier(self):
        """The shared engine's certifier of this LMI system (built on first use).

        The question is the strict system of (24)-(25) (and (27)): every vertex matrix negative
        definite (with the bound term for the performance designs) and Q̄0, Q̄p positive definite.
        The entry bounds and the margin cap are normalisations, not part of it.

        Returns
        -------
        netrepro.engines.certify.CertifiedLMI
        """
        if self._certifier is None:
            from ...engines.certify import CertifiedLMI

            self._certifier = CertifiedLMI(self._blocks, problem=self.problem,
                                           drop=() if self.performance else (self.t,))
        return self._certifier

    # -- the blocks of (24)-(25), one function each, so they read against the paper
    def Qbar(self, p):
        """Q̄^i = Q̄0 + p_i Q̄p (25), (27).

        Parameters
        ----------
        p : float

        Returns
        -------
        cvxpy expression
        """
        return self.vars["Q0"] + p * self.vars["Qp"]

    def Gbar(self, p):
        """Ḡ^i = Ḡ0 + p_i Ḡf (25).

        Parameters
        ----------
        p : float

        Returns
        -------
        cvxpy expression
        """
        if self.zero_filter:
            return np.zeros((self.sys.n, self.sys.n))
        if self.fixed_gains is not None:  # T = I (S21 = S22 = R2): Ḡ = R2^T G(p), inverse of (26)
            return self.vars["R2"].T @ self.fixed_gains.G(p)
        return self.vars["G0"] + p * self.vars["Gf"] if self.scheduled else self.vars["G0"]

    def Hbar(self, p):
        """H̄^i = H̄0 + p_i H̄f (25).

        Parameters
        ----------
        p : float

        Returns
        -------
        cvxpy expression
        """
        if self.zero_filter:
            return np.zeros((self.sys.n, self.sys.m))
        if self.fixed_gains is not None:  # T = I: H̄ = R2^T H(p), inverse of (26)
            return self.vars["R2"].T @ self.fixed_gains.H(p)
        return self.vars["H0"] + p * self.vars["Hf"] if self.scheduled else self.vars["H0"]

    def Lambda(self, pl):
        """Λ^l = [[S11 + S11^T, R1 + R2^T], [R1^T + R2, R2 + R2^T]] - Q̄^l (25).

        Parameters
        ----------
        pl : float
            p_l of (25).

        Returns
        -------
        cvxpy expression
        """
        v = self.vars
        SS = cp.bmat([[v["S11"] + v["S11"].T, v["R1"] + v["R2"].T], [v["R1"].T + v["R2"], v["R2"] + v["R2"].T]])
        return SS - self.Qbar(pl)

    def Gamma1(self, pi, pj):
        """Γ1^{ij} = [[S11^T A + p_j H̄^i C + S11^T B F1 Z, Ḡ^i], [R1^T A + p_j H̄^i C + R1^T B F1 Z, Ḡ^i]] (25).

        Parameters
        ----------
        pi, pj : float

        Returns
        -------
        cvxpy expression
        """
        s, v = self.sys, self.vars
        AF = s.A + s.B @ s.F1 @ s.Z
        HC = pj * (self.Hbar(pi) @ s.C)
        return cp.bmat([[v["S11"].T @ AF + HC, self.Gbar(pi)], [v["R1"].T @ AF + HC, self.Gbar(pi)]])

    def Gamma3(self, pi, pj, pr):
        """Γ3^{ijr} = Θ^{jr} [H̄^i C; H̄^i C] N, Θ^{jr} = p_j (1 - p_r) (25) (= T^T Θ S^T C̄ N T).

        Parameters
        ----------
        pi, pj, pr : float

        Returns
        -------
        cvxpy expression
        """
        s = self.sys
        theta = pj * (1.0 - pr)
        n = s.n
        HC = self.Hbar(pi) @ s.C
        top = HC if self.gamma3_top == "HC" else np.zeros((n, n))
        return theta * cp.bmat([[top, np.zeros((n, n))], [HC, np.zeros((n, n))]])

    def Gamma4(self):
        """Γ4 = σ² [S11^T D; R1^T D] N (22).

        Returns
        -------
        cvxpy expression
        """
        s, v = self.sys, self.vars
        n = s.n
        return self.sigma2 * cp.bmat([[v["S11"].T @ s.D, np.zeros((n, n))], [v["R1"].T @ s.D, np.zeros((n, n))]])

    def Bhat(self):
        """B̂ = [S11^T B; R1^T B] (22).

        Returns
        -------
        cvxpy expression
        """
        s, v = self.sys, self.vars
        return cp.vstack([v["S11"].T @ s.B, v["R1"].T @ s.B])

    def vertex(self, pi, pj, pr, pl):
        """The vertex matrix M^{ijrl} of (24) (lower triangle written, upper by transposition).

        Parameters
        ----------
        pi, pj, pr, pl : float

        Returns
        -------
        cvxpy expression
        """
        s = self.sys
        nn, nz = 2 * s.n, s.nz
        theta = pj * (1.0 - pr)
        FZN = s.F @ s.Z @ s.N
        part = self._part
        G1 = part(("Gamma1", pi, pj), self.Gamma1, pi, pj)
        G3 = part(("Gamma3", pi, pj, pr), self.Gamma3, pi, pj, pr)
        Bh = part(("Bhat",), self.Bhat)
        Lam = part(("Lambda", pl), self.Lambda, pl)
        mQ = part(("-Qbar", pi), lambda p: -self.Qbar(p), pi)
        O = np.zeros
        if not self.noise_row:
            return cp.bmat([
                [mQ, FZN.T, G1.T, G3.T],
                [FZN, -2 * np.eye(nz), Bh.T, O((nz, nn))],
                [G1, Bh, -Lam, O((nn, nn))],
                [G3, O((nn, nz)), O((nn, nn)), -theta * Lam],
            ])
        G4 = part(("Gamma4",), self.Gamma4)
        return cp.bmat([
            [mQ, FZN.T, G1.T, G3.T, G4.T],
            [FZN, -2 * np.eye(nz), Bh.T, O((nz, nn)), O((nz, nn))],
            [G1, Bh, -Lam, O((nn, nn)), O((nn, nn))],
            [G3, O((nn, nz)), O((nn, nn)), -theta * Lam, O((nn, nn))],
            [G4, O((nn, nz)), O((nn, nn)), O((nn, nn)), -self.sigma2 * Lam],
        ])

    def _part(self, key, build, *args):
        """The sub-block ``build(*args)`` of the vertices, built on first use and reused (keyed by ``key``)."""
        if key not in self._parts:
            self._parts[key] = build(*args)
        return self._parts[key]

    def n_scalar_variables(self) -> int:
        """Number of scalar decision variables (Q̄0, Q̄p, S11, R1, R2, Ḡ, H̄).

        Returns
        -------
        int
        """
        return int(sum(x.size for x in self.vars.values()))

    def solve(self, sigma2: float | None = None) -> Theorem3Solution:
        """Solve at noise variance ``sigma2`` (default: the system's); keep the status string.

        Parameters
        ----------
        sigma2 : float, optional

        Returns
        -------
        Theorem3Solution
        """
        self.sigma2.value = self.sys.sigma2 if sigma2 is None else float(sigma2)
        start = time.perf_counter()
        try:
            solve_problem(self.problem)
            status = str(self.problem.status)
        except cp.error.SolverError as exc:
            return Theorem3Solution(f"solver_error: {exc}", np.nan, np.nan, False,
                                    solve_time_s=time.perf_counter() - start,
                                    n_scalar_variables=self.n_scalar_variables())
        elapsed = time.perf_counter() - start
        values = {k: (None if x.value is None else np.array(x.value)) for k, x in self.vars.items()}
        if self.fixed_gains is not None and values["R2"] is not None:
            for name, mat in self.fixed_gains.as_dict().items():
                values[name] = values["R2"].T @ mat
        if self.zero_filter and values["R2"] is not None:
            values["G0"] = np.zeros((self.sys.n, self.sys.n))
            values["H0"] = np.zeros((self.sys.n, self.sys.m))
        if not self.scheduled and values["G0"] is not None:
            values["Gf"] = np.zeros_like(values["G0"])
            values["Hf"] = np.zeros_like(values["H0"])
        ok_status = status == cp.OPTIMAL
        has_values = status in (cp.OPTIMAL, cp.OPTIMAL_INACCURATE) and values.get("R2") is not None
        if self.performance:
            margin = self.margin_tol if has_values else np.nan
            objective = float(self.gamma.value) if self.gamma.value is not None else np.nan
            feasible = ok_status
        else:
            margin = float(self.t.value) if (has_values and self.t.value is not None) else np.nan
            objective = margin
            feasible = ok_status and margin > self.margin_tol
        return Theorem3Solution(status, margin, objective, feasible, values if has_values else {}, elapsed,
                                self.n_scalar_variables())

    def check_point(self, values: dict, sigma2: float):
        """The engine's eigenvalue check of a candidate point of (24)-(25), (27), whatever the solver said.

        Parameters
        ----------
        values : dict
            Variable name -> ndarray (a solution or any candidate).
        sigma2 : float

        Returns
        -------
        tuple
            ``(ok, slack)``: every block strictly on its side beyond the engine's margin, and the
            smallest ``min_eig - tolerance`` over the blocks (> 0 iff ``ok``).
        """
        from ...engines.certify import check_point

        for name, var in self.vars.items():
            var.value = values[name]
        self.sigma2.value = float(sigma2)
        cert = self.certifier
        pc = check_point(cert.coefficients(), cert.point(), safety=cert.safety)
        return bool(pc.feasible), float(pc.slack)

    def certify(self, sigma2: float | None = None):
        """Solve at ``sigma2`` and decide with the engine: feasible (point check), infeasible (necessary
        condition of :mod:`.feasibility`, or a checked dual certificate), undecided.

        Parameters
        ----------
        sigma2 : float, optional

        Returns
        -------
        tuple
            ``(Verdict, Theorem3Solution)`` (:class:`netrepro.engines.certify.Verdict`); the status is information only.
        """
        from .feasibility import necessary_condition

        s2 = self.sys.sigma2 if sigma2 is None else float(sigma2)
        sol = self.solve(s2)
        verdict = self.certifier.certify(sol.status, necessary=necessary_condition(self.sys, s2))
        return verdict, sol


def recover_gains(values: dict, realisation: str = "identity_T") -> tuple[Gains, dict]:
    """Filter gains from a Theorem 3 solution by (26), for a choice of S21, S22 with R2 = S21^T S22^{-T} S21.

    .. math::

        G_0 = S_{21}^{-T}\\bar G_0 S_{21}^{-1} S_{22},\\; G_f = S_{21}^{-T}\\bar G_f S_{21}^{-1} S_{22},\\;
        H_0 = S_{21}^{-T}\\bar H_0,\\; H_f = S_{21}^{-T}\\bar H_f .

    ``realisation``:

    * ``"identity_T"``: S21 = S22 = R2, so T = diag(I, S22^{-1} S21) = I, Q = Q̄,
      and G = R2^{-T} Ḡ, H = R2^{-T} H̄.
    * ``"S21_identity"``: S21 = I, S22 = R2^{-T} (Algorithm 1 lets the user
      choose), giving G = Ḡ R2^{-T}, H = H̄. Similar to the first as a
      system, but the *estimate* x_f differs by the factor J = R2^T.

    Parameters
    ----------
    values : dict
        A Theorem 3 solution (``Theorem3Solution.values``).
    realisation : str
        One of :data:`REALISATIONS`.

    Returns
    -------
    tuple
        The gains and ``{"S": S, "T": T}``: the full slack S = [[S11, S12], [S21, S22]] with
        S12 = R1 S21^{-1} S22 (from R1 = S12 S22^{-1} S21, (23)) and T.

    Raises
    ------
    GainschedError
        On an unknown realisation.
    """
    R2 = values["R2"]
    if realisation == "identity_T":
        S21, S22 = R2.copy(), R2.copy()
    elif realisation == "S21_identity":
        S21, S22 = np.eye(R2.shape[0]), np.linalg.inv(R2).T
    else:
        raise GainschedError(f"realisation must be one of {REALISATIONS}, got {realisation!r}")
    S21inv_T = np.linalg.inv(S21).T
    right = np.linalg.solve(S21, S22)  # S21^{-1} S22
    gains = Gains(
        G0=S21inv_T @ values["G0"] @ right,
        Gf=S21inv_T @ values["Gf"] @ right,
        H0=S21inv_T @ values["H0"],
        Hf=S21inv_T @ values["Hf"],
    )
    S12 = values["R1"] @ right
    S = np.block([[values["S11"], S12], [S21, S22]])
    n = R2.shape[0]
    J = np.linalg.solve(S22, S21)
    T = np.block([[np.eye(n), np.zeros((n, n))], [np.zeros((n, n)), J]])
    return gains, {"S": S, "T": T}


def recover_output_gains(values: dict) -> Gains:
    r"""Gains of form (9) of the full-slack performance design (``output_slack``), estimate x̂ = L̄ x_f.

    With the ``identity_T`` realisation (J = I, so L_f = L̄), (26) gives G(p), H(p) for x_f and
    the estimate is x̂ = L̄ x_f. In the coordinates x̃ = L̄ x_f (L̄ nonsingular, x̃(0) = 0 when
    x_f(0) = 0) the filter is again of form (9) with x̃ itself the estimate:

    .. math::

        G_0' = \bar L G_0 \bar L^{-1},\; G_f' = \bar L G_f \bar L^{-1},\; H_0' = \bar L H_0,\; H_f' = \bar L H_f .

    Parameters
    ----------
    values : dict
        A solution of the ``output_slack`` performance problem (must hold ``Lbar``).

    Returns
    -------
    Gains

    Raises
    ------
    GainschedError
        If ``Lbar`` is missing or singular.
    """
    if values.get("Lbar") is None:
        raise GainschedError("values has no 'Lbar': not an output_slack performance solution")
    Lb = np.asarray(values["Lbar"], dtype=float)
    if np.linalg.cond(Lb) > 1e12:
        raise GainschedError(f"Lbar is singular (condition {np.linalg.cond(Lb):.3g})")
    g, _ = recover_gains(values, "identity_T")
    Li = np.linalg.inv(Lb)
    return Gains(Lb @ g.G0 @ Li, Lb @ g.Gf @ Li, Lb @ g.H0, Lb @ g.Hf)


def certified_cost(values: dict, X0, p1: float, p2: float) -> float:
    """The guaranteed cost max_{p in [p1, p2]} tr(Q̄(p) X0) of a performance solution, from its values.

    Q̄(p) = Q̄0 + p Q̄p is affine in p, so the maximum is at p1 or p2. With the point certified
    (every block strictly negative), sum_k E||e(k)||^2 <= this value for every f in the sector and
    every p(k) in [p1, p2], from E z̄(0) z̄(0)^T = X0 with x_f(0) = 0 (T-invariant).

    Parameters
    ----------
    values : dict
        A performance solution's values (``Theorem3Solution.values``), holding Q̄0 and Q̄p.
    X0 : ndarray (2n, 2n)
        E z̄(0) z̄(0)^T, the initial second moment of [x; x_f] with x_f(0) = 0.
    p1, p2 : float
        Bounds of p(k) (7).

    Returns
    -------
    float
        The guaranteed cost max(tr(Q̄(p1) X0), tr(Q̄(p2) X0)).
    """
    X0 = np.asarray(X0, dtype=float)
    return max(float(np.trace((values["Q0"] + p * values["Qp"]) @ X0)) for p in (p1, p2))


def output_certificate(values: dict) -> dict:
    """Theorem 1 certificate (Q0, Qp, S) of the full-slack performance design in the coordinates of its form-(9) gains.

    (26) with T = I gives the filter state x_f and the certificate Q̄, S = [[S11, R1], [R2, R2]];
    in the coordinates z' = [x; x̃], x̃ = L̄ x_f, i.e. z̄ = T' z' with T' = diag(I, L̄^{-1}),
    the certificate is Q' = T'^T Q̄ T', S' = T'^T S T' (V is unchanged).

    Parameters
    ----------
    values : dict
        A solution of the ``output_slack`` performance problem.

    Returns
    -------
    dict
        ``Q0``, ``Qp``, ``S`` for (12) with the gains of :func:`recover_output_gains`.
    """
    _, extra = recover_gains(values, "identity_T")
    n = values["R2"].shape[0]
    Tp = np.eye(2 * n)
    Tp[n:, n:] = np.linalg.inv(np.asarray(values["Lbar"], dtype=float))
    return {"Q0": Tp.T @ values["Q0"] @ Tp, "Qp": Tp.T @ values["Qp"] @ Tp, "S": Tp.T @ extra["S"] @ Tp}


def certificate_from_solution(values: dict, realisation: str = "identity_T") -> dict:
    """Theorem 1 certificate (Q0, Qp, S) in original coordinates: Q = T^{-T} Q̄ T^{-1} (proof of Thm 2).

    Parameters
    ----------
    values : dict
        A Theorem 3 solution.
    realisation : str
        One of :data:`REALISATIONS` (see :func:`recover_gains`).

    Returns
    -------
    dict
        ``Q0``, ``Qp``, ``S`` for (12), (27).
    """
    _, extra = recover_gains(values, realisation)
    Tinv = np.linalg.inv(extra["T"])
    return {"Q0": Tinv.T @ values["Q0"] @ Tinv, "Qp": Tinv.T @ values["Qp"] @ Tinv, "S": extra["S"]}


def congruence_residual(sys: System, values: dict, pairs, realisation: str = "identity_T",
                        gamma3_top: str = "HC") -> float:
    """Max-abs residual of Theorem 2's equivalence over the (p(k), p(k+1)) pairs ``pairs``.

    Compares the polytopic combination (28)-(33) of the vertices (24),
    :math:`\\sum \\alpha_i\\alpha_j\\alpha_r\\beta_l M^{ijrl}`, with the congruence
    diag(T, I, T, T, T)^T (12) diag(T, I, T, T, T) of the Theorem 1 matrix built
    from the gains (26), the slack S of (23) and Q = T^{-T} Q̄ T^{-1}. Zero (to
    rounding) when every block of (24)-(25) is read correctly.

    Parameters
    ----------
    sys : System
        The plant (1), (2), (6), its sector (3) and the bounds of p(k) (7).
    values : dict
        A Theorem 3 solution.
    pairs : iterable of (float, float)
        (p(k), p(k+1)) pairs.
    realisation : str
        One of :data:`REALISATIONS` (see :func:`recover_gains`).
    gamma3_top : {"HC", "zero"}
        Upper row of Γ3 in the vertices (24): H̄^i C, or 0 (the misreading; see the module docstring).

    Returns
    -------
    float
        Largest absolute entry of the difference over all pairs.
    """
    from .model import theorem1_matrix

    prob = Theorem3(sys, gamma3_top=gamma3_top)
    for name, var in prob.vars.items():
        var.value = values[name]
    gains, extra = recover_gains(values, realisation)
    cert = certificate_from_solution(values, realisation)
    T = extra["T"]
    ps = (sys.p1, sys.p2)
    span = sys.p2 - sys.p1
    nn, nz = 2 * sys.n, sys.nz
    big = np.zeros((4 * nn + nz, 4 * nn + nz))
    big[:nn, :nn] = T
    big[nn:nn + nz, nn:nn + nz] = np.eye(nz)
    for k in range(3):
        o = nn + nz + nn * k
        big[o:o + nn, o:o + nn] = T
    vertices = {(i, j, r, l): prob.vertex(ps[i], ps[j], ps[r], ps[l]).value
                for i in range(2) for j in range(2) for r in range(2) for l in range(2)}
    worst = 0.0
    for p, pn in pairs:
        a = ((sys.p2 - p) / span, (p - sys.p1) / span)  # (28)
        b = ((sys.p2 - pn) / span, (pn - sys.p1) / span)  # (30)
        combo = sum(a[i] * a[j] * a[r] * b[l] * V for (i, j, r, l), V in vertices.items())
        M = theorem1_matrix(sys, gains, cert["Q0"] + p * cert["Qp"], cert["Q0"] + pn * cert["Qp"], cert["S"], p)
        worst = max(worst, float(np.max(np.abs(big.T @ M @ big - combo))))
    return worst


class FixedGainsVertexLMI:
    r"""Theorem 3's vertex LMIs (24) for *given* gains, in the original coordinates.

    By the congruence diag(T, I, T, T, T) of the proof of Theorem 2, (24) with recovered gains
    (G, H) is feasible iff there are Q0, Qp > 0 (27) and a slack S = [S_ij] such that the 16
    vertex matrices of (12),

    .. math::

        \begin{bmatrix}
        -Q^i & * & * & * & * \\
        FZN & -2I & * & * & * \\
        S^T(\mathcal A^{ij} + \bar B F_1 Z N) & S^T\bar B & -\Lambda^l & * & * \\
        \Theta^{jr} S^T \bar C^i N & 0 & 0 & -\Theta^{jr}\Lambda^l & * \\
        \sigma^2 S^T \bar D N & 0 & 0 & 0 & -\sigma^2\Lambda^l
        \end{bmatrix} < 0,

    are negative definite, with :math:`Q^i = Q_0 + p_i Q_p`, :math:`\Lambda^l = S + S^T - Q^l`,
    :math:`\Theta^{jr} = p_j(1-p_r)`, :math:`\mathcal A^{ij} = [[A, 0], [p_j H(p_i) C, G(p_i)]]`,
    :math:`\bar C^i = [0; H(p_i) C]` (the multi-affine lifting (28)-(33) of p H(p), Θ H(p)).
    For fixed gains this is an LMI in (Q0, Qp, S); S21, S22 nonsingular is generic (a strict
    solution can be perturbed), so no realisation of (26) is imposed.

    Parameters
    ----------
    sys : System
        The plant (1), (2), (6), its sector (3) and the bounds of p(k) (7).
    gains : Gains
        The filter parameters of (9) to certify.
    eps : float
        Q0, Qp >= eps I in the proposing problem (the question itself is strict).
    bound : float
        Entry-wise bound on Q0, Qp, S (scale fixing).
    margin_cap : float
        The proposing problem maximises t <= margin_cap with vertices <= -t I.

    Returns
    -------
    FixedGainsVertexLMI
        :meth:`certify` gives the shared engine's verdict at a noise variance.
    """

    def __init__(self, sys: System, gains: Gains, eps: float = 1e-6, bound: float = 1e3, margin_cap: float = 0.1):
        self.sys, self.gains = sys, gains
        nn = 2 * sys.n
        self.sigma2 = cp.Parameter(nonneg=True, name="sigma2", value=sys.sigma2)
        self.Q0 = cp.Variable((nn, nn), symmetric=True, name="Q0")
        self.Qp = cp.Variable((nn, nn), symmetric=True, name="Qp")
        self.S = cp.Variable((nn, nn), name="S")
        self.t = cp.Variable(name="t")
        ps = (sys.p1, sys.p2)
        self._parts = {}  # sub-blocks shared by several vertices, built once (see Theorem3)
        cons = [cp.abs(self.Q0) <= bound, cp.abs(self.Qp) <= bound, cp.abs(self.S) <= bound, self.t <= margin_cap,
                self.Q0 >> eps * np.eye(nn), self.Qp >> eps * np.eye(nn)]
        blocks = []
        for i in range(2):
            for j in range(2):
                for r in range(2):
                    for l in range(2):
                        M = self.vertex(ps[i], ps[j], ps[r], ps[l])
                        Msym = M  # structurally symmetric: equals 0.5 (M + M^T) exactly (see Theorem3)
                        cons.append(Msym << -self.t * np.eye(M.shape[0]))
                        blocks.append((f"vertex{i}{j}{r}{l}", -Msym))
        blocks += [("Q0", self.Q0), ("Qp", self.Qp)]
        self.problem = cp.Problem(cp.Maximize(self.t), cons)
        from ...engines.certify import CertifiedLMI

        self.certifier = CertifiedLMI(blocks, problem=self.problem, drop=(self.t,))

    def vertex(self, pi: float, pj: float, pr: float, pl: float):
        """The vertex (i, j, r, l) of (24) in the original coordinates (see the class docstring).

        Parameters
        ----------
        pi, pj, pr, pl : float

        Returns
        -------
        cvxpy expression (8n + nz, 8n + nz)
        """
        s, g = self.sys, self.gains
        n, nn, nz = s.n, 2 * s.n, s.nz
        Gi, Hi = g.G(pi), g.H(pi)
        N = s.N
        Acal = np.block([[s.A, np.zeros((n, n))], [pj * Hi @ s.C, Gi]])
        Bbar = np.vstack([s.B, np.zeros((n, nz))])
        Cbar = np.vstack([np.zeros((n, n)), Hi @ s.C])
        Dbar = np.vstack([s.D, np.zeros((n, n))])
        theta = pj * (1.0 - pr)
        S = self.S
        part = self._part
        ST = part(("S^T",), lambda: S.T)
        Lam = part(("Lambda", pl), lambda: S + ST - (self.Q0 + pl * self.Qp))
        Om1 = ST @ (Acal + Bbar @ s.F1 @ s.Z @ N)
        Om2 = theta * (ST @ (Cbar @ N))
        SB = part(("SB",), lambda: ST @ Bbar)
        SD = part(("SD",), lambda: self.sigma2 * (ST @ (Dbar @ N)))
        mQ = part(("-Q", pi), lambda: -(self.Q0 + pi * self.Qp))
        FZN = s.F @ s.Z @ N
        O = np.zeros
        return cp.bmat([
            [mQ, FZN.T, Om1.T, Om2.T, SD.T],
            [FZN, -2 * np.eye(nz), SB.T, O((nz, nn)), O((nz, nn))],
            [Om1, SB, -Lam, O((nn, nn)), O((nn, nn))],
            [Om2, O((nn, nz)), O((nn, nn)), -theta * Lam, O((nn, nn))],
            [SD, O((nn, nz)), O((nn, nn)), O((nn, nn)), -self.sigma2 * Lam],
        ])

    def _part(self, key, build):
        """The sub-block ``build()`` of the vertices, built on first use and reused (keyed by ``key``)."""
        if key not in self._parts:
            self._parts[key] = build()
        return self._parts[key]

    def certify(self, sigma2: float):
        """Solve at ``sigma2`` and decide with the shared engine (status is information only).

        Infeasibility is certified by a checked dual certificate or by the necessary condition that
        (24) implies mean-square stability of (10): the frozen second-moment radius of (10) at the
        sector vertices and p in {p1, p2}, and the plant's for the worst linear gain of class (3)
        (:func:`.feasibility.sector_class_radius`), must be < 1.

        Parameters
        ----------
        sigma2 : float

        Returns
        -------
        tuple
            ``(Verdict, status, margin)``.
        """
        from .feasibility import RADIUS_MARGIN, sector_class_radius, with_sigma2
        from .model import frozen_radius, sector_cases

        self.sigma2.value = float(sigma2)
        try:
            solve_problem(self.problem)
            status = str(self.problem.status)
        except cp.error.SolverError as exc:  # pragma: no cover - solver failure path
            status = f"solver_error: {exc}"
        sys2 = with_sigma2(self.sys, sigma2)

        def necessary():
            rho = max([frozen_radius(sys2, self.gains, p, F) for p in (sys2.p1, sys2.p2)
                       for F in sector_cases(sys2).values()] + [sector_class_radius(sys2, sigma2)])
            return rho >= 1.0 + RADIUS_MARGIN, f"second-moment radius of (10) {rho:.12g} at sigma2 = {sigma2:.12g}"

        verdict = self.certifier.certify(status, necessary=necessary)
        margin = float(self.t.value) if self.t.value is not None else np.nan
        return verdict, status, margin


def zero_diagonal_blocks(coefficients) -> list:
    """Blocks of a strict system ``F_j(u) > 0`` with a diagonal entry identically zero in every coordinate.

    A positive definite matrix has a positive diagonal, so any such block makes the strict
    system infeasible for every value of the variables (the noise row of (24) at sigma^2 = 0).

    Parameters
    ----------
    coefficients : netrepro.engines.certify.LMICoefficients
        Constant and variable coefficients ``F0``, ``F`` of each named block.

    Returns
    -------
    list of (str, int)
        ``(block name, diagonal index)`` of each identically zero diagonal entry.
    """
    hits = []
    for name, F0, F in zip(coefficients.names, coefficients.F0, coefficients.F):
        const = np.abs(np.diagonal(F0))
        coef = np.abs(np.diagonal(F, axis1=-2, axis2=-1)).max(axis=0) if np.size(F) else np.zeros_like(const)
        hits += [(name, int(d)) for d in np.flatnonzero((const == 0) & (coef == 0))]
    return hits
