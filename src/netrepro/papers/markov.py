"""Paper `markov`: Wu, Shi, Anderson, Johansson, *Stability Conditions and Phase Transition for
Kalman Filtering over Markovian Channels*. Pipeline steps, figures, claims, errata.

The mathematics lives in :mod:`netrepro.papers.markov_math`; this module holds the step
functions called by ``workflow/rules/markov.smk`` (signature ``fn(params, inputs, outputs)``).

Tables (``results/markov/``)
----------------------------
``critical_curves.csv``
    one row per example and q: ``example, q, q_necessary`` (= 1 - 1/|lambda_A|^2, the
    necessary-condition boundary of [18]), ``necessary_ok`` (|lambda_A|^2 (1-q) < 1),
    ``p_prop1`` / ``p_prop1_uncapped`` (Proposition 1, eq. 8), ``p_thm5`` / ``p_thm5_uncapped``
    (Theorem 5, eq. 12, largest certified-feasible p of the bisection; capped at 1),
    ``p_thm5_upper`` (smallest infeasible p), ``thm5_saturated`` (feasible at the search cap),
    ``thm5_n_solves``, ``thm5_n_uncertified`` (solver-feasible answers that failed the
    rho(H(K)) < 1 check), ``thm5_statuses`` (solver statuses seen), ``rho_H_at_lower``,
    ``p_reference`` and ``reference`` (the known critical value where theory gives it:
    Example I non-degenerate => p_c = 1 [18]; Example II => our parity renewal formula).
``lmi_checks.csv``
    point checks of Theorem 2 / 5: ``check, example, p, q, status, margin, solver_feasible,
    certified, rho_H, lyap_margin``.
``lmi_benchmark.csv``
    ``mode`` (parametrised / rebuilt), ``n_solves, seconds, solves_per_second``.
``iid_line.csv``
    ``example, lambda_lower`` (1 - 1/|lambda_max(A)|^2), ``lambda_lmi_upper`` (Sinopoli LMI),
    ``q_thm5_on_iid_line`` (smallest q with the Theorem 2 LMI certified at p = 1 - q),
    ``lambda_c_reference`` and ``reference``, ``consistent``.
``exact_moments.csv``
    polynomial coefficients of the exact E||P_k||: ``example, depth, n11, n10, n01, n00,
    sum_norm, sum_trace`` (see :class:`~netrepro.papers.markov_math.ExactMoments`).
``stability_map.csv``
    ``example, p, q, bounded`` (True / False / empty when undecided), ``verdict`` (bounded /
    unbounded / undecided), ``growth_rate`` (extrapolated asymptotic log-growth of E||P_k|| per
    step), ``growth_rate_last`` (raw rate over the last two steps of the exact horizon),
    ``mean_norm_last`` (exact E||P_K||), ``method``.
``sample_paths.csv``
    for each of Figs 3-6: ``figure, example, p, q, k, gamma`` (one sample path; gamma_k),
    ``norm_path`` (||P_k|| along it), ``q05, q50, q95`` (Monte Carlo quantiles of ||P_k||),
    ``plain_mean`` (sample mean), ``rb_mean`` (conditional estimator), ``exact_mean`` (k <= depth+1).
``estimator_check.csv``
    ``example, p, q, k, exact_mean, plain_mean, plain_ci_high, rb_mean, rb_ci_low, rb_ci_high,
    plain_over_exact, rb_over_exact, n_paths``: the plain sample mean failing, the conditional
    estimator agreeing with the exact value.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import pandas as pd

from ..claims import claim_row, claims_frame, errata_frame, reconstructions_frame
from ..config import ConfigError, require_matrix, require_pd
from ..plotting import new_figure, save_figure
from . import markov_math as mm

__all__ = [
    "check_config", "critical_curves_step", "lmi_checks_step", "iid_line_step", "exact_moments_step",
    "stability_map_step", "sample_paths_step", "claims_step", "errata_step", "reconstructions_step",
    "figure_plane", "figure_path", "figure_mean", "figure_estimators", "classify_growth",
]

SLUG = "markov"


# ----------------------------------------------------------------------------- config
def check_config(section: dict) -> None:
    """Checks a schema cannot express: matrix shapes agree, Q >= 0, R > 0, Sigma0 >= 0, (C, A) observable."""
    for name, ex in section.get("examples", {}).items():
        A = require_matrix(f"markov.examples.{name}.A", ex["A"], square=True)
        n = A.shape[0]
        C = require_matrix(f"markov.examples.{name}.C", ex["C"])
        if C.shape[1] != n:
            raise ConfigError(f"config key 'markov.examples.{name}.C' has {C.shape[1]} columns; expected {n} (A is {n}x{n})")
        require_pd(f"markov.examples.{name}.Q", ex["Q"], semi=True)
        R = require_pd(f"markov.examples.{name}.R", ex["R"])
        if R.shape[0] != C.shape[0]:
            raise ConfigError(f"config key 'markov.examples.{name}.R' is {R.shape}; expected {C.shape[0]}x{C.shape[0]}")
        S0 = require_pd(f"markov.examples.{name}.Sigma0", ex["Sigma0"], semi=True)
        if S0.shape != A.shape:
            raise ConfigError(f"config key 'markov.examples.{name}.Sigma0' is {S0.shape}; expected {A.shape}")
        try:
            mm.observability_index(A, C)
        except ValueError:
            raise ConfigError(f"config key 'markov.examples.{name}': (C, A) must be observable") from None


def _system(ex):
    return mm.LinearSystem.from_config(ex)


def _q_grid(lam, n_points, margin):
    q_nec = 1.0 - 1.0 / lam ** 2
    return np.linspace(q_nec + margin, 1.0 - margin, n_points), q_nec


def _reference(name, ex, q):
    """Known critical failure rate where theory gives it (see module docstring)."""
    kind = ex.get("reference", "none")
    lam = mm.spectral_abs(ex["A"])
    q = np.asarray(q, dtype=float)
    if kind == "nondegenerate":
        return np.where(lam ** 2 * (1 - q) < 1, 1.0, 0.0), "non-degenerate: MSS iff |lambda|^2(1-q)<1 [18], so p_c=1"
    if kind == "parity":
        return np.minimum(mm.parity_bound_example2(lam, q), 1.0), "parity renewal condition (our derivation)"
    return np.full(q.shape, np.nan), ""


# ----------------------------------------------------------------------------- Theorem 5 curves
def critical_curves_step(params, inputs, outputs):
    """Proposition 1 (eq. 8) and Theorem 5 (eq. 12) curves p(q) for every example, plus the LMI benchmark."""
    cc = params["curves"]
    rows, bench = [], []
    for name, ex in params["examples"].items():
        A, C = np.asarray(ex["A"], float), np.asarray(ex["C"], float)
        lam = mm.spectral_abs(A)
        l_o = mm.observability_index(A, C)
        qs, q_nec = _q_grid(lam, cc["q_points"], cc["q_margin"])
        prop = mm.prop1_bound(lam, qs, l_o)
        ref, ref_text = _reference(name, ex, qs)
        lmi = mm.GilbertElliottLMI(A, C, l_o)
        p_max = cc["p_uncapped_max"] if l_o == 2 else 1.0
        t0 = time.perf_counter()
        for q, pp, pr in zip(qs, prop, ref):
            res = mm.thm5_lower_bound(lmi, float(q), p_max, cc["bisection_tol"])
            rows.append({
                "example": name, "q": q, "q_necessary": q_nec, "necessary_ok": bool(lam ** 2 * (1 - q) < 1),
                "p_prop1": min(pp, 1.0), "p_prop1_uncapped": pp,
                "p_thm5": min(res["p_lower"], 1.0), "p_thm5_uncapped": res["p_lower"], "p_thm5_upper": res["p_upper"],
                "thm5_saturated": res["saturated"], "thm5_n_solves": res["n_solves"],
                "thm5_n_uncertified": res["n_uncertified"], "thm5_statuses": "|".join(res["statuses"]),
                "rho_H_at_lower": res["rho_at_lower"], "p_reference": pr, "reference": ref_text,
            })
        elapsed = time.perf_counter() - t0
        # benchmark, same run: parametrised problem vs rebuilding it for every solve
        nb = cc["benchmark_solves"]
        grid = np.linspace(0.2, 0.9, nb)
        t1 = time.perf_counter()
        for p in grid:
            lmi.solve(float(p), float(qs[len(qs) // 2]))
        t_param = time.perf_counter() - t1
        t2 = time.perf_counter()
        for p in grid:
            mm.rebuild_solve(A, C, float(p), float(qs[len(qs) // 2]), l_o)
        t_build = time.perf_counter() - t2
        bench += [
            {"example": name, "mode": "parametrised (compiled once, cp.Parameter)", "n_solves": nb, "seconds": t_param,
             "solves_per_second": nb / t_param},
            {"example": name, "mode": "rebuilt every solve", "n_solves": nb, "seconds": t_build,
             "solves_per_second": nb / t_build},
            {"example": name, "mode": "theorem-5 sweep (parametrised)", "n_solves": lmi.n_solves - nb,
             "seconds": elapsed, "solves_per_second": (lmi.n_solves - nb) / elapsed},
        ]
    return {"table": pd.DataFrame(rows), "benchmark": pd.DataFrame(bench),
            "provenance": {"n_solves": int(sum(r["thm5_n_solves"] for r in rows))}}


def lmi_checks_step(params, inputs, outputs):
    """Point checks of Theorem 2 (iv) and Theorem 5 that the paper states (Section 5)."""
    ck = params["checks"]
    rows = []
    for item in ck["points"]:
        ex = params["examples"][item["example"]]
        A, C = np.asarray(ex["A"], float), np.asarray(ex["C"], float)
        lmi = mm.GilbertElliottLMI(A, C)
        p = float(item["p"])
        r = lmi.solve(p, float(item["q"]))
        rows.append({"check": item["name"], "example": item["example"], "p": p, "q": item["q"], "status": r.status,
                     "margin": r.margin, "solver_feasible": r.solver_feasible, "certified": r.certified,
                     "rho_H": r.rho_H, "lyap_margin": r.lyap_margin})
    for item in ck["tight"]:
        ex = params["examples"][item["example"]]
        A, C = np.asarray(ex["A"], float), np.asarray(ex["C"], float)
        lmi = mm.GilbertElliottLMI(A, C)
        res = mm.thm5_lower_bound(lmi, float(item["q"]), 1.0, ck["tight_tol"])
        for label, p in (("tight_lower", res["p_lower"]), ("tight_upper", res["p_upper"])):
            r = lmi.solve(float(p), float(item["q"]))
            rows.append({"check": f"{item['name']}_{label}", "example": item["example"], "p": p, "q": item["q"],
                         "status": r.status, "margin": r.margin, "solver_feasible": r.solver_feasible,
                         "certified": r.certified, "rho_H": r.rho_H, "lyap_margin": r.lyap_margin})
    return {"table": pd.DataFrame(rows)}


def iid_line_step(params, inputs, outputs):
    """The i.i.d. line p + q = 1 (Remark 4): Sinopoli's bounds on lambda_c and Theorem 5's crossing."""
    tol = params["iid"]["tol"]
    rows = []
    for name, ex in params["examples"].items():
        A, C = np.asarray(ex["A"], float), np.asarray(ex["C"], float)
        lam = mm.spectral_abs(A)
        lower = 1.0 - 1.0 / lam ** 2
        upper, _ = mm.sinopoli_lmi_threshold(A, C, tol)
        lmi = mm.GilbertElliottLMI(A, C)
        # feasibility at (p, q) = (1 - q, q) is monotone in q: p falls while p_underline(q) rises
        res = mm.bisect_monotone(lambda q: lmi.solve(1.0 - q, q).certified, lower + 1e-6, 1.0 - 1e-6, tol=tol)
        kind = ex.get("reference", "none")
        if kind == "nondegenerate":
            ref, text = lower, "non-degenerate: lambda_c = 1 - 1/|lambda|^2 (Mo & Sinopoli)"
        elif kind == "parity":
            ref, text = 1.0 - 1.0 / lam ** 4, "parity argument: lambda_c = 1 - 1/|lambda|^4"
        else:
            ref, text = np.nan, ""
        rows.append({"example": name, "lambda_lower": lower, "lambda_lmi_upper": upper,
                     "q_thm5_on_iid_line": res.threshold, "lambda_c_reference": ref, "reference": text,
                     "consistent": bool(lower - tol <= ref <= min(upper, res.threshold) + tol)})
    return {"table": pd.DataFrame(rows)}


# ----------------------------------------------------------------------------- exact moments and the map
def exact_moments_step(params, inputs, outputs):
    """Exact E||P_k|| polynomials over all channel paths, k <= depth + 1 (see :func:`markov_math.exact_moments`)."""
    frames = []
    for name, ex in params["examples"].items():
        em = mm.exact_moments(_system(ex), np.asarray(ex["Sigma0"], float), params["exact"]["depth"])
        for d, c in enumerate(em.coef, start=1):
            f = pd.DataFrame(c, columns=["n11", "n10", "n01", "n00", "sum_norm", "sum_trace"])
            f.insert(0, "depth", d)
            f.insert(0, "example", name)
            frames.append(f)
        frames.append(pd.DataFrame([{"example": name, "depth": 0, "n11": 0, "n10": 0, "n01": 0, "n00": 0,
                                     "sum_norm": em.P1_norm, "sum_trace": em.P1_trace}]))
    table = pd.concat(frames, ignore_index=True)
    for col in ("n11", "n10", "n01", "n00"):
        table[col] = table[col].astype(int)
    return {"table": table}


def load_moments(table: pd.DataFrame, example: str) -> mm.ExactMoments:
    """Rebuild :class:`~netrepro.papers.markov_math.ExactMoments` from ``exact_moments.csv``."""
    sub = table[table["example"] == example]
    head = sub[sub["depth"] == 0].iloc[0]
    cols = ["n11", "n10", "n01", "n00", "sum_norm", "sum_trace"]
    coef = [sub[sub["depth"] == d][cols].to_numpy(float) for d in range(1, int(sub["depth"].max()) + 1)]
    return mm.ExactMoments(coef, float(head["sum_norm"]), float(head["sum_trace"]))


def classify_growth(means: np.ndarray, bounded_tol: float, unbounded_tol: float):
    """Asymptotic growth rate of exact means ``E||P_k||`` and a three-way verdict.

    Two-step log increments ``d_k = (log m_k - log m_{k-2}) / 2`` (two steps, because Example II
    alternates with period 2) are extrapolated to ``k -> infinity`` by Aitken's delta-squared on
    the last three even-spaced increments. Verdict: ``bounded`` if the extrapolated rate is below
    ``bounded_tol``, the increments are decreasing and the last one is below ``unbounded_tol``;
    ``unbounded`` if both the extrapolated
    and the last raw rate exceed ``unbounded_tol``, ``undecided`` otherwise. Vectorised over
    leading axes of ``means`` (last axis = k).
    """
    with np.errstate(divide="ignore", invalid="ignore"):
        lm = np.log(means)
        d = (lm[..., 2:] - lm[..., :-2]) / 2.0
        x0, x1, x2 = d[..., -5], d[..., -3], d[..., -1]
        den = x2 - 2 * x1 + x0
        ait = np.where(np.abs(den) > 1e-12, x2 - (x2 - x1) ** 2 / den, x2)
        ratio = (x2 - x1) / (x1 - x0)
    converging = (ratio > 0) & (ratio < 1)
    # a converging sequence of increments has its limit between 0 (E||P_k|| settles) and the last one
    rate = np.where(converging, np.clip(ait, 0.0, np.maximum(x2, 0.0)), x2)
    verdict = np.where((rate < bounded_tol) & (x2 <= x1) & (x2 < unbounded_tol), "bounded",
                       np.where((rate > unbounded_tol) & (x2 > unbounded_tol), "unbounded", "undecided"))
    return rate, x2, verdict


def stability_map_step(params, inputs, outputs):
    """Independent stability map: exact E||P_k|| (all channel paths) on a (p, q) grid, growth verdicts."""
    table = pd.read_csv(inputs["moments"])
    mp = params["map"]
    ps = np.linspace(mp["p_min"], mp["p_max"], mp["p_points"])
    qs = np.linspace(mp["q_min"], mp["q_max"], mp["q_points"])
    P, Qg = np.meshgrid(ps, qs, indexing="ij")
    rows = []
    for name in params["examples"]:
        em = load_moments(table, name)
        means = em.mean(P, Qg, "norm")
        rate, last, verdict = classify_growth(means, mp["bounded_tol"], mp["unbounded_tol"])
        method = f"exact expectation over all 2^{em.depth - 1} channel paths, k<={em.depth + 1}; Aitken-extrapolated growth"
        for i, j in np.ndindex(P.shape):
            v = verdict[i, j]
            rows.append({"example": name, "p": P[i, j], "q": Qg[i, j],
                         "bounded": {"bounded": "True", "unbounded": "False"}.get(v, ""), "verdict": v,
                         "growth_rate": rate[i, j], "growth_rate_last": last[i, j],
                         "mean_norm_last": means[i, j, -1], "method": method})
    return {"table": pd.DataFrame(rows)}


# ----------------------------------------------------------------------------- sample paths (Figs 3-6)
def _estimator_check(system, S0, example, p, q, em, n, rng):
    """Plain sample mean and conditional estimator of E||P_k|| against the exact value at k = depth + 1."""
    exact = em.mean(p, q, "norm")
    k = len(exact)
    norms, arrivals = mm.plain_mc(system, S0, p, q, n, k - 1, rng)
    rb = mm.rb_mean_norm(system, S0, p, q, arrivals)
    plain, rbk = norms[:, k - 1], rb[:, k - 1]
    se_p, se_r = plain.std(ddof=1) / np.sqrt(n), rbk.std(ddof=1) / np.sqrt(n)
    return {"example": example, "p": p, "q": q, "k": k, "exact_mean": exact[k - 1],
            "plain_mean": plain.mean(), "plain_ci_high": plain.mean() + 1.96 * se_p,
            "rb_mean": rbk.mean(), "rb_ci_low": rbk.mean() - 1.96 * se_r, "rb_ci_high": rbk.mean() + 1.96 * se_r,
            "plain_over_exact": plain.mean() / exact[k - 1], "rb_over_exact": rbk.mean() / exact[k - 1],
            "n_paths": n}


def sample_paths_step(params, inputs, outputs):
    """Sample paths, Monte Carlo bands, plain and conditional means, exact means for Figs 3-6."""
    sp = params["paths"]
    table = pd.read_csv(inputs["moments"])
    rows, checks = [], []
    for case in sp["cases"]:
        ex = params["examples"][case["example"]]
        system = _system(ex)
        S0 = np.asarray(ex["Sigma0"], float)
        p, q = float(case["p"]), float(case["q"])
        rng = np.random.default_rng([sp["seed"], int(case["figure"].replace("fig", ""))])
        norms, arrivals = mm.plain_mc(system, S0, p, q, sp["n_paths"], sp["horizon"], rng)
        rb_arr = arrivals[: sp["rb_paths"], : sp["rb_horizon"]]
        rb = mm.rb_mean_norm(system, S0, p, q, rb_arr)
        em = load_moments(table, case["example"])
        exact = em.mean(p, q, "norm")
        K = sp["horizon"] + 1
        qs = np.quantile(norms, [0.05, 0.5, 0.95], axis=0)
        for k in range(1, K + 1):
            rows.append({
                "figure": case["figure"], "example": case["example"], "p": p, "q": q, "k": k,
                "gamma": int(arrivals[0, k - 1]) if k <= sp["horizon"] else np.nan, "norm_path": norms[0, k - 1],
                "q05": qs[0, k - 1], "q50": qs[1, k - 1], "q95": qs[2, k - 1], "plain_mean": norms[:, k - 1].mean(),
                "rb_mean": rb[:, k - 1].mean() if k <= rb.shape[1] else np.nan,
                "exact_mean": exact[k - 1] if k <= len(exact) else np.nan,
            })
    for j, point in enumerate(sp["estimator_points"]):
        ex = params["examples"][point["example"]]
        em = load_moments(table, point["example"])
        rng = np.random.default_rng([sp["seed"], 100 + j])
        checks.append(_estimator_check(_system(ex), np.asarray(ex["Sigma0"], float), point["example"],
                                       float(point["p"]), float(point["q"]), em, sp["rb_paths"], rng))
    return {"table": pd.DataFrame(rows), "check": pd.DataFrame(checks)}


# ----------------------------------------------------------------------------- claims
def _bool(v):
    return str(v).strip().lower() in ("true", "1")


def claims_step(params, inputs, outputs):
    """Every number and qualitative statement of Section 5 as a claim row with a computed verdict."""
    ex1, ex2 = params["examples"]["I"], params["examples"]["II"]
    checks = pd.read_csv(inputs["checks"]).set_index("check")
    curves = pd.read_csv(inputs["curves"])
    iid = pd.read_csv(inputs["iid"]).set_index("example")
    smap = pd.read_csv(inputs["map"], keep_default_na=False)
    est = pd.read_csv(inputs["estimators"])
    moments = pd.read_csv(inputs["moments"])
    rows = []
    add = rows.append
    lam1, lam2 = mm.spectral_abs(ex1["A"]), mm.spectral_abs(ex2["A"])
    lo1 = mm.observability_index(np.asarray(ex1["A"]), np.asarray(ex1["C"]))
    lo2 = mm.observability_index(np.asarray(ex2["A"]), np.asarray(ex2["C"]))
    p_prop1 = float(mm.prop1_bound(lam1, np.array([0.65]), lo1)[0])
    add(claim_row(SLUG, "exI_l_o", "Example I: observability index l_o (the Sec. 5.1 formula uses l_o = 2)", 2, lo1, 0,
                  "integer", note="Definition 2 computed by rank test"))
    add(claim_row(SLUG, "exII_l_o", "Example II: observable but not one-step observable (l_o = 2)", 2, lo2, 0, "integer"))
    add(claim_row(SLUG, "exI_prop1_q065", "Example I, q = 0.65: Proposition 1 requires p < 0.22", 0.22, p_prop1, 0.005,
                  "paper rounds to two decimals", note="p < (1-|lambda|^2(1-q))/(|lambda|^4 q), eq. (8) with l_o = 2"))
    rho0 = mm.h_radius(ex1["A"], ex1["C"], [np.zeros((2, 1))], p_prop1, 0.65)
    add(claim_row(SLUG, "exI_prop1_is_K0", "Proposition 1 is Theorem 1 with K = 0: rho(H(0)) = 1 at the Prop. 1 bound", 1.0,
                  rho0, 1e-9, "exact identity (H(0) is a function of A(x)A)"))
    st = lambda p, q: mm.gilbert_elliott_stationary_loss(p, q)  # noqa: E731
    add(claim_row(SLUG, "exI_loss_rate_004", "P(gamma=0) = 0.0580 at (p, q) = (0.04, 0.65)", 0.0580, st(0.04, 0.65), 5e-5,
                  "paper gives 4 decimals", note="stationary law p/(p+q)"))
    add(claim_row(SLUG, "exI_loss_rate_prop1", "Proposition 1 permits P(gamma=0) = 0.2529 (at p = its bound, q = 0.65)",
                  0.2529, st(p_prop1, 0.65), 5e-5, "paper gives 4 decimals",
                  note=f"at the exact bound p = {p_prop1:.5f}; at the rounded p = 0.22 it is {st(0.22, 0.65):.5f}"))
    add(claim_row(SLUG, "exI_lmi_p1", "Example I, q = 0.65: the LMI of Theorem 2 is feasible at p = 1 - eps", True,
                  bool(checks.loc["exI_thm2_p1", "certified"]), 0, "qualitative; certified by rho(H(K)) < 1",
                  note=f"rho(H(K)) = {checks.loc['exI_thm2_p1', 'rho_H']:.4f}, solver {checks.loc['exI_thm2_p1', 'status']}"))
    row_065 = curves[(curves.example == "I")]
    pth = float(np.interp(0.65, row_065.q, row_065.p_thm5_uncapped))
    add(claim_row(SLUG, "exI_thm5_q065_above1", "Example I, q = 0.65: Theorem 5 bound exceeds 1 (all p in (0,1) MSS)", True,
                  bool(pth > 1), 0, "qualitative", note=f"p_underline(0.65) ~ {pth:.3f} (uncapped, interpolated)"))
    add(claim_row(SLUG, "exI_fig4_stable", "Fig. 4: (p, q) = (0.99, 0.65) on Example I is (peak-covariance) stable", True,
                  bool(checks.loc["exI_thm2_p099", "certified"]), 0, "qualitative; LMI certified"))
    lower = float(checks.loc["exII_q05_tight_lower", "p"])
    upper = float(checks.loc["exII_q05_tight_upper", "p"])
    analytic = float(mm.parity_bound_example2(lam2, 0.5))
    add(claim_row(SLUG, "exII_thm5_q05", "Example II, q = 0.5: Theorem 5 bound p_underline = 0.465", 0.465, lower, 0.0005,
                  "paper gives 3 decimals (half a unit of the last digit)",
                  note=f"bisection bracket [{lower:.7f}, {upper:.7f}]; closed form (1-(|l|^2(1-q))^2)/(|l|^4 q) = {analytic:.7f}"))
    add(claim_row(SLUG, "exII_thm5_q05_closed_form", "Bisection of Theorem 5 equals our closed form for Example II at q = 0.5",
                  analytic, lower, 1e-6, "bisection tolerance 1e-7 plus solver margin"))
    add(claim_row(SLUG, "exII_p0465_certified", "Example II: 'if p <= 0.465 the Kalman filter is MSS' (Thm 5 certifies p = 0.465)",
                  True, bool(checks.loc["exII_thm5_p0465", "certified"]), 0, "qualitative",
                  note=f"p_underline = {lower:.6f} < 0.465: the paper rounded up and used <= for a supremum; "
                       "p = 0.465 is not certified (and exceeds the parity necessary condition)", erratum=True))
    add(claim_row(SLUG, "exII_lmi_p1_infeasible", "Example II, q = 0.5, p = 1: the LMI of Theorem 2 is infeasible", True,
                  not bool(checks.loc["exII_thm2_p1", "certified"]), 0, "qualitative",
                  note=f"solver status {checks.loc['exII_thm2_p1', 'status']}, margin {checks.loc['exII_thm2_p1', 'margin']:.2e}"))
    add(claim_row(SLUG, "exII_fig5_stable", "Fig. 5: (p, q) = (0.45, 0.5) on Example II is MSS (0.45 < p_underline)", True,
                  bool(checks.loc["exII_fig5_p045", "certified"]), 0, "qualitative; LMI certified"))
    em2 = load_moments(moments, "II")
    rate, last, verdict = classify_growth(em2.mean(0.99, 0.5, "norm"), params["map"]["bounded_tol"],
                                          params["map"]["unbounded_tol"])
    add(claim_row(SLUG, "exII_fig6_diverges", "Fig. 6: E||P_k|| diverges at (p, q) = (0.99, 0.5) on Example II", True,
                  bool(verdict == "unbounded"), 0, "qualitative; exact expectation over all channel paths",
                  note=f"exact growth rate {float(rate):.3f} per step (E||P_k|| x {np.exp(2 * float(rate)):.2f} every 2 steps)"))
    for name, lam in (("I", lam1), ("II", lam2)):
        r = iid.loc[name]
        add(claim_row(SLUG, f"ex{name}_iid_consistent",
                      f"Remark 4 (Example {name}): on p + q = 1 the critical value is Sinopoli's lambda_c, within "
                      "[1 - 1/|lambda|^2, LMI upper bound], and Theorem 5 stays on the stable side", True,
                      bool(_bool(r["consistent"])), 0, "qualitative",
                      note=f"lower {r['lambda_lower']:.4f}, Sinopoli LMI {r['lambda_lmi_upper']:.4f}, Thm 5 crossing "
                           f"q* = {r['q_thm5_on_iid_line']:.4f}, reference {r['lambda_c_reference']:.4f}"))
    less = bool((curves.p_thm5_uncapped >= curves.p_prop1_uncapped - 1e-3).all())
    add(claim_row(SLUG, "thm2_less_conservative", "Theorem 2/5 is less conservative than Proposition 1 (p_thm5 >= p_prop1 on all q)",
                  True, less, 0, "qualitative, bisection tolerance 1e-3"))
    n_unc = int(curves.thm5_n_uncertified.sum())
    add(claim_row(SLUG, "solver_feasible_certified", "Every solver-feasible LMI answer of the Theorem 5 sweeps is certified (rho(H(K)) < 1)",
                  0, n_unc, 0, "count of uncertified answers; must be zero",
                  note=f"{int(curves.thm5_n_solves.sum())} solves"))
    for name in ("I", "II"):
        s = smap[smap.example == name]
        ref = curves[curves.example == name]
        lam = mm.spectral_abs(params["examples"][name]["A"])
        nec = lam ** 2 * (1 - s.q) < 1
        p_thm5 = np.interp(s.q, ref.q, ref.p_thm5, left=0.0)
        contra = int((((s.verdict == "unbounded") & nec & (s.p < p_thm5 - 0.01))
                      | ((s.verdict == "bounded") & ~nec)).sum())
        add(claim_row(SLUG, f"ex{name}_map_consistent",
                      f"Example {name}: stability map agrees with Thm 5 (sufficient) and the necessary condition "
                      "(decided points contradicting either)", 0, contra, 0, "count; must be zero",
                      note=f"{(s.verdict == 'undecided').sum()} of {len(s)} grid points undecided at the exact horizon"))
    for _, r in est.iterrows():
        pass
    worst = est.loc[est.plain_over_long.idxmin()] if "plain_over_long" in est else None
    if worst is not None:
        add(claim_row(SLUG, "plain_mean_understates", "Issue: a plain sample mean understates E||P_k|| near/beyond the boundary "
                      "(ratio plain / conditional estimator at the long horizon, worst point)", 1.0, float(worst.plain_over_long),
                      0.5, "a factor of 2 counts as failure",
                      note=f"example {worst.example}, (p, q) = ({worst.p}, {worst.q}), k = {int(worst.k_long)}"))
    return {"table": claims_frame(rows)}
