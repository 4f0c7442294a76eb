"""Pipeline steps of the `gainsched` paper: designs, stability checks, Monte Carlo, sensitivity, timing.

Each step is ``fn(params, inputs, outputs) -> {output name: DataFrame}`` and receives the
whole ``gainsched`` configuration section. The mathematics is in :mod:`.model` (plant,
filter, augmented system (10)-(11), sector (3)-(5), Theorem 1 (12), second moments,
simulation of Algorithm 1), :mod:`.design` (Theorem 3 vertex LMIs (24)-(25), gain
recovery (26), performance-aware variant) and :mod:`.tuning` (Monte Carlo tuned gains).

Designs compared (column ``design`` of the tables):

* ``paper``: the gains printed in Section IV;
* ``theorem3``: Theorem 3 feasibility, gains by (26) with S21 = S22 = R2 (T = I);
* ``theorem3_S21I``: the same LMI solution recovered with S21 = I (Algorithm 1
  leaves S21, S22 free): same stability, different estimate;
* ``fixed_gain``: Theorem 3 with Ḡf = H̄f = 0 (G_f = H_f = 0);
* ``performance``: Theorem 3 plus the bound sum_k E||e(k)||^2 <= gamma, minimised, with the full
  slack variable (a free estimate output L̄, :class:`.design.Theorem3` ``output_slack``); its
  cost is certified from the checked point (``certified_cost``);
* ``performance_tied``: the former performance design: the bound term [I, -I] added in the
  T-coordinates ties the estimate to S21 = S22 and the optimum collapses to x_f = 0;
* ``tuned_exact``: gains tuned on the exact second-moment cost (f = (F1+F2)/2 z, x(0) ~ N(0, I));
* ``tuned_fixed`` / ``tuned_scheduled``: gains of form (9) tuned by Monte Carlo
  (Nelder-Mead on common random numbers) for the named nonlinearity: what a
  filter of this structure can achieve when not restricted to a worst-case bound;
* ``zero``: the trivial estimate x_f = 0 (all gains zero): what any filter must beat.
"""

from __future__ import annotations

import dataclasses
import time

import numpy as np
import pandas as pd

from ...pipeline.io import read_table
from .model import (
    Gains,
    GainschedError,
    System,
    augmented_initial_moment,
    frozen_radius,
    gains_from_dict,
    p_schedule,
    realisation,
    scheduled_growth_rate,
    sector_cases,
    simulate,
    system_from_config,
    theorem1_grid_check,
    theorem1_lmi,
    zero_gains,
)
from .moments import error_mse, initial_moment, linear_gains, mode_matrices, second_moments
from .tuning import tune_gains, tune_gains_exact

__all__ = [
    "MATRICES",
    "gains_table",
    "gains_from_table",
    "load_solutions",
    "p_sequence",
    "design_step",
    "stability_step",
    "simulation_step",
    "exact_moments_step",
    "sensitivity_step",
    "scheduling_step",
    "timing_step",
    "vertex_lmi_step",
]

MATRICES = ("G0", "Gf", "H0", "Hf")


def _sys(params) -> System:
    return system_from_config(params["system"])


# ----------------------------------------------------------------------------- gains tables
def gains_table(design: str, gains: Gains) -> pd.DataFrame:
    """Long table ``design, matrix, row, col, value`` of one design's G0, Gf, H0, Hf (9).

    Parameters
    ----------
    design : str
        Name of the design (the ``design`` column).
    gains : Gains
        Its filter parameters G0, Gf, H0, Hf of (9).

    Returns
    -------
    pandas.DataFrame
        One row per matrix entry (row-major within each matrix).
    """
    rows = []
    for name, mat in gains.as_dict().items():
        mat = np.atleast_2d(mat)
        for (r, c), v in np.ndenumerate(mat):
            rows.append({"design": design, "matrix": name, "row": r, "col": c, "value": float(v)})
    return pd.DataFrame(rows, columns=["design", "matrix", "row", "col", "value"])


def gains_from_table(table: pd.DataFrame, design: str, sys: System) -> Gains:
    """Inverse of :func:`gains_table` for one design.

    Parameters
    ----------
    table : pandas.DataFrame
        A gains table (``results/gainsched/gains.csv``, columns ``design, matrix, row, col, value``).
    design : str
        The design to read.
    sys : System
        The plant; its n and m give the matrices' shapes (entries missing from the table are 0).

    Returns
    -------
    Gains
        The design's G0, Gf, H0, Hf of (9).

    Raises
    ------
    GainschedError
        If the table has no row of ``design``.
    """
    sub = table[table["design"] == design]
    if sub.empty:
        raise GainschedError(f"design {design!r} is not in the gains table")
    shapes = {"G0": (sys.n, sys.n), "Gf": (sys.n, sys.n), "H0": (sys.n, sys.m), "Hf": (sys.n, sys.m)}
    mats = {}
    for name, shape in shapes.items():
        m = np.zeros(shape)
        for r in sub[sub["matrix"] == name].itertuples():
            m[int(r.row), int(r.col)] = r.value
        mats[name] = m
    return Gains(**mats)


# ----------------------------------------------------------------------------- Monte Carlo helpers
def p_sequence(params, sys, horizon=None):
    """The configured scheduling sequence p(0..K-1) (Section IV), K = ``simulation.horizon`` by default.

    Parameters
    ----------
    params : dict
        The ``gainsched`` configuration; reads ``simulation.horizon`` and ``simulation.sine_omega``.
    sys : System
        The plant; its bounds p1, p2 of (7).
    horizon : int, optional
        K, overriding ``simulation.horizon``.

    Returns
    -------
    ndarray (K,)
        p(k) = p1 + (p2 - p1)|sin(omega k)|, k = 0..K-1 (:func:`.model.p_schedule`).
    """
    sim = params["simulation"]
    K = int(sim["horizon"] if horizon is None else horizon)
    return p_schedule(np.arange(K), sys.p1, sys.p2, float(sim["sine_omega"]))


def _mc_errors(sys, gains, p_seq, x0, seed, nonlinearity, xf0=None):
    return simulate(sys, gains, p_seq, x0, np.random.default_rng(seed), nonlinearity, xf0=xf0)


# ----------------------------------------------------------------------------- steps
def _append_tuned_designs(params, sys, tables: list, rows: list) -> None:
    """Append the tuned filters' gains tables and design rows: Monte Carlo tuned fixed and scheduled gains
    (Nelder-Mead, the scheduled search from the fixed optimum) and a filter tuned on the exact cost."""
    tune = params["tuning"]
    p_seq = p_sequence(params, sys, tune["horizon"])
    tuned = None
    for dname, sched in (("tuned_fixed", False), ("tuned_scheduled", True)):
        start = time.perf_counter()
        # the scheduled search starts from the fixed optimum, so it can only improve on it
        tuned, info = tune_gains(sys, p_seq, int(tune["n_runs"]), int(tune["seed"]),
                                 params["simulation"]["nonlinearity"], sched, int(tune["maxiter"]), start=tuned)
        tables.append(gains_table(dname, tuned))
        rows.append({"design": dname, "method": "Monte Carlo tuned (Nelder-Mead)", "status": "tuned",
                     "margin": np.nan, "objective": info["cost"], "solver_feasible": np.nan,
                     "solve_time_s": time.perf_counter() - start, "n_scalar_variables": len(MATRICES) and
                     (tuned.G0.size + tuned.H0.size) * (2 if sched else 1), "realisation": "direct",
                     "n_evaluations": info["n_eval"]})
    # a filter tuned on the exact cost (f = (F1+F2)/2 z, x(0) ~ N(0, I), the configured p(k)), from the
    # performance design: what the structure (9) achieves for one f, without a guarantee for the others
    start = time.perf_counter()
    p_full = p_sequence(params, sys)
    mid = 0.5 * (sys.F1 + sys.F2)
    perf = gains_from_table(pd.concat(tables, ignore_index=True), "performance", sys)
    tuned_ex, info = tune_gains_exact(sys, p_full, mid, augmented_initial_moment(np.eye(sys.n), sys.n), True,
                                      int(tune["maxiter"]), start=perf)
    tables.append(gains_table("tuned_exact", tuned_ex))
    rows.append({"design": "tuned_exact", "method": "tuned on the exact sum E||e||^2 (f = mid, x0 ~ N(0, I)), "
                 "Nelder-Mead from the performance design", "status": "tuned", "margin": np.nan,
                 "objective": info["cost"], "solver_feasible": np.nan, "solve_time_s": time.perf_counter() - start,
                 "n_scalar_variables": 2 * (tuned_ex.G0.size + tuned_ex.H0.size), "realisation": "direct",
                 "n_evaluations": info["n_eval"]})


def design_step(params, inputs, outputs):
    """All designs: paper gains, Theorem 3 (24)-(26) variants, performance-aware, MC-tuned, zero (x_f = 0).

    Writes ``gains`` (design, matrix, row, col, value) and ``designs`` (one row
    per design: solver status, margin, objective, solve time, realisation).

    Parameters
    ----------
    params : dict
        The ``gainsched`` configuration's ``system``, ``paper_gains``, ``lmi`` (``eps``, ``bound``,
        ``qp_positive``, ``margin_cap``, ``gamma3_top``), ``performance`` (``initial_cov``),
        ``tuning`` (``horizon``, ``n_runs``, ``seed``, ``maxiter``) and ``simulation`` sections.
    inputs : dict
        Only the step's code (no table is read).
    outputs : dict
        ``gains``, ``designs`` and ``solutions`` (``results/gainsched/gains.csv``,
        ``designs.csv``, ``lmi_solutions.csv``).

    Returns
    -------
    dict
        ``{"gains", "designs", "solutions": DataFrame, "provenance": {"solver_status": ...}}``;
        ``solutions`` holds every Theorem 3 variable entry by entry (problem, variable, row, col,
        value), read back by :func:`load_solutions`. Only designs whose point the shared engine
        certifies get gains and solutions (the solver's status is information).

    Raises
    ------
    GainschedError
        When ``theorem3`` or ``performance`` (whose gains later steps use) has no certified point:
        the message names the step, the design, the solver's status and the engine's evidence.
    """
    from .design import Theorem3, certified_cost, recover_gains, recover_output_gains

    sys = _sys(params)
    lmi = params["lmi"]
    tables, rows = [], []
    paper = gains_from_dict(params["paper_gains"], sys)
    tables.append(gains_table("paper", paper))
    rows.append({"design": "paper", "method": "printed in Section IV", "status": "printed", "margin": np.nan,
                 "objective": np.nan, "solver_feasible": np.nan, "solve_time_s": np.nan, "n_scalar_variables": 0,
                 "realisation": "unknown"})
    X0 = augmented_initial_moment(params["performance"]["initial_cov"], sys.n)
    common = dict(eps=float(lmi["eps"]), bound=float(lmi["bound"]), qp_positive=bool(lmi["qp_positive"]),
                  margin_cap=float(lmi["margin_cap"]), gamma3_top=lmi.get("gamma3_top", "HC"))
    problems = {
        "theorem3": dict(scheduled=True, performance=False),
        "fixed_gain": dict(scheduled=False, performance=False),
        "performance": dict(scheduled=True, performance=True, output_slack=True),
        "performance_tied": dict(scheduled=True, performance=True),
    }
    methods = {"theorem3": "Theorem 3 feasibility, scheduled", "fixed_gain": "Theorem 3 feasibility, fixed (Gf=Hf=0)",
               "performance": "Theorem 3 + error bound, full slack (free estimate output L̄), gamma minimised",
               "performance_tied": "Theorem 3 + error bound [I,-I] in T-coordinates (ties the estimate to "
                                   "S21 = S22): collapses to x_f = 0"}
    solutions, lmi_rows = {}, []
    for name, opts in problems.items():
        prob = Theorem3(sys, X0=X0 if opts["performance"] else None, **opts, **common)
        sol = prob.solve()
        solutions[name] = sol
        verdict, slack, evidence = _decide_point(prob, sol, sys, with_evidence=True)
        if verdict != "feasible":  # no certified point: no design (its gains would carry no guarantee)
            if name in _NEEDED_DESIGNS:
                raise GainschedError(
                    f"gainsched_design: the {name} design of Theorem 3 is {verdict} at sigma2 = {sys.sigma2:g} "
                    f"(solver status {sol.status}; engine: {evidence}): the steps that use its gains cannot run")
            rows.append({"design": name, "method": "Theorem 3", "status": sol.status, "margin": sol.margin,
                         "objective": sol.objective, "solver_feasible": False, "solve_time_s": sol.solve_time_s,
                         "n_scalar_variables": sol.n_scalar_variables, "realisation": "", "verdict": verdict,
                         "certified_slack": slack})
            continue
        for var, val in sol.values.items():
            for (r, c), x in np.ndenumerate(np.atleast_2d(val)):
                lmi_rows.append({"problem": name, "variable": var, "row": r, "col": c, "value": float(x)})
        realisations = [("identity_T", name)]
        if name == "theorem3":
            realisations.append(("S21_identity", "theorem3_S21I"))
        for real, dname in realisations:
            if opts.get("output_slack"):
                gains, real = recover_output_gains(sol.values), "identity_T + output L̄"
            else:
                gains, _ = recover_gains(sol.values, real)
            tables.append(gains_table(dname, gains))
            method = methods[name] + (" (S21 = I realisation)" if dname == "theorem3_S21I" else "")
            cost = certified_cost(sol.values, X0, sys.p1, sys.p2) if opts["performance"] else np.nan
            rows.append({"design": dname, "method": method, "status": sol.status, "margin": sol.margin,
                         "certified_cost": cost if verdict == "feasible" else np.nan,
                         "objective": sol.objective, "solver_feasible": sol.solver_feasible,
                         "solve_time_s": sol.solve_time_s, "n_scalar_variables": sol.n_scalar_variables,
                         "realisation": real, "verdict": verdict, "certified_slack": slack})
    _append_tuned_designs(params, sys, tables, rows)
    tables.append(gains_table("zero", zero_gains(sys)))
    rows.append({"design": "zero", "method": "x_f = 0 (trivial estimate)", "status": "given", "margin": np.nan, "objective": np.nan,
                 "solver_feasible": np.nan, "solve_time_s": np.nan, "n_scalar_variables": 0, "realisation": ""})
    return {"gains": pd.concat(tables, ignore_index=True), "designs": pd.DataFrame(rows),
            "solutions": pd.DataFrame(lmi_rows, columns=["problem", "variable", "row", "col", "value"]),
            "provenance": {"solver_status": {k: v.status for k, v in solutions.items()}}}


# Theorem 3 designs whose gains later steps use (stability certificates, the exact tuning's start, evidence)
_NEEDED_DESIGNS = ("theorem3", "performance")


def _decide_point(prob, sol, sys, with_evidence=False):
    """Certified verdict of a solved Theorem 3 problem at the system's sigma^2 (no re-solve), by the shared engine."""
    from .feasibility import necessary_condition

    v = prob.certifier.certify(sol.status, necessary=necessary_condition(sys, sys.sigma2))
    out = (v.verdict, (v.point.slack if v.point is not None else np.nan))
    return out + (v.evidence,) if with_evidence else out


def _no_decision(rows, step, what):
    """Stop a step whose every LMI decision is undecided, naming the step and the solver statuses.

    Parameters
    ----------
    rows : list of dict
        The step's rows so far, each with ``verdict`` and ``status``.
    step : str
        The rule's name (for the message).
    what : str
        What was decided (for the message).

    Raises
    ------
    GainschedError
        If there is at least one row and every ``verdict`` is ``undecided``.
    """
    verdicts = [r.get("verdict") for r in rows]
    if verdicts and all(v == "undecided" for v in verdicts):
        statuses = sorted({str(r.get("status")) for r in rows})
        raise GainschedError(f"{step}: every decision of {what} is undecided (no certified point, no certificate of "
                             f"infeasibility); solver statuses: {', '.join(statuses)}")


def load_solutions(path) -> dict:
    """LMI solutions stored by :func:`design_step` (``lmi_solutions.csv``): problem -> {variable: ndarray}.

    Parameters
    ----------
    path : str or Path
        The ``lmi_solutions.csv`` table (problem, variable, row, col, value).

    Returns
    -------
    dict
        Problem name -> variable name -> matrix (shape from the largest row and column index).
    """
    sols = read_table(path)
    out = {}
    for name, sub in sols.groupby("problem", sort=False):
        values = {}
        for var, vs in sub.groupby("variable"):
            mat = np.zeros((int(vs["row"].max()) + 1, int(vs["col"].max()) + 1))
            mat[vs["row"].astype(int), vs["col"].astype(int)] = vs["value"]
            values[var] = mat
        out[name] = values
    return out


def _certificate_for(design, sys, gains, params):
    """Theorem 1 test of given gains: a fresh LMI solve on a grid, then a fine-grid eigenvalue check."""
    lmi = params["lmi"]
    res = theorem1_lmi(sys, gains, n_grid=int(lmi["theorem1_grid"]), bound=float(lmi["bound"]),
                       margin_cap=float(lmi["margin_cap"]))
    out = {"design": design, "thm1_status": res.status, "thm1_margin": res.margin,
           "thm1_solver_feasible": res.solver_feasible, "thm1_pairs": res.n_pairs, "thm1_verdict": res.verdict}
    if res.Q0 is not None:
        worst, qmin, wv = theorem1_grid_check(sys, gains, res.Q0, res.Qp, res.S, int(lmi["check_grid"]))
    else:
        worst, qmin, wv = np.nan, np.nan, np.nan
    out.update({"thm1_max_eig_grid": worst, "thm1_max_eig_vertices": wv, "thm1_min_eig_Q": qmin,
                "thm1_certified": bool(res.verdict == "feasible" and res.Q0 is not None and worst < 0 and qmin > 0)})
    return out


def stability_step(params, inputs, outputs):
    """Independent checks of every design: Theorem 1 (12) on vertices and a fine grid, second-moment radii.

    ``stability``: design, p, sector_case, spectral_radius (frozen p, linear f = F z,
    F at the vertices of the diagonal sector). ``theorem1``: per design the
    Theorem 1 solve (status, margin), the fine-grid maximum eigenvalue, the
    check of the Theorem 3 certificate itself (rebuilt Q, S of (23), (27)),
    and the growth rate of E||z||^2 along the scheduled p(k).

    Parameters
    ----------
    params : dict
        The ``gainsched`` configuration's ``system``, ``lmi`` (``check_grid`` and the Theorem 1
        solve settings), ``stability`` (``n_p``: points of the p grid) and ``simulation`` sections.
    inputs : dict
        ``gains`` (``results/gainsched/gains.csv``) and ``solutions`` (``lmi_solutions.csv``).
    outputs : dict
        ``stability`` and ``theorem1`` (``results/gainsched/stability.csv``, ``theorem1.csv``).

    Returns
    -------
    dict
        ``{"stability": DataFrame, "theorem1": DataFrame}``.
    """
    from .design import certificate_from_solution, output_certificate, recover_gains, recover_output_gains

    sys = _sys(params)
    table = read_table(inputs["gains"])
    designs = list(dict.fromkeys(table["design"]))
    ps = np.linspace(sys.p1, sys.p2, int(params["stability"]["n_p"]))
    cases = sector_cases(sys)
    srows, trows = [], []
    p_seq = p_sequence(params, sys)
    lmi = params["lmi"]
    # Theorem 3 certificates, rebuilt from the stored LMI solution (checks the algebra of (22)-(23), (26)-(27))
    cert = {}
    for name, values in load_solutions(inputs["solutions"]).items():
        perf = name.startswith("performance")
        reals = [("identity_T", name)] + ([("S21_identity", "theorem3_S21I")] if name == "theorem3" else [])
        if "Lbar" in values:  # full-slack performance design: certificate in the coordinates of its gains
            c = output_certificate(values)
            cert[name] = theorem1_grid_check(sys, recover_output_gains(values), c["Q0"], c["Qp"], c["S"],
                                             int(lmi["check_grid"]), performance=True, multiplier=c["multiplier"])
            continue
        lam = float(np.asarray(values["lam"]).ravel()[0]) if "lam" in values else 1.0
        for real, dname in reals:
            g, _ = recover_gains(values, real)
            c = certificate_from_solution(values, real)
            cert[dname] = theorem1_grid_check(sys, g, c["Q0"], c["Qp"], c["S"], int(lmi["check_grid"]),
                                              performance=perf and real == "identity_T", multiplier=lam)
    for d in designs:
        gains = gains_from_table(table, d, sys)
        for p in ps:
            for cname, F in cases.items():
                srows.append({"design": d, "p": float(p), "sector_case": cname,
                              "spectral_radius": frozen_radius(sys, gains, float(p), F)})
        row = _certificate_for(d, sys, gains, params)
        w = cert.get(d, (np.nan, np.nan, np.nan))
        row.update({"thm3_cert_max_eig_grid": w[0], "thm3_cert_min_eig_Q": w[1], "thm3_cert_max_eig_vertices": w[2]})
        row["scheduled_growth_max"] = max(scheduled_growth_rate(sys, gains, p_seq, F) for F in cases.values())
        row["filter_radius_max"] = max(float(np.max(np.abs(np.linalg.eigvals(gains.G(p))))) for p in ps)
        trows.append(row)
    return {"stability": pd.DataFrame(srows), "theorem1": pd.DataFrame(trows)}


def simulation_step(params, inputs, outputs):
    """Monte Carlo of Algorithm 1 for every design: errors.csv, error_summary.csv, sample_paths.csv.

    Runs are vectorised, time is looped; the same random numbers (seed) for
    every design. ``errors``: mean over runs of e1, e2 with a 95% band (2.5 and
    97.5 percentiles over runs), the per-component RMS error ``e1_rms``, ``e2_rms``
    (sqrt of the mean of e_i(k)^2 over runs; for x(0) ~ N(0, I) the mean error is zero for every
    design by symmetry, so the RMS is the informative quantity) and mse(k) = E||e(k)||^2 with
    its standard error ``mse_se``; ``error_summary``: sum_k mse(k) for the fixed x0
    and for x0 ~ N(0, initial_cov), with the standard error of the per-run sum.

    This Monte Carlo is for the configured (nonlinear) f only; for linear f the exact
    second moments are in ``exact_moments.csv`` (:func:`exact_moments_step`). With a
    multiplicative noise ||e||^2 is heavy-tailed: the standard errors are sample
    standard errors and understate the uncertainty where the fourth moment is large.

    Parameters
    ----------
    params : dict
        The ``gainsched`` configuration's ``system``, ``simulation`` (``horizon``, ``sine_omega``,
        ``n_runs``, ``x0``, ``xf0``, ``seed``, ``band``, ``nonlinearity``) and ``performance``
        (``initial_cov``) sections.
    inputs : dict
        ``gains`` (``results/gainsched/gains.csv``).
    outputs : dict
        ``errors``, ``error_summary`` and ``paths`` (``results/gainsched/errors.csv``,
        ``error_summary.csv``, ``sample_paths.csv``).

    Returns
    -------
    dict
        ``{"errors", "error_summary", "paths": DataFrame}``; ``paths`` is the first run's e1, e2
        and p(k) per design (fixed x0).
    """
    sys = _sys(params)
    sim = params["simulation"]
    table = read_table(inputs["gains"])
    designs = list(dict.fromkeys(table["design"]))
    p_seq = p_sequence(params, sys)
    R = int(sim["n_runs"])
    x0_fixed = np.tile(np.asarray(sim["x0"], dtype=float), (R, 1))
    cov = np.asarray(params["performance"]["initial_cov"], dtype=float)
    x0_rand = np.random.default_rng(int(sim["seed"]) + 7).multivariate_normal(np.zeros(sys.n), cov, size=R)
    q_lo, q_hi = 100 * (1 - sim["band"]) / 2, 100 * (1 + sim["band"]) / 2
    erows, srows, prow = [], [], []
    ks = np.arange(len(p_seq) + 1)
    for d in designs:
        gains = gains_from_table(table, d, sys)
        e = _mc_errors(sys, gains, p_seq, x0_fixed, int(sim["seed"]), sim["nonlinearity"], sim.get("xf0"))
        mean = e.mean(0)
        lo, hi = np.percentile(e, q_lo, axis=0), np.percentile(e, q_hi, axis=0)
        sq = (e ** 2).sum(-1)
        mse = sq.mean(0)
        rms = np.sqrt((e ** 2).mean(0))
        mse_se = sq.std(0, ddof=1) / np.sqrt(R)
        for k in ks:
            erows.append({"design": d, "initial_state": "fixed_x0", "k": int(k), "e1_mean": mean[k, 0],
                          "e2_mean": mean[k, 1], "e1_lo": lo[k, 0], "e1_hi": hi[k, 0], "e2_lo": lo[k, 1],
                          "e2_hi": hi[k, 1], "mse": mse[k], "mse_se": mse_se[k], "e1_rms": rms[k, 0],
                          "e2_rms": rms[k, 1]})
            prow.append({"design": d, "k": int(k), "p": float(p_seq[k]) if k < len(p_seq) else np.nan,
                         "e1": e[0, k, 0], "e2": e[0, k, 1]})
        srows.append({"design": d, "initial_state": "fixed_x0", "sum_mse": float(mse.sum()),
                      "sum_mse_se": float(sq.sum(1).std(ddof=1) / np.sqrt(R))})
        er = _mc_errors(sys, gains, p_seq, x0_rand, int(sim["seed"]) + 1, sim["nonlinearity"])
        sr = (er ** 2).sum(-1)
        gmean = er.mean(0)
        glo, ghi = np.percentile(er, q_lo, axis=0), np.percentile(er, q_hi, axis=0)
        gse = sr.std(0, ddof=1) / np.sqrt(R)
        grms = np.sqrt((er ** 2).mean(0))
        for k in ks:
            erows.append({"design": d, "initial_state": "gaussian", "k": int(k), "e1_mean": gmean[k, 0],
                          "e2_mean": gmean[k, 1], "e1_lo": glo[k, 0], "e1_hi": ghi[k, 0], "e2_lo": glo[k, 1],
                          "e2_hi": ghi[k, 1], "mse": sr.mean(0)[k], "mse_se": gse[k], "e1_rms": grms[k, 0],
                          "e2_rms": grms[k, 1]})
        srows.append({"design": d, "initial_state": "gaussian", "sum_mse": float(sr.mean(0).sum()),
                      "sum_mse_se": float(sr.sum(1).std(ddof=1) / np.sqrt(R))})
    return {"errors": pd.DataFrame(erows), "error_summary": pd.DataFrame(srows), "paths": pd.DataFrame(prow)}


def exact_moments_step(params, inputs, outputs):
    """Exact E||e(k)||^2 of every design for linear f = F z, F in {F1, F2, mid}, by the recursion of :mod:`.moments`.

    Initial states: ``gaussian`` (x(0) ~ N(0, I), x_f(0) = 0) and ``x0`` (the configured x0 and
    x_f(0) = xf0; the ``zero`` design keeps x_f = 0 throughout). ``exact_moments``: design,
    nonlinearity, initial_state, sum_mse (k = 0..K), final_mse (k = K); ``exact_mse``: the same
    per k. The designs named in ``simulation.flipped`` are repeated as ``<design>_flipped``: the
    same filter with the opposite sign of its state (H -> -H, :func:`.model.realisation` with
    J = -I); ``performance`` (performance.csv) keeps the designs of the gains table.

    Parameters
    ----------
    params : dict
        The ``gainsched`` configuration's ``system`` and ``simulation`` (``horizon``, ``sine_omega``,
        ``x0``, ``xf0``, ``flipped``) sections.
    inputs : dict
        ``gains`` and ``designs`` (``results/gainsched/gains.csv``, ``designs.csv``).
    outputs : dict
        ``table``, ``per_k`` and ``performance`` (``results/gainsched/exact_moments.csv``,
        ``exact_mse.csv``, ``performance.csv``).

    Returns
    -------
    dict
        ``{"table", "per_k", "performance": DataFrame}``; ``performance`` has per design its
        certified cost beside ``sum_mse_<initial state>_<F>`` and the worst over F.
    """
    sys = _sys(params)
    sim = params["simulation"]
    table = read_table(inputs["gains"])
    designs = list(dict.fromkeys(table["design"]))
    p_seq = p_sequence(params, sys)
    n = sys.n
    x0 = np.asarray(sim["x0"], dtype=float)
    xf0 = np.asarray(sim.get("xf0", np.zeros(n)), dtype=float)
    starts = {"gaussian": lambda d: initial_moment(np.zeros(n), np.eye(n), np.zeros(n)),
              "x0": lambda d: initial_moment(x0, np.zeros((n, n)), np.zeros(n) if d == "zero" else xf0)}
    keys, M1s, M0s, X0s = [], [], [], []
    # the opposite sign of the filter state (J = -I, an equally valid realisation of Algorithm 1)
    flipped = {f"{d}_flipped": realisation(gains_from_table(table, d, sys), -np.eye(n))
               for d in sim.get("flipped", []) if d in designs}
    for d in designs + list(flipped):
        gains = flipped[d] if d in flipped else gains_from_table(table, d, sys)
        for fname, F in linear_gains(sys).items():
            M1, M0, W = mode_matrices(sys, gains, p_seq, F)
            for sname, start in starts.items():
                keys.append((d, fname, sname))
                M1s.append(M1)
                M0s.append(M0)
                X0s.append(start(d))
    X = second_moments(np.array(M1s), np.array(M0s), W, p_seq, sys.sigma2, np.array(X0s))
    mse = error_mse(X)
    ks = np.arange(mse.shape[1])
    summary = pd.DataFrame([{"design": d, "nonlinearity": f, "initial_state": s, "sum_mse": float(m.sum()),
                             "final_mse": float(m[-1])} for (d, f, s), m in zip(keys, mse)])
    # the comparison of issue 17: certified cost (only where the LMI point is certified) beside the exact errors
    designs_tab = read_table(inputs["designs"]).set_index("design")
    comp = []
    for d in designs:
        sub = summary[summary["design"] == d].set_index(["initial_state", "nonlinearity"])["sum_mse"]
        row = {"design": d, "method": designs_tab.loc[d, "method"] if d in designs_tab.index else "",
               "certified_cost": float(designs_tab["certified_cost"].get(d, np.nan))
               if "certified_cost" in designs_tab else np.nan}
        for st in starts:
            for f in linear_gains(sys):
                row[f"sum_mse_{st}_{f}"] = float(sub.loc[(st, f)])
            row[f"sum_mse_{st}_worst"] = float(max(sub.loc[(st, f)] for f in linear_gains(sys)))
        comp.append(row)
    per_k = pd.DataFrame({"design": np.repeat([k[0] for k in keys], ks.size),
                          "nonlinearity": np.repeat([k[1] for k in keys], ks.size),
                          "initial_state": np.repeat([k[2] for k in keys], ks.size),
                          "k": np.tile(ks, len(keys)), "mse": mse.ravel()})
    return {"table": summary, "per_k": per_k, "performance": pd.DataFrame(comp)}


# the method and sector class of each certified threshold of feasibility_limit.csv
_LIMIT_METHODS = {"scheduled": "Theorem 3 (24)-(25), gain-scheduled", "fixed_gain": "Theorem 3 with Gf = Hf = 0",
                  "zero": "Theorem 3 with all gains 0 (x_f = 0)",
                  "printed_gains": "vertex LMIs (24) with the printed gains, general slack S",
                  "plant": "plant Lyapunov + S-procedure LMI, scalar multiplier (lossless for one quadratic constraint)",
                  "plant_componentwise": "plant Lyapunov + S-procedure LMI, diagonal multiplier"}
_LIMIT_CLASSES = {"plant_componentwise": "componentwise sectors"}


def _limit_row(name, lo, hi, certified, between, n_solves, infeasible_by, role="sufficient"):
    """One row of feasibility_limit.csv: the certified bracket ``[lo, hi]`` of a design's threshold in sigma^2."""
    return {"design": name, "sigma2_max": lo, "sigma2_lo": lo, "sigma2_hi": hi, "certified": bool(certified),
            "undecided_from": min(between) if between else np.nan, "n_undecided": len(between),
            "n_solves": n_solves, "method": _LIMIT_METHODS[name], "infeasible_by": infeasible_by,
            "sector_class": _LIMIT_CLASSES.get(name, "condition (3)"), "role": role}


def _necessary_limits(base, nec) -> list:
    """The rows of the necessary ends of feasibility_limit.csv: the worst linear gain of each sector class
    (closed-form limit, radius checked at both ends)."""
    from .feasibility import worst_sector_gain

    worst = worst_sector_gain(base)
    limits = []
    for name, sector, text in (
            ("plant_necessary", "condition3",
             f"worst linear gain K = (F1+F2)/2 + U(F2-F1)/2, U orthogonal ({'reflection' if worst['reflect'] else 'rotation'}"
             f" by {worst['theta']:.6f} rad; K = [" + "; ".join(", ".join(f"{x:.5g}" for x in r) for r in worst["K"])
             + "]), "
             f"closed-form limit {worst['value']:.9g}"),
            ("plant_componentwise_necessary", "componentwise", "diagonal sector vertices F = diag(F1_ii or F2_ii)")):
        below, above = nec[sector]
        ok = bool(np.isfinite(above))  # necessary_limit's bisection keeps radius >= 1 + RADIUS_MARGIN at `above`
        limits.append({"design": name, "sigma2_max": np.nan, "sigma2_lo": below, "sigma2_hi": above,
                       "certified": ok, "undecided_from": np.nan, "n_undecided": 0, "n_solves": 0,
                       "method": text,
                       "infeasible_by": f"plant second-moment radius >= 1 + 1e-9 at sigma2 = {above:.9g} for a linear "
                                        "gain of the class (not mean-square stable for that f)",
                       "sector_class": "condition (3)" if sector == "condition3" else "componentwise sectors",
                       "role": "necessary"})
    return limits


def _z22_limits(base, params, common, guesses) -> list:
    """The rows of feasibility_limit.csv for the other readings of Z[1][1] (reconstruction Z22): the plant
    bracket for class (3) and Theorem 3's certified end, designs ``"<design> Z22=<value>"``."""
    from ...engines.certify import bisect_certified

    from .design import Theorem3
    from .feasibility import PlantLMI, necessary_limit

    lmi, sens = params["lmi"], params["sensitivity"]
    lo0, hi0, tol = float(sens["sigma2_lo"]), float(sens["sigma2_hi"]), float(sens["tol"])
    limits = []
    for z22 in sorted({float(z) for z in sens.get("z22_readings", [])} - {float(base.Z[1, 1])}):
        Zz = base.Z.copy()
        Zz[1, 1] = z22
        sysz = dataclasses.replace(base, Z=Zz)
        tag = f" Z22={z22:g}"
        below, above = necessary_limit(sysz, lo0, hi0, sector="condition3")
        plant = PlantLMI(sysz, margin_cap=float(lmi["margin_cap"]), bound=float(lmi["bound"]), multiplier="scalar")
        prob = Theorem3(sysz, scheduled=True, **common)
        top = above if np.isfinite(above) else hi0
        for name, decide in (("plant", plant.certify), ("scheduled", lambda s2, prob=prob: prob.certify(s2)[0])):
            b = bisect_certified(decide, lo0, top, tol=tol, feasible_above=False, guess=guesses.get("condition3"),
                                 width=2 * tol)
            ends = (b.feasible_end, b.infeasible_end)
            between = [x for x in b.undecided if ends[0] < x < ends[1]] if b.certified else list(b.undecided)
            row = _limit_row(name, b.feasible_end, b.infeasible_end, b.certified, between, b.n_evals,
                             b.verdicts[b.infeasible_end].evidence if b.certified else "")
            limits.append(dict(row, design=name + tag, Z22=z22))
        limits.append({"design": "plant_necessary" + tag, "sigma2_max": np.nan, "sigma2_lo": below,
                       "sigma2_hi": above, "certified": bool(np.isfinite(above)), "undecided_from": np.nan,
                       "n_undecided": 0, "n_solves": 0,
                       "method": f"worst linear gain K = (F1+F2)/2 + U(F2-F1)/2, U orthogonal, with Z22 = {z22:g}",
                       "infeasible_by": f"plant second-moment radius >= 1 + 1e-9 at sigma2 = {above:.9g} for a linear "
                                        "gain of the class (not mean-square stable for that f)",
                       "sector_class": "condition (3)", "role": "necessary", "Z22": z22})
    return limits


def sensitivity_step(params, inputs, outputs):
    """Certified feasibility against sigma^2: Theorem 3 (scheduled, fixed gain, zero filter), the printed
    gains' vertex LMIs, and the plant's own limit for the paper's class (3) and for componentwise sectors.

    Every decision comes from the shared engine (:mod:`netrepro.engines.certify`): ``feasible``
    (its eigenvalue check of the returned point), ``infeasible`` (the plant's second-moment
    radius >= 1 for a linear gain of the class, a necessary condition of every criterion, or a
    checked dual certificate) or ``undecided``; the solver status and margin are information.
    ``table``: the sigma^2 grid (``sigma2_grid`` and the finer ``sigma2_zoom`` near the limit)
    per design; at and beyond the class's necessary end the verdict is the necessary condition's
    and no LMI is solved (status ``not solved``, margin NaN). ``limits`` (feasibility_limit.csv): per criterion the certified-feasible end
    ``sigma2_lo`` (= ``sigma2_max``) and certified-infeasible end ``sigma2_hi`` of the engine's
    certified bisection, the undecided points between them, and whether both ends are
    certified; ``sector_class`` (condition (3) or componentwise sectors) and ``role``
    (``sufficient``: an LMI; ``necessary``: the sigma^2 at which the worst linear gain of the class
    makes the plant's second-moment radius reach 1, :func:`.feasibility.worst_sector_gain`).
    For class (3) the plant's limit lies between the ``plant`` row's feasible end and the
    ``plant_necessary`` row's infeasible end.

    Parameters
    ----------
    params : dict
        The ``gainsched`` configuration's ``system``, ``paper_gains``, ``lmi`` and ``sensitivity``
        (``sigma2_grid``, ``sigma2_zoom``, the bisection bracket ``sigma2_lo``, ``sigma2_hi``, ``tol``, and
        ``z22_readings``: the declared range of reconstruction Z22, at whose other readings the rows
        ``plant Z22=<value>``, ``plant_necessary Z22=<value>`` and ``scheduled Z22=<value>`` are added;
        column ``Z22`` gives every row's reading) sections.
    inputs : dict
        Only the step's code (no table is read).
    outputs : dict
        ``table`` and ``limits`` (``results/gainsched/sensitivity.csv``, ``feasibility_limit.csv``).

    Returns
    -------
    dict
        ``{"table": DataFrame, "limits": DataFrame}``.
    """
    from ...engines.certify import bisect_certified

    from .design import FixedGainsVertexLMI, Theorem3
    from .feasibility import PlantLMI, necessary_condition, necessary_limit

    base = _sys(params)
    lmi = params["lmi"]
    sens = params["sensitivity"]
    grid = np.array(sorted({float(s) for s in sens["sigma2_grid"]} | {float(s) for s in sens.get("sigma2_zoom", [])}))
    lo0, hi0, tol = float(sens["sigma2_lo"]), float(sens["sigma2_hi"]), float(sens["tol"])
    nec = {c: necessary_limit(base, lo0, hi0, sector=c) for c in ("condition3", "componentwise")}
    common = dict(eps=float(lmi["eps"]), bound=float(lmi["bound"]), qp_positive=bool(lmi["qp_positive"]),
                  margin_cap=float(lmi["margin_cap"]), gamma3_top=lmi.get("gamma3_top", "HC"))
    problems = {"scheduled": Theorem3(base, scheduled=True, **common),
                "fixed_gain": Theorem3(base, scheduled=False, **common),
                "zero": Theorem3(base, zero_filter=True, **common)}
    printed = FixedGainsVertexLMI(base, gains_from_dict(params["paper_gains"], base), eps=float(lmi["eps"]),
                                  bound=float(lmi["bound"]), margin_cap=float(lmi["margin_cap"]))
    plants = {"plant": PlantLMI(base, margin_cap=float(lmi["margin_cap"]), bound=float(lmi["bound"]),
                                multiplier="scalar"),
              "plant_componentwise": PlantLMI(base, margin_cap=float(lmi["margin_cap"]), bound=float(lmi["bound"]),
                                              multiplier="diagonal")}

    def decider(name):
        if name in plants:
            def decide(s2, plant=plants[name]):
                v = plant.certify(s2)
                return v, (float(plant.t.value) if plant.t.value is not None else np.nan)
        elif name == "printed_gains":
            def decide(s2):
                v, _, margin = printed.certify(s2)
                return v, margin
        else:
            def decide(s2, prob=problems[name]):
                v, sol = prob.certify(s2)
                return v, sol.margin
        return decide

    rows, limits = [], []

    # the plants first (small LMIs): the class-(3) plant's threshold is then the guess of the Theorem 3
    # bisections (a guess changes the number of solves, never the answer)
    guesses = {}
    for name in ("plant", "plant_componentwise", "scheduled", "fixed_gain", "zero"):
        decide = decider(name)
        sector = "componentwise" if name == "plant_componentwise" else "condition3"
        top = nec[sector][1] if np.isfinite(nec[sector][1]) else hi0
        for s2 in grid:
            if s2 >= nec[sector][1]:  # certified infeasible without a solve: the class's necessary condition fails
                violated, text = necessary_condition(base, float(s2), sector)()
                assert violated, text  # necessary_limit's bisection guarantees it (radius monotone in sigma^2)
                rows.append({"variant": name, "sigma2": float(s2), "status": "not solved", "margin": np.nan,
                             "certified_slack": np.nan, "verdict": "infeasible",
                             "evidence": f"necessary condition violated: {text}", "kind": "grid"})
                continue
            v, margin = decide(float(s2))
            rows.append({"variant": name, "sigma2": float(s2), "status": v.solver_status, "margin": margin,
                         "certified_slack": v.point.slack if v.point is not None else np.nan,
                         "verdict": v.verdict, "evidence": v.evidence, "kind": "grid"})
        b = bisect_certified(lambda s2, decide=decide: decide(s2)[0], lo0, top, tol=tol, feasible_above=False,
                             guess=guesses.get(sector), width=2 * tol)
        if b.certified:
            guesses.setdefault(sector, b.feasible_end)
        ends = (b.feasible_end, b.infeasible_end)
        between = [x for x in b.undecided if ends[0] < x < ends[1]] if b.certified else list(b.undecided)
        limits.append(_limit_row(name, b.feasible_end, b.infeasible_end, b.certified, between, b.n_evals,
                                 b.verdicts[b.infeasible_end].evidence if b.certified else ""))
    # the printed gains (grid in vertex_lmis.csv): certified feasible at the plant's feasible end, infeasible from
    # the class-(3) necessary end on ((24) implies mean-square stability of the plant); feasibility of (24) is
    # monotone in sigma^2 > 0 (sigma^2 enters through sigma^2 S^T D̄ N Λ^{-1} N^T D̄^T S >= 0 by a Schur complement)
    s2_ok = guesses.get("condition3", np.nan)
    v_ok = decider("printed_gains")(s2_ok)[0] if np.isfinite(s2_ok) else None
    ok = v_ok is not None and v_ok.feasible and np.isfinite(nec["condition3"][1])
    limits.append(_limit_row("printed_gains", s2_ok if ok else np.nan, nec["condition3"][1], ok, [], 1,
                             "necessary condition: the plant for the worst linear gain of class (3) (plant_necessary)"))
    limits += _necessary_limits(base, nec)
    for row in limits:
        row["Z22"] = float(base.Z[1, 1])
    limits += _z22_limits(base, params, common, guesses)
    return {"table": pd.DataFrame(rows), "limits": pd.DataFrame(limits)}


def scheduling_step(params, inputs, outputs):
    """What gain scheduling buys over fixed gains (claim ``less_conservative``; issue 27).

    Two comparisons that can tell the families apart (``scheduling.csv``, one row per family and
    comparison):

    * ``guaranteed_cost``: the certified cost gamma of the performance LMI (Theorem 3 plus the bound
      sum_k E||e(k)||^2 <= gamma, full slack, :class:`.design.Theorem3` ``output_slack``) for the
      scheduled family, fixed gains (Gf = Hf = 0) and the zero filter (x_f = 0), with the S-procedure
      multiplier free (column ``multiplier``: ``free``, its value in ``lambda``) and fixed as printed
      in (12) (``fixed``, the paper's rows): the conservatism of the LMI design itself; the verdict is
      the engine's check of the point;
    * ``guaranteed_cost_lower`` / ``guaranteed_cost_upper``: the certified bracket of the least
      guaranteed cost (multiplier free) of the scheduled family, on a lattice around the fixed
      family's certified cost (``scheduling.cost_span``, ``cost_resolution``), and of the zero filter
      (:func:`.design.guaranteed_cost_bracket`): what scheduling can buy in the guarantee, at most;
    * ``exact_tuned``: the best gains found for the exact sum_k E||e(k)||^2 (f = (F1+F2)/2 z,
      x(0) ~ N(0, I), the configured p(k)) in each family (:func:`.tuning.best_exact_gains`, BFGS
      from the designs named in ``scheduling.starts``, or from x_f = 0 if none; the scheduled search
      starts from the fixed optimum too, so it can only improve on it): what scheduling buys in the
      error itself.

    A row ``schedule_size`` gives max(|Gf|, |Hf|) of each LMI design of ``gains.csv`` (is it scheduled?).

    Parameters
    ----------
    params : dict
        The ``gainsched`` configuration's ``system``, ``lmi``, ``performance``, ``simulation`` and
        ``scheduling`` sections (``scheduling.starts``: the designs of ``gains.csv`` the exact
        tuning starts from).
    inputs : dict
        ``gains``: the designed gains table (``results/gainsched/gains.csv``).
    outputs : dict
        ``table`` (``results/gainsched/scheduling.csv``).

    Returns
    -------
    dict
        ``{"table": DataFrame}`` with columns comparison, family, multiplier, value, verdict,
        certified_slack, status, lambda, start, n_evaluations.

    Raises
    ------
    GainschedError
        When every guaranteed-cost solve is undecided (the message names the step and the statuses).
    """
    from .design import Theorem3, certified_cost, guaranteed_cost_bracket
    from .tuning import best_exact_gains

    sys = _sys(params)
    lmi = params["lmi"]
    cfg = params["scheduling"]
    X0 = augmented_initial_moment(params["performance"]["initial_cov"], sys.n)
    common = dict(eps=float(lmi["eps"]), bound=float(lmi["bound"]), qp_positive=bool(lmi["qp_positive"]),
                  margin_cap=float(lmi["margin_cap"]), gamma3_top=lmi.get("gamma3_top", "HC"))
    rows, solved = [], {}
    for multiplier in ("free", "fixed"):
        for family, opts in (("scheduled", dict(scheduled=True)), ("fixed_gain", dict(scheduled=False)),
                             ("zero", dict(zero_filter=True))):
            prob = Theorem3(sys, X0=X0, performance=True, output_slack=True, multiplier=multiplier, **opts, **common)
            sol = prob.solve()
            verdict, slack = _decide_point(prob, sol, sys)
            cost = certified_cost(sol.values, X0, sys.p1, sys.p2) if verdict == "feasible" else np.nan
            lam = float(np.asarray(sol.values["lam"])) if "lam" in sol.values else 1.0
            solved[(multiplier, family)] = (prob, sol, cost)
            rows.append({"comparison": "guaranteed_cost", "family": family, "multiplier": multiplier,
                         "value": cost, "verdict": verdict, "certified_slack": slack, "status": sol.status,
                         "lambda": lam if sol.values else np.nan, "start": "", "n_evaluations": np.nan})
    _no_decision(rows, "gainsched_scheduling", "the performance LMI (guaranteed cost)")
    # certified brackets of the least guaranteed cost (free multiplier) on a lattice around a reference certified
    # cost: the scheduled family's around the fixed-gain family's (the most scheduling can buy in the guarantee),
    # and the zero filter's (min tr Q of x_f = 0) around its own
    for family, reference in (("scheduled", "fixed_gain"), ("zero", "zero")):
        prob, sol, _ = solved[("free", family)]
        ref = solved[("free", reference)][2]
        if sol.values and np.isfinite(ref):
            b = guaranteed_cost_bracket(prob, sol.values, X0, ref, float(cfg["cost_span"]),
                                        float(cfg["cost_resolution"]))
            lower, upper, n_eval, und = b.infeasible_end, b.feasible_end, b.n_evals, len(b.undecided)
        else:
            lower, upper, n_eval, und = np.nan, np.nan, 0, 0
        for name, value in (("guaranteed_cost_lower", lower), ("guaranteed_cost_upper", upper)):
            rows.append({"comparison": name, "family": family, "multiplier": "free", "value": value,
                         "verdict": "certified" if np.isfinite(value) else "undecided", "certified_slack": np.nan,
                         "status": f"certified bisection on the cost level ({und} undecided lattice points)",
                         "lambda": np.nan, "start": f"reference {reference} {ref:.9g}", "n_evaluations": n_eval})
    table = read_table(inputs["gains"])
    p_seq = p_sequence(params, sys)
    mid = 0.5 * (sys.F1 + sys.F2)
    Xg = augmented_initial_moment(np.eye(sys.n), sys.n)
    named = [(d, gains_from_table(table, d, sys)) for d in params["scheduling"]["starts"]]
    fixed, info_f = best_exact_gains(sys, p_seq, mid, Xg, False, named or [("zero", zero_gains(sys))])
    sched, info_s = best_exact_gains(sys, p_seq, mid, Xg, True, [("best fixed", fixed)] + named)
    for family, info in (("fixed_gain", info_f), ("scheduled", info_s)):
        rows.append({"comparison": "exact_tuned", "family": family, "multiplier": "", "value": info["cost"],
                     "verdict": "", "lambda": np.nan,
                     "certified_slack": np.nan, "status": "local minimum (BFGS)", "start": info["start"],
                     "n_evaluations": info["n_eval"]})
    for d in dict.fromkeys(table["design"]):
        if d in ("theorem3", "fixed_gain", "performance", "performance_tied"):
            g = gains_from_table(table, d, sys)
            rows.append({"comparison": "schedule_size", "family": d, "multiplier": "", "lambda": np.nan,
                         "value": float(max(np.abs(g.Gf).max(), np.abs(g.Hf).max())), "verdict": "",
                         "certified_slack": np.nan, "status": "", "start": "", "n_evaluations": np.nan})
    return {"table": pd.DataFrame(rows)}


def timing_step(params, inputs, outputs):
    """Remark 5 check: Theorem 3 solve time against the number of design variables.

    Random stable systems (spectral radius of A 0.5) of ``timing.n_states``
    states with the example's p bounds; keeps status, compile and solver time,
    and a power-law fit of solver time against the number of scalar variables
    (columns ``fit_exponent``, ``extrapolated_1000_s``, identical on every row).

    Parameters
    ----------
    params : dict
        The ``gainsched`` configuration's ``system`` (its p bounds), ``lmi`` (``eps``, ``bound``,
        ``margin_cap``) and ``timing`` (``n_states``, ``seed``) sections.
    inputs : dict
        Only the step's code (no table is read).
    outputs : dict
        ``table`` (``results/gainsched/timing.csv``).

    Returns
    -------
    dict
        ``{"table": DataFrame}``, one row per state dimension (NaN fit with fewer than two timed solves).
    """
    from .design import Theorem3

    base = _sys(params)
    cfg = params["timing"]
    rng = np.random.default_rng(int(cfg["seed"]))
    rows = []
    for n in cfg["n_states"]:
        n = int(n)
        A = rng.standard_normal((n, n))
        A *= 0.5 / max(abs(np.linalg.eigvals(A)))
        sysn = System(A, 0.05 * rng.standard_normal((n, n)), rng.standard_normal((1, n)),
                      0.1 * rng.standard_normal((n, n)), np.eye(n), np.diag(np.full(n, 0.4)),
                      np.diag(np.full(n, 1.2)), 0.5, base.p1, base.p2)
        prob = Theorem3(sysn, eps=float(params["lmi"]["eps"]), bound=float(params["lmi"]["bound"]),
                        margin_cap=float(params["lmi"]["margin_cap"]))
        sol = prob.solve()
        stats = prob.problem.solver_stats
        rows.append({"n_states": n, "n_scalar_variables": sol.n_scalar_variables, "lmi_size": 9 * n,
                     "n_lmis": prob.n_vertices, "status": sol.status, "total_time_s": sol.solve_time_s,
                     "compile_time_s": float(prob.problem.compilation_time or np.nan),
                     "solver_time_s": float(stats.solve_time) if stats.solve_time is not None else np.nan,
                     "iterations": stats.num_iters})
    frame = pd.DataFrame(rows)
    ok = frame["solver_time_s"] > 0
    if ok.sum() >= 2:
        slope, icpt = np.polyfit(np.log(frame.loc[ok, "n_scalar_variables"]), np.log(frame.loc[ok, "solver_time_s"]), 1)
        frame["fit_exponent"] = slope
        frame["extrapolated_1000_s"] = float(np.exp(icpt + slope * np.log(1000.0)))
    else:
        frame["fit_exponent"] = np.nan
        frame["extrapolated_1000_s"] = np.nan
    return {"table": frame}


def vertex_lmi_step(params, inputs, outputs):
    """Certified decisions on the vertex LMIs (24) beyond the designs (issue 15).

    ``table`` (vertex_lmis.csv), one row per problem, slack family, Γ3 reading and sigma^2:

    * ``printed_gains``: do the gains printed in Section IV satisfy (24)? With the general slack S
      in the original coordinates (:class:`.design.FixedGainsVertexLMI`, both readings of Γ3
      coincide there), and in the paper's T-coordinates with S21 = S22 (T = I) under both
      readings of Γ3 (a restricted family: only its feasible verdicts speak for (24));
    * ``scheduled``: Theorem 3 with free gains under the other reading of Γ3, Θ[0; H̄C]N;
    * ``noise_free``: Theorem 3 at sigma^2 = 0 with and without the last block row of (24);
      with it, a diagonal block that is identically zero certifies infeasibility.

    Every verdict is the shared engine's (point check, dual certificate or necessary condition);
    the solver status and margin are information.

    Parameters
    ----------
    params : dict
        The ``gainsched`` configuration's ``system``, ``paper_gains``, ``lmi`` and ``sensitivity``
        (``sigma2_grid``, to which the system's own sigma^2 is added) sections.
    inputs : dict
        Only the step's code (no table is read).
    outputs : dict
        ``table`` (``results/gainsched/vertex_lmis.csv``).

    Returns
    -------
    dict
        ``{"table": DataFrame}``: problem, slack, gamma3_top, sigma2, verdict, evidence, status,
        margin, certified_slack.
    """
    from .design import FixedGainsVertexLMI, Theorem3, zero_diagonal_blocks
    from .feasibility import necessary_condition, with_sigma2

    sys = _sys(params)
    lmi = params["lmi"]
    gains = gains_from_dict(params["paper_gains"], sys)
    grid = sorted({float(s) for s in params["sensitivity"]["sigma2_grid"]} | {float(sys.sigma2)})
    eps, bound, cap = float(lmi["eps"]), float(lmi["bound"]), float(lmi["margin_cap"])
    common = dict(eps=eps, bound=bound, margin_cap=cap, qp_positive=bool(lmi["qp_positive"]))
    rows = []

    def record(problem, family, top, s2, verdict, status, margin):
        rows.append({"problem": problem, "slack": family, "gamma3_top": top, "sigma2": float(s2),
                     "verdict": verdict.verdict, "evidence": verdict.evidence, "status": status, "margin": margin,
                     "certified_slack": verdict.point.slack if verdict.point is not None else np.nan})

    general = FixedGainsVertexLMI(sys, gains, eps=eps, bound=bound, margin_cap=cap)
    for s2 in grid:
        v, status, margin = general.certify(s2)
        record("printed_gains", "general", "HC", s2, v, status, margin)
    for top in ("HC", "zero"):
        prob = Theorem3(sys, fixed_gains=gains, gamma3_top=top, **common)
        for s2 in grid:
            v, sol = prob.certify(s2)
            record("printed_gains", "S21=S22", top, s2, v, sol.status, sol.margin)
    prob = Theorem3(sys, gamma3_top="zero", **common)
    for s2 in grid:
        v, sol = prob.certify(s2)
        record("scheduled", "free", "zero", s2, v, sol.status, sol.margin)
    sys0 = with_sigma2(sys, 0.0)
    for keep in (True, False):
        prob = Theorem3(sys0, noise_row=keep, gamma3_top=lmi.get("gamma3_top", "HC"), **common)
        sol = prob.solve(0.0)
        plant = necessary_condition(sys0, 0.0)
        zeros = zero_diagonal_blocks(prob.certifier.coefficients())

        def necessary(zeros=zeros, plant=plant):
            if zeros:
                return True, (f"{len(zeros)} diagonal entries identically zero (e.g. {zeros[0][0]}, index "
                              f"{zeros[0][1]}): no strict solution")
            return plant()

        v = prob.certifier.certify(sol.status, necessary=necessary)
        record("noise_free", "with noise row" if keep else "without noise row", lmi.get("gamma3_top", "HC"), 0.0,
               v, sol.status, sol.margin)
    return {"table": pd.DataFrame(rows)}
