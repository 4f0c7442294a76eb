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
    unbounded / undecided), ``growth_rate`` (log-growth per step of the method that decided),
    ``growth_rate_exact`` (extrapolated from the exact E||P_k||), ``growth_rate_last`` (raw rate over
    the last two exact steps), ``mean_norm_last`` (exact E||P_K||), ``growth_rate_long`` and
    ``rel_halfwidth_long`` (long-horizon conditional estimator, only for points the exact horizon
    left undecided), ``method`` (which computation decided).
``sample_paths.csv``
    for each of Figs 3-6: ``figure, example, p, q, k, gamma`` (one sample path; gamma_k),
    ``norm_path`` (||P_k|| along it), ``q05, q50, q95`` (Monte Carlo quantiles of ||P_k||),
    ``plain_mean`` (sample mean), ``rb_mean`` (conditional estimator), ``exact_mean`` (k <= depth+1).
``estimator_check.csv``
    ``example, p, q, k, exact_mean, plain_mean, plain_ci_high, rb_mean, rb_ci_low, rb_ci_high,
    plain_over_exact, rb_over_exact`` at ``k = depth + 1`` (conditional estimator against the
    exact value); ``k_long, plain_mean_long, rb_mean_long, plain_over_rb_long`` at the long
    horizon (the plain sample mean failing); ``n_paths``.
"""

from __future__ import annotations

import time

import numpy as np
import pandas as pd

from ..claims import claim_row, claims_frame, errata_frame, reconstructions_frame
from ..config import ConfigError, require_matrix, require_pd
from . import markov_math as mm

__all__ = [
    "check_config", "critical_curves_step", "lmi_checks_step", "iid_line_step", "exact_moments_step",
    "stability_map_step", "sample_paths_step", "claims_step", "errata_step", "reconstructions_step",
    "figure_plane", "figure_path", "figure_mean", "figure_estimators", "figure_curves", "classify_growth",
    "load_moments", "refine_long_horizon",
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


REFINE_DEFAULTS = {"enabled": True, "n_paths": 200, "horizon": 160, "n_batches": 10, "rel_tol": 0.1,
                   "bounded_tol": 0.003, "unbounded_tol": 0.01, "chunk": 64, "seed": 4242,
                   "pilot_paths": 100, "pilot_horizon": 60}


def refine_long_horizon(system, Sigma0, ps, qs, opts, rng):
    """Long-horizon verdicts from the conditional trace estimator (:func:`markov_math.rb_trace_grid`).

    The growth rate is ``log(m_T / m_{T/2}) / (T/2)``. The estimator integrates the trailing loss
    run exactly but samples everything before it, so it is trusted only where its batch-means
    95% half-width stays below ``rel_tol`` of the mean over ``k >= T/2`` (a heavy tail that is not
    a trailing loss run, e.g. Example II's parity-locked receptions, shows up as a wide interval);
    elsewhere the verdict stays ``undecided``. A short pilot run screens out points whose interval
    is already wider than twice ``rel_tol``.

    Returns
    -------
    (rate, rel_halfwidth, verdict) arrays over the points.
    """
    def run(idx, n_paths, T):
        rates, rels = [], []
        for start in range(0, len(idx), opts["chunk"]):
            sel = idx[start:start + opts["chunk"]]
            m, h = mm.rb_trace_grid(system, Sigma0, ps[sel], qs[sel], n_paths, T, rng, opts["n_batches"])
            with np.errstate(divide="ignore", invalid="ignore"):
                rates.append(np.log(m[:, -1] / m[:, T // 2]) / (T - T // 2))
                rels.append(np.max(h[:, T // 2:] / m[:, T // 2:], axis=1))
        return (np.concatenate(rates), np.concatenate(rels)) if rates else (np.array([]), np.array([]))

    ps, qs = np.asarray(ps, float), np.asarray(qs, float)
    rate, rel = np.full(len(ps), np.nan), np.full(len(ps), np.inf)
    # pilot: a short, cheap run; points whose interval is already wide are not worth the long run
    _, rel_pilot = run(np.arange(len(ps)), opts["pilot_paths"], opts["pilot_horizon"])
    keep = np.flatnonzero(np.isfinite(rel_pilot) & (rel_pilot < 2 * opts["rel_tol"]))
    rate[keep], rel[keep] = run(keep, opts["n_paths"], opts["horizon"])
    reliable = np.isfinite(rate) & np.isfinite(rel) & (rel < opts["rel_tol"])
    verdict = np.where(~reliable, "undecided", np.where(rate < opts["bounded_tol"], "bounded",
                                                         np.where(rate > opts["unbounded_tol"], "unbounded", "undecided")))
    return rate, rel, verdict


def stability_map_step(params, inputs, outputs):
    """Independent stability map of E||P_k|| on a (p, q) grid.

    1. Exact E||P_k|| over all channel paths for ``k <= depth + 1`` (:func:`markov_math.exact_moments`),
       growth extrapolated by :func:`classify_growth`.
    2. Points left undecided get the long-horizon conditional estimator of E tr P_k
       (:func:`refine_long_horizon`; trace and 2-norm are equivalent norms for boundedness),
       trusted only where its confidence interval is narrow.
    """
    table = pd.read_csv(inputs["moments"])
    mp = params["map"]
    opts = dict(REFINE_DEFAULTS, **mp.get("refine", {}))
    ps = np.linspace(mp["p_min"], mp["p_max"], mp["p_points"])
    qs = np.linspace(mp["q_min"], mp["q_max"], mp["q_points"])
    P, Qg = np.meshgrid(ps, qs, indexing="ij")
    frames = []
    for e_idx, (name, ex) in enumerate(params["examples"].items()):
        em = load_moments(table, name)
        means = em.mean(P, Qg, "norm")
        rate, last, verdict = classify_growth(means, mp["bounded_tol"], mp["unbounded_tol"])
        exact_method = f"exact E||P_k|| over all 2^{em.depth - 1} channel paths (k<={em.depth + 1}), extrapolated growth"
        f = pd.DataFrame({"example": name, "p": P.ravel(), "q": Qg.ravel(), "verdict": verdict.ravel(),
                          "growth_rate": rate.ravel(), "growth_rate_exact": rate.ravel(), "growth_rate_last": last.ravel(),
                          "mean_norm_last": means[..., -1].ravel(), "growth_rate_long": np.nan,
                          "rel_halfwidth_long": np.nan, "method": exact_method})
        todo = np.flatnonzero(f.verdict.to_numpy() == "undecided")
        if opts["enabled"] and len(todo):
            rng = np.random.default_rng([opts["seed"], e_idx])
            r_long, rel, v_long = refine_long_horizon(_system(ex), np.asarray(ex["Sigma0"], float),
                                                      f.p.to_numpy()[todo], f.q.to_numpy()[todo], opts, rng)
            f.loc[todo, "growth_rate_long"] = r_long
            f.loc[todo, "rel_halfwidth_long"] = rel
            decided = todo[v_long != "undecided"]
            f.loc[decided, "verdict"] = v_long[v_long != "undecided"]
            f.loc[decided, "growth_rate"] = r_long[v_long != "undecided"]
            f.loc[decided, "method"] = (f"conditional estimator of E tr P_k, k<={opts['horizon'] + 1}, "
                                        f"{opts['n_paths']} paths, 95% half-width < {opts['rel_tol']:g} of the mean")
            f.loc[todo[v_long == "undecided"], "method"] = "undecided: exact horizon too short, conditional estimator not trusted"
        f.insert(3, "bounded", f.verdict.map({"bounded": "True", "unbounded": "False"}).fillna(""))
        frames.append(f)
    return {"table": pd.concat(frames, ignore_index=True)}


# ----------------------------------------------------------------------------- sample paths (Figs 3-6)
def _estimator_check(system, S0, example, p, q, em, n, horizon, rng):
    """Plain sample mean and conditional estimator of E||P_k||: against the exact value at k = depth + 1,
    and against each other at the long horizon ``k = horizon + 1`` (where only the conditional one is trusted)."""
    exact = em.mean(p, q, "norm")
    k = len(exact)
    norms, arrivals = mm.plain_mc(system, S0, p, q, n, max(horizon, k - 1), rng)
    rb = mm.rb_mean_norm(system, S0, p, q, arrivals)
    plain, rbk = norms[:, k - 1], rb[:, k - 1]
    se_p, se_r = plain.std(ddof=1) / np.sqrt(n), rbk.std(ddof=1) / np.sqrt(n)
    kl = rb.shape[1]
    return {"example": example, "p": p, "q": q, "k": k, "exact_mean": exact[k - 1],
            "plain_mean": plain.mean(), "plain_ci_high": plain.mean() + 1.96 * se_p,
            "rb_mean": rbk.mean(), "rb_ci_low": rbk.mean() - 1.96 * se_r, "rb_ci_high": rbk.mean() + 1.96 * se_r,
            "plain_over_exact": plain.mean() / exact[k - 1], "rb_over_exact": rbk.mean() / exact[k - 1],
            "k_long": kl, "plain_mean_long": norms[:, kl - 1].mean(), "rb_mean_long": rb[:, kl - 1].mean(),
            "plain_over_rb_long": norms[:, kl - 1].mean() / rb[:, kl - 1].mean(), "n_paths": n}


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
                                       float(point["p"]), float(point["q"]), em, sp["rb_paths"], sp["rb_horizon"], rng))
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
    proxy = float(mm.norm_relaxation_bound(np.asarray(ex1["A"], float), 0.65))
    for cid, val, where in (("ref16_p004", 0.04, "'[16] concludes that p < 0.04 guarantees peak-covariance stability'"),
                            ("ref16_p0045", 0.045, "'the criterion of [16] only covers failure rates lower than 4.5%'")):
        add(claim_row(SLUG, cid, f"Example I, q = 0.65: {where}", val, proxy, 0.005, "two significant digits",
                      note="[16]'s constants cannot be recomputed from this text; our value is the norm relaxation "
                           "q sum (1-q)^(j-1)||A^j||^2 p||A||^2 < 1 by which the paper says its Theorem 1 covers [15-17] "
                           "(a proxy, not [16]'s criterion); the two printed values disagree with each other (erratum E4)"))
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
                      note=f"{(s.verdict == 'undecided').sum()} of {len(s)} grid points undecided"))
    return {"table": claims_frame(rows)}


# ----------------------------------------------------------------------------- errata and reconstructions
def _schur_residual(A, C, p, q, rng):
    """max |Schur complement of Psi (11) - (X - sum_i w_i M_i' Y M_i)| on random data, with C^{(i)} = [C; ...; CA^{i-1}]."""
    n, m = A.shape[0], C.shape[0]
    l_o = mm.observability_index(A, C)
    X = np.eye(n) * 50.0
    G = rng.standard_normal((n, n))
    Y = G @ G.T + np.eye(n)
    F = [rng.standard_normal((m * i, n)) for i in range(1, l_o)]
    cols = [np.sqrt(p * (1 - p) ** (i - 1)) * (Y @ np.linalg.matrix_power(A, i) + F[i - 1].T @ mm.stacked_output(A, C, i))
            for i in range(1, l_o)]
    schur = X - sum(c.T @ np.linalg.solve(Y, c) for c in cols)
    K = [np.linalg.solve(Y, f.T) for f in F]
    direct = X - sum(p * (1 - p) ** (i - 1) * M.T @ Y @ M for i, M in
                     ((i, np.linalg.matrix_power(A, i) + K[i - 1] @ mm.stacked_output(A, C, i)) for i in range(1, l_o)))
    return float(np.max(np.abs(schur - direct)))


def errata_step(params, inputs, outputs):
    """Every inconsistency of the text with its correction and a numerical demonstration."""
    checks = pd.read_csv(inputs["checks"]).set_index("check")
    ex1, ex2 = params["examples"]["I"], params["examples"]["II"]
    A1, C1 = np.asarray(ex1["A"], float), np.asarray(ex1["C"], float)
    A2 = np.asarray(ex2["A"], float)
    rng = np.random.default_rng(7)
    schur = _schur_residual(A1, C1, 0.5, 0.65, rng)
    lower = float(checks.loc["exII_q05_tight_lower", "p"])
    analytic = float(mm.parity_bound_example2(mm.spectral_abs(A2), 0.5))
    # adjoint check of eq (9) against eq (7): <L_K(X), P> = <X, H_K(P)>
    K = [rng.standard_normal((2, 1))]
    Xr, Pr = np.eye(2) + 0.1, np.diag([2.0, 0.5])
    lhs = np.trace(mm.L_operator(A1, C1, K, 0.5, 0.65, Xr) @ Pr)
    HP = (mm.H_matrix(A1, C1, K, 0.5, 0.65) @ Pr.reshape(-1, order="F")).real.reshape(2, 2, order="F")
    adj = abs(lhs - np.trace(Xr @ HP))
    m = C1.shape[0]
    rows = [
        {"erratum_id": "E1_C_i_undefined", "location": "eqs. (7), (9), (11), Theorems 1-2",
         "printed": "C^{(i)} used but never defined",
         "corrected": "C^{(i)} = [C; CA; ...; CA^{i-1}] (i-step observability matrix), K^{(i)} of size n x m i",
         "demonstration": "with this reading L_K (9) is the adjoint of H(K) (7) and the Schur complement of (11) is "
                          "X - sum_i w_i M_i'YM_i; residuals of both identities (printed: not evaluable)",
         "residual_printed": np.nan, "residual_corrected": max(schur, adj)},
        {"erratum_id": "E2_eq11_last_block", "location": "eq. (11), last row and column",
         "printed": "(C^{(l_0)})' F_{l_0-1} and F^*_{l_0-1} C^{(l_0)}",
         "corrected": "(C^{(l_o-1)})' F_{l_o-1} and F^*_{l_o-1} C^{(l_o-1)} (also l_0 -> l_o, Definition 2)",
         "demonstration": "F_{l-1} has m(l-1) rows; C^{(l)} has m l rows: row mismatch (printed) vs none (corrected)",
         "residual_printed": float(m), "residual_corrected": 0.0},
        {"erratum_id": "E3_exII_0465", "location": "Section 5.2, Example II",
         "printed": "Theorem 5: if p <= 0.465 the Kalman filter is mean-square stable (q = 0.5)",
         "corrected": f"p < p_underline(0.5) = {analytic:.6f} (a supremum, not attained; rounded down: p < 0.4645)",
         "demonstration": "distance of the printed bound and of our closed form from the certified bisection value; "
                          "the LMI at p = 0.465 is infeasible",
         "residual_printed": 0.465 - lower, "residual_corrected": abs(analytic - lower)},
        {"erratum_id": "E4_ref16_value", "location": "Section 5.1, two paragraphs",
         "printed": "[16] concludes p < 0.04 ... the criterion of [16] only covers failure rates lower than 4.5%",
         "corrected": "one of 0.04 / 0.045 is a slip; [16]'s criterion cannot be recomputed from this text "
                      f"(its norm relaxation with K = 0 gives p < {mm.norm_relaxation_bound(A1, 0.65):.3f})",
         "demonstration": "difference between the two printed values", "residual_printed": 0.005,
         "residual_corrected": np.nan},
        {"erratum_id": "E5_item_reference", "location": "Section 5.1",
         "printed": "the LMI in 2) of Theorem 2", "corrected": "the LMI in (iv) of Theorem 2 (item (ii) is a spectral radius)",
         "demonstration": "textual", "residual_printed": np.nan, "residual_corrected": np.nan},
        {"erratum_id": "E6_prop2_index", "location": "proof of Proposition 2",
         "printed": "pi(z~_k = j | z~_k = i)", "corrected": "pi(z~_{k+1} = j | z~_k = i)",
         "demonstration": "textual (index slip)", "residual_printed": np.nan, "residual_corrected": np.nan},
        {"erratum_id": "E7_phi_definite", "location": "below eq. (9)",
         "printed": "Phi_X is the positive definite solution of (1-q)A'Phi A + qA'XA = Phi",
         "corrected": "Phi_X = sum_j q(1-q)^{j-1} (A')^j X A^j is positive semidefinite (definite if X > 0)",
         "demonstration": "X = 0 gives Phi_X = 0", "residual_printed": np.nan, "residual_corrected": 0.0},
        {"erratum_id": "E8_prop1_form", "location": "Section 5.1",
         "printed": "Proposition 1 requires p < (1-|lambda|^2(1-q)) / (|lambda|^4 q)",
         "corrected": "this closed form is eq. (8) for l_o = 2 only (true for Example I; stated without l_o)",
         "demonstration": "eq. (8) with l_o = 2 vs the closed form at q = 0.65",
         "residual_printed": abs(float(mm.prop1_bound(1.3, np.array([0.65]), 2)[0])
                                 - (1 - 1.69 * 0.35) / (1.69 ** 2 * 0.65)), "residual_corrected": 0.0},
        {"erratum_id": "E9_typo_equiblock", "location": "Definitions 5-6",
         "printed": "quasi-eqiblock", "corrected": "quasi-equiblock", "demonstration": "textual",
         "residual_printed": np.nan, "residual_corrected": np.nan},
    ]
    for r in rows:
        r["paper"] = SLUG
    return {"table": errata_frame(rows)}


def reconstructions_step(params, inputs, outputs):
    """Every parameter the paper does not state: key, value, reason, sensitivity."""
    sp, ex = params["paths"], params["examples"]
    rows = [
        ("examples.*.Sigma0", str(ex["I"]["Sigma0"]) + " / " + str(ex["II"]["Sigma0"]),
         "Sigma_0 >= 0 is never given", "boundedness does not depend on it (Prop. 2 holds for all Sigma_0); "
         "finite-horizon means and the undecided band of the map do"),
        ("gamma_1", "1", "paper: 'without loss of generality gamma_1 = 1'; used in every simulation and exact sum",
         "none for boundedness"),
        ("C^{(i)}", "[C; CA; ...; CA^{i-1}]", "undefined in the text (erratum E1)", "l_o = 2 in both examples, so only C^{(1)} = C enters"),
        ("checks.eps", str(params["checks"]["eps"]), "footnote 4: p = 1 - eps, eps 'arbitrarily small'",
         "the Example I LMI is feasible up to p ~ 1.4 (uncapped), so any eps works"),
        ("paths.horizon", str(sp["horizon"]), "figure horizons not stated", "visual only"),
        ("paths.seed", str(sp["seed"]), "sample paths of Figs 3-5 are random; the paper's realisations are lost",
         "the drawn path changes; bands and means do not"),
        ("paths.n_paths / rb_paths", f"{sp['n_paths']} / {sp['rb_paths']}", "Monte Carlo sizes for bands and conditional means",
         "band edges move by ~1/sqrt(n)"),
        ("exact.depth", str(params["exact"]["depth"]), "exact expectation over all 2^(depth-1) channel paths; memory/time budget",
         "larger depth narrows the undecided band of the stability map"),
        ("map.bounded_tol / unbounded_tol", f"{params['map']['bounded_tol']} / {params['map']['unbounded_tol']}",
         "growth-rate thresholds of the map verdicts; chosen so that the finite-horizon transient of stable points near "
         "the boundary is not called unbounded", "move points between decided and undecided"),
        ("curves.p_uncapped_max", str(params["curves"]["p_uncapped_max"]),
         "search cap of the uncapped Theorem 5 value (l_o = 2: the LMI depends on sqrt(p) only)",
         "rows with thm5_saturated = True are lower bounds"),
        ("LMI normalisation", "max t s.t. Psi >= t I, (10) >= 0, Y <= I; margin_tol 1e-7",
         "the LMI (10)-(11) is homogeneous; strictness needs a margin", "feasible answers are certified by rho(H(K)) < 1 anyway"),
        ("norm", "induced 2-norm ||P_k|| (largest eigenvalue)", "paper's notation section", "map uses the same norm"),
    ]
    return {"table": reconstructions_frame({"paper": SLUG, "key": k, "value": v, "reason": r, "sensitivity": s}
                                           for k, v, r, s in rows)}


# ----------------------------------------------------------------------------- figures
_COLORS = {"bounded": "#2ca02c", "unbounded": "#d62728", "undecided": "#bbbbbb"}


def figure_plane(params, inputs, outputs):
    """Fig. 2 made quantitative: the p-q plane of both examples with the curves and the stability map."""
    from ..plotting import new_figure, save_figure

    curves = pd.read_csv(inputs["curves"])
    smap = pd.read_csv(inputs["map"], keep_default_na=False)
    iid = pd.read_csv(inputs["iid"]).set_index("example")
    names = list(params["examples"])
    fig, axes = new_figure(1, len(names), figsize=(5.2 * len(names), 4.6), squeeze=False)
    for ax, name in zip(axes[0], names):
        s = smap[smap.example == name]
        for verdict, color in _COLORS.items():
            sub = s[s.verdict == verdict]
            ax.scatter(sub.q, sub.p, s=7, marker="s", color=color, alpha=0.55, linewidths=0,
                       label=f"map: E||P_k|| {verdict}")
        c = curves[curves.example == name]
        ax.plot(c.q, c.p_thm5, color="k", lw=2, label="Theorem 5 lower bound p(q)")
        ax.plot(c.q, c.p_prop1, color="tab:blue", lw=1.5, ls="--", label="Proposition 1 (eq. 8)")
        if c.p_reference.notna().any():
            ax.plot(c.q, c.p_reference, color="tab:purple", lw=1, ls=":", label="reference p_c (table column reference)")
        qn = c.q_necessary.iloc[0]
        ax.axvline(qn, color="tab:orange", lw=1.5, label=f"necessary |lambda|^2(1-q) = 1 (q = {qn:.3f})")
        ax.plot([0, 1], [1, 0], color="0.3", lw=1, ls="-.", label="i.i.d. line p + q = 1")
        r = iid.loc[name]
        ax.plot([r.q_thm5_on_iid_line], [1 - r.q_thm5_on_iid_line], "k*", ms=10, label="Thm 5 on the i.i.d. line")
        ax.plot([r.lambda_lmi_upper], [1 - r.lambda_lmi_upper], "bv", ms=7, label="Sinopoli LMI bound")
        ax.plot([r.lambda_lower], [1 - r.lambda_lower], "b^", ms=7, label="Sinopoli lower bound")
        ax.set_xlim(0, 1)
        ax.set_ylim(0, 1.02)
        ax.set_xlabel("recovery rate q")
        ax.set_ylabel("failure rate p")
        ax.set_title(f"Example {name}")
    axes[0][-1].legend(fontsize=6.5, loc="upper left", bbox_to_anchor=(1.0, 1.0))
    save_figure(fig, outputs["figure"])
    return {}


def figure_path(params, inputs, outputs):
    """Figs. 3-5: a sample path of ||P_k|| and gamma_k, with Monte Carlo bands and trustworthy means."""
    from ..plotting import new_figure, save_figure

    t = pd.read_csv(inputs["paths"])
    t = t[t.figure == params["figure"]]
    fig, (ax, ax2) = new_figure(2, 1, figsize=(6.4, 4.8), sharex=True, gridspec_kw={"height_ratios": [3, 1]})
    ax.fill_between(t.k, t.q05, t.q95, color="tab:blue", alpha=0.15, label="5-95% of ||P_k|| (Monte Carlo)")
    ax.plot(t.k, t.q50, color="tab:blue", lw=1, ls="--", label="median")
    ax.plot(t.k, t.norm_path, color="k", lw=1.2, label="one sample path ||P_k||")
    ax.plot(t.k, t.rb_mean, color="tab:red", lw=1.5, label="E||P_k|| (conditional estimator)")
    ax.plot(t.k, t.exact_mean, color="tab:orange", lw=2.5, ls=":", label="E||P_k|| (exact, all paths)")
    ax.set_yscale("log")
    ax.set_ylabel("||P_k||")
    p, q = t.p.iloc[0], t.q.iloc[0]
    ax.set_title(f"Example {t.example.iloc[0]}, p = {p}, q = {q}")
    ax.legend(fontsize=7)
    g = t.dropna(subset=["gamma"])
    ax2.step(g.k, g.gamma, where="post", color="k", lw=0.8)
    ax2.set_ylim(-0.2, 1.2)
    ax2.set_yticks([0, 1])
    ax2.set_ylabel("gamma_k")
    ax2.set_xlabel("k")
    save_figure(fig, outputs["figure"])
    return {}


def figure_mean(params, inputs, outputs):
    """Fig. 6: divergence of E||P_k|| at (0.99, 0.5) on Example II (exact, conditional, plain)."""
    from ..plotting import new_figure, save_figure

    t = pd.read_csv(inputs["paths"])
    t = t[t.figure == params["figure"]]
    fig, ax = new_figure()
    ax.plot(t.k, t.exact_mean, color="tab:orange", lw=2.5, label="E||P_k|| exact (all channel paths)")
    ax.plot(t.k, t.rb_mean, color="tab:red", lw=1.2, label="conditional estimator (trailing loss run integrated)")
    ax.plot(t.k, t.plain_mean, color="tab:blue", lw=1, ls="--", label="plain sample mean")
    ax.plot(t.k, t.q50, color="0.5", lw=1, ls=":", label="median ||P_k||")
    ax.set_yscale("log")
    ax.set_xlabel("k")
    ax.set_ylabel("E||P_k||")
    ax.set_title(f"Example {t.example.iloc[0]}, p = {t.p.iloc[0]}, q = {t.q.iloc[0]}")
    ax.legend(fontsize=7)
    save_figure(fig, outputs["figure"])
    return {}


def figure_estimators(params, inputs, outputs):
    """Fig. S1: plain sample mean vs conditional estimator vs exact expectation."""
    from ..plotting import new_figure, save_figure

    e = pd.read_csv(inputs["check"])
    labels = [f"Ex {r.example}\n({r.p:g}, {r.q:g})" for r in e.itertuples()]
    x = np.arange(len(e))
    fig, ax = new_figure(figsize=(7.0, 4.0))
    ax.bar(x - 0.27, e.plain_over_exact, 0.27, label="plain / exact  (k = depth+1)", color="tab:blue")
    ax.bar(x, e.rb_over_exact, 0.27, label="conditional / exact  (k = depth+1)", color="tab:red")
    ax.bar(x + 0.27, e.plain_over_rb_long, 0.27, label="plain / conditional  (long horizon)", color="0.5")
    ax.axhline(1.0, color="k", lw=0.8)
    ax.set_yscale("log")
    ax.set_xticks(x)
    ax.set_xticklabels(labels, fontsize=7)
    ax.set_ylabel("ratio of estimates of E||P_k||")
    ax.legend(fontsize=7)
    save_figure(fig, outputs["figure"])
    return {}


def figure_curves(params, inputs, outputs):
    """Fig. S2: uncapped Proposition 1 and Theorem 5 bounds (log scale) with the reference critical values."""
    from ..plotting import new_figure, save_figure

    curves = pd.read_csv(inputs["curves"])
    fig, ax = new_figure()
    for name, color in zip(params["examples"], ("tab:blue", "tab:green", "tab:red")):
        c = curves[curves.example == name]
        ax.plot(c.q, c.p_thm5_uncapped, color=color, lw=2, label=f"Ex {name}: Theorem 5 (uncapped)")
        ax.plot(c.q, c.p_prop1_uncapped, color=color, lw=1, ls="--", label=f"Ex {name}: Proposition 1")
        sat = c[c.thm5_saturated.astype(str).str.lower() == "true"]
        ax.plot(sat.q, sat.p_thm5_uncapped, "^", color=color, ms=5, label=f"Ex {name}: search cap reached")
    ax.axhline(1.0, color="k", lw=0.8)
    ax.set_yscale("log")
    ax.set_xlabel("q")
    ax.set_ylabel("bound on p")
    ax.legend(fontsize=7)
    save_figure(fig, outputs["figure"])
    return {}
