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
* ``performance``: Theorem 3 plus the bound sum_k E||e(k)||^2 <= gamma, minimised;
* ``performance_fixed``: the same with G_f = H_f = 0;
* ``tuned_fixed`` / ``tuned_scheduled``: gains of form (9) tuned by Monte Carlo
  (Nelder-Mead on common random numbers) for the named nonlinearity: what a
  filter of this structure can achieve when not restricted to a worst-case bound;
* ``trivial``: x_f = 0 (all gains zero).
"""

from __future__ import annotations

import time

import numpy as np
import pandas as pd

from ...io import read_table
from .model import (
    Gains,
    GainschedError,
    System,
    augmented_initial_moment,
    frozen_radius,
    gains_from_dict,
    p_schedule,
    plant_ms_radius,
    scheduled_growth_rate,
    sector_cases,
    simulate,
    system_from_config,
    theorem1_grid_check,
    theorem1_lmi,
    zero_gains,
)
from .tuning import tune_gains

__all__ = [
    "MATRICES",
    "gains_table",
    "gains_from_table",
    "load_solutions",
    "p_sequence",
    "design_step",
    "stability_step",
    "simulation_step",
    "sensitivity_step",
    "timing_step",
]

MATRICES = ("G0", "Gf", "H0", "Hf")


def _sys(params) -> System:
    return system_from_config(params["system"])


# ----------------------------------------------------------------------------- gains tables
def gains_table(design: str, gains: Gains) -> pd.DataFrame:
    """Long table ``design, matrix, row, col, value`` of one design's G0, Gf, H0, Hf (9)."""
    rows = []
    for name, mat in gains.as_dict().items():
        mat = np.atleast_2d(mat)
        for (r, c), v in np.ndenumerate(mat):
            rows.append({"design": design, "matrix": name, "row": r, "col": c, "value": float(v)})
    return pd.DataFrame(rows, columns=["design", "matrix", "row", "col", "value"])


def gains_from_table(table: pd.DataFrame, design: str, sys: System) -> Gains:
    """Inverse of :func:`gains_table` for one design."""
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
    """The configured scheduling sequence p(0..K-1) (Section IV), K = ``simulation.horizon`` by default."""
    sim = params["simulation"]
    K = int(sim["horizon"] if horizon is None else horizon)
    return p_schedule(np.arange(K), sys.p1, sys.p2, float(sim["sine_omega"]))


def _mc_errors(sys, gains, p_seq, x0, seed, nonlinearity, xf0=None):
    return simulate(sys, gains, p_seq, x0, np.random.default_rng(seed), nonlinearity, xf0=xf0)


# ----------------------------------------------------------------------------- steps
def design_step(params, inputs, outputs):
    """All designs: paper gains, Theorem 3 (24)-(26) variants, performance-aware, MC-tuned, trivial.

    Writes ``gains`` (design, matrix, row, col, value) and ``designs`` (one row
    per design: solver status, margin, objective, solve time, realisation).
    """
    from .design import Theorem3, recover_gains

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
        "performance": dict(scheduled=True, performance=True),
        "performance_fixed": dict(scheduled=False, performance=True),
    }
    solutions, lmi_rows = {}, []
    for name, opts in problems.items():
        prob = Theorem3(sys, X0=X0 if opts["performance"] else None, **opts, **common)
        sol = prob.solve()
        solutions[name] = sol
        for var, val in sol.values.items():
            for (r, c), x in np.ndenumerate(np.atleast_2d(val)):
                lmi_rows.append({"problem": name, "variable": var, "row": r, "col": c, "value": float(x)})
        if not sol.values:
            rows.append({"design": name, "method": "Theorem 3", "status": sol.status, "margin": sol.margin,
                         "objective": sol.objective, "solver_feasible": False, "solve_time_s": sol.solve_time_s,
                         "n_scalar_variables": sol.n_scalar_variables, "realisation": ""})
            continue
        realisations = [("identity_T", name)]
        if name == "theorem3":
            realisations.append(("S21_identity", "theorem3_S21I"))
        for real, dname in realisations:
            gains, _ = recover_gains(sol.values, real)
            tables.append(gains_table(dname, gains))
            method = ("Theorem 3 " + ("+ bound min " if opts["performance"] else "feasibility ")
                      + ("scheduled" if opts["scheduled"] else "fixed (Gf=Hf=0)"))
            rows.append({"design": dname, "method": method, "status": sol.status, "margin": sol.margin,
                         "objective": sol.objective, "solver_feasible": sol.solver_feasible,
                         "solve_time_s": sol.solve_time_s, "n_scalar_variables": sol.n_scalar_variables,
                         "realisation": real})
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
    tables.append(gains_table("trivial", zero_gains(sys)))
    rows.append({"design": "trivial", "method": "x_f = 0", "status": "given", "margin": np.nan, "objective": np.nan,
                 "solver_feasible": np.nan, "solve_time_s": np.nan, "n_scalar_variables": 0, "realisation": ""})
    return {"gains": pd.concat(tables, ignore_index=True), "designs": pd.DataFrame(rows),
            "solutions": pd.DataFrame(lmi_rows, columns=["problem", "variable", "row", "col", "value"]),
            "provenance": {"solver_status": {k: v.status for k, v in solutions.items()}}}


def load_solutions(path) -> dict:
    """LMI solutions stored by :func:`design_step` (``lmi_solutions.csv``): problem -> {variable: ndarray}."""
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
           "thm1_solver_feasible": res.solver_feasible, "thm1_pairs": res.n_pairs}
    if res.Q0 is not None:
        worst, qmin, wv = theorem1_grid_check(sys, gains, res.Q0, res.Qp, res.S, int(lmi["check_grid"]))
    else:
        worst, qmin, wv = np.nan, np.nan, np.nan
    out.update({"thm1_max_eig_grid": worst, "thm1_max_eig_vertices": wv, "thm1_min_eig_Q": qmin,
                "thm1_certified": bool(res.Q0 is not None and worst < 0 and qmin > 0)})
    return out


def stability_step(params, inputs, outputs):
    """Independent checks of every design: Theorem 1 (12) on vertices and a fine grid, second-moment radii.

    ``stability``: design, p, sector_case, spectral_radius (frozen p, linear f = F z,
    F at the vertices of the diagonal sector). ``theorem1``: per design the
    Theorem 1 solve (status, margin), the fine-grid maximum eigenvalue, the
    check of the Theorem 3 certificate itself (rebuilt Q, S of (23), (27)),
    and the growth rate of E||z||^2 along the scheduled p(k).
    """
    from .design import certificate_from_solution, recover_gains

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
        for real, dname in reals:
            g, _ = recover_gains(values, real)
            c = certificate_from_solution(values, real)
            cert[dname] = theorem1_grid_check(sys, g, c["Q0"], c["Qp"], c["S"], int(lmi["check_grid"]),
                                              performance=perf and real == "identity_T")
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
    97.5 percentiles over runs) and mse(k) = E||e(k)||^2 for the fixed initial
    state; ``error_summary``: sum_k mse(k) for the fixed x0 and for x0 ~ N(0, initial_cov).
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
        mse = (e ** 2).sum(-1).mean(0)
        for k in ks:
            erows.append({"design": d, "k": int(k), "e1_mean": mean[k, 0], "e2_mean": mean[k, 1], "e1_lo": lo[k, 0],
                          "e1_hi": hi[k, 0], "e2_lo": lo[k, 1], "e2_hi": hi[k, 1], "mse": mse[k]})
            prow.append({"design": d, "k": int(k), "p": float(p_seq[k]) if k < len(p_seq) else np.nan,
                         "e1": e[0, k, 0], "e2": e[0, k, 1]})
        srows.append({"design": d, "initial_state": "fixed_x0", "sum_mse": float(mse.sum())})
        er = _mc_errors(sys, gains, p_seq, x0_rand, int(sim["seed"]) + 1, sim["nonlinearity"])
        srows.append({"design": d, "initial_state": "gaussian", "sum_mse": float((er ** 2).sum(-1).mean(0).sum())})
    return {"errors": pd.DataFrame(erows), "error_summary": pd.DataFrame(srows), "paths": pd.DataFrame(prow)}


def sensitivity_step(params, inputs, outputs):
    """Theorem 3 margin against sigma^2 (one parametrised problem per variant) and the largest feasible sigma^2.

    Also the true mean-square stability limit of the plant (linear sector
    vertices): the criterion can never certify beyond it.
    """
    from ...engines.lmi import bisect_monotone

    from .design import Theorem3

    base = _sys(params)
    lmi = params["lmi"]
    sens = params["sensitivity"]
    grid = np.asarray(sens["sigma2_grid"], dtype=float)
    rows = []
    for variant, sched in (("scheduled", True), ("fixed", False)):
        prob = Theorem3(base, scheduled=sched, eps=float(lmi["eps"]), bound=float(lmi["bound"]),
                        qp_positive=bool(lmi["qp_positive"]), margin_cap=float(lmi["margin_cap"]),
                        gamma3_top=lmi.get("gamma3_top", "HC"))
        for s2 in grid:
            sol = prob.solve(float(s2))
            rows.append({"variant": variant, "sigma2": float(s2), "status": sol.status, "margin": sol.margin,
                         "solver_feasible": sol.solver_feasible, "kind": "grid"})

        def infeasible(s2, prob=prob):
            return not prob.solve(float(s2)).solver_feasible

        b = bisect_monotone(infeasible, float(sens["sigma2_lo"]), float(sens["sigma2_hi"]), tol=float(sens["tol"]))
        rows.append({"variant": variant, "sigma2": b.lower, "status": f"bisection ({b.n_evals} solves)",
                     "margin": np.nan, "solver_feasible": True, "kind": "sigma2_max"})
    # plant MS stability limit: radius of A+BFZ (x) itself + sigma2 D(x)D crosses 1
    def plant_unstable(s2):
        sysv = System(base.A, base.B, base.C, base.D, base.Z, base.F1, base.F2, float(s2), base.p1, base.p2)
        return plant_ms_radius(sysv) >= 1.0

    b = bisect_monotone(plant_unstable, float(sens["sigma2_lo"]), float(sens["sigma2_hi"]), tol=float(sens["tol"]))
    rows.append({"variant": "plant_ms_limit", "sigma2": b.lower, "status": "bisection on spectral radius",
                 "margin": np.nan, "solver_feasible": np.nan, "kind": "sigma2_max"})
    return {"table": pd.DataFrame(rows)}


def timing_step(params, inputs, outputs):
    """Remark 5 check: Theorem 3 solve time against the number of design variables.

    Random stable systems (spectral radius of A 0.5) of ``timing.n_states``
    states with the example's p bounds; keeps status, compile and solver time,
    and a power-law fit of solver time against the number of scalar variables
    (columns ``fit_exponent``, ``extrapolated_1000_s``, identical on every row).
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
