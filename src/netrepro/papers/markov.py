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
