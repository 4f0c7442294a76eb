"""Paper `markov`: Wu, Shi, Anderson, Johansson, *Stability Conditions and Phase Transition for
Kalman Filtering over Markovian Channels*. Pipeline steps.

The mathematics lives in the math modules of this package (:mod:`.model`, :mod:`.lmis`,
:mod:`.exact`, :mod:`.estimators`, :mod:`.stability`); this module holds the step functions called
by the rules generated from ``steps.yaml`` (signature ``fn(params, inputs, outputs)``).

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
    point checks of Theorem 2 / 5: ``check, example, p, q, status, verdict, evidence, margin, solver_feasible,
    certified, rho_H, lyap_margin``; ``certified`` is True when the verdict rests on a certificate, feasible
    (eigenvalue check and ``rho(H(K)) < 1``) or infeasible (a necessary condition or a checked dual certificate).
``tight_variants.csv``
    the tight Theorem 5 bisections repeated at each ``checks.tight_tol_variants``: ``check, example,
    q, tol, p_lower, p_upper, certified, n_solves, n_undecided, statuses`` (solver statuses seen).
``lmi_benchmark.csv``
    ``mode`` (parametrised / rebuilt), ``n_solves, seconds, solves_per_second``.
``iid_line.csv``
    ``example, lambda_lower`` (1 - 1/|lambda_max(A)|^2), ``lambda_lmi_upper`` (Sinopoli LMI),
    ``lambda_lmi_upper_infeasible_end`` (the bisection's certified-infeasible end),
    ``lambda_lmi_infeasible_certified_end`` (the larger of it and the arrival rate below which a lower
    bound certifies divergence, where the LMI, sufficient for stability, cannot be feasible),
    ``lambda_lmi_infeasible_evidence`` and ``lambda_lmi_bracket_width`` (upper minus that end),
    ``q_thm5_on_iid_line`` (smallest q with the Theorem 2 LMI certified at p = 1 - q),
    ``lambda_c_reference`` and ``reference``, ``consistent``.
``exact_moments.csv``
    polynomial coefficients of the exact E||P_k||: ``example, depth, n11, n10, n01, n00,
    sum_norm, sum_trace`` (see :class:`~netrepro.papers.markov.exact.ExactMoments`).
``stability_map.csv``
    ``example, p, q, bounded`` (True / False / empty when undecided), ``verdict`` (bounded /
    unbounded / undecided), ``growth_rate`` (log-growth per step of the method that decided),
    ``growth_rate_exact`` (extrapolated from the exact E||P_k||), ``growth_rate_last`` (raw rate over
    the last two exact steps), ``mean_norm_last`` (exact E||P_K||), ``growth_rate_long`` and
    ``rel_halfwidth_long`` (long-horizon conditional estimator, only for points the exact horizon
    left undecided), ``method`` (which computation decided), ``p_thm1`` (``1 / rho(H_1(K))``: Theorem 1 certifies
    every ``p < p_thm1`` at that ``q``) and ``p_thm1_above_cap`` (``p_thm1 > 1``: above the cap ``p <= 1`` of a
    failure rate, so the number is no failure rate; it says that every ``p < 1`` is certified).
``sample_paths.csv``
    for each of Figs 3-6: ``figure, example, p, q, k, gamma`` (one sample path; gamma_k),
    ``norm_path`` (||P_k|| along it), ``q05, q50, q95`` (Monte Carlo quantiles of ||P_k||),
    ``plain_mean`` (sample mean), ``rb_mean`` (conditional estimator), ``exact_mean`` (k <= depth+1).
``estimator_check.csv``
    ``example, p, q, k, exact_mean, plain_mean, plain_ci_high, rb_mean, rb_ci_low, rb_ci_high,
    plain_over_exact, rb_over_exact`` at ``k = depth + 1`` (conditional estimator against the
    exact value); ``k_long, plain_mean_long, rb_mean_long, plain_over_rb_long`` at the long
    horizon (the plain sample mean failing); ``n_paths``.
``expectations.csv``
    for each of Figs 3-6 and ``k = 1..horizon+1`` (same ``k`` as ``sample_paths.csv``, ``P_1 = Sigma0``):
    ``example, p, q, k, mean_norm`` (E||P_k||, spectral norm of the prediction covariance),
    ``lo, hi`` and ``method``: ``exact`` (all channel paths, lo = hi = mean), ``estimate_conditional``
    (conditional estimator validated against the exact values, 95% interval, relative half-width
    below ``rel_tol``), ``asymptote`` (derived two-step rate, bracket from the observed ratio, validated
    by a backtest on the exact range) or ``not_trustworthy`` (empty mean); on ``asymptote`` rows
    ``limit, limit_lo, limit_hi``: ``lim_k E||P_k||`` of the asymptote and its bracket (``inf`` when it
    diverges; :func:`.expectations.asymptote_limit`), empty elsewhere.
``asymptote_holdout.csv``
    out-of-sample test of the asymptote: for every figure setting continued by the asymptote, the exact
    ``E||P_k||`` at the ``expectations.holdout`` steps after the exact range (computed here, from a deeper tree
    than the asymptote saw) against the asymptote's bracket: ``figure, example, p, q, k, exact_mean, asym_mean,
    asym_lo, asym_hi, inside``.

Every step that solves LMIs fails, naming itself and the solver statuses, when none of its LMI questions was
decided by a certificate (:func:`_require_decisions`): a table of undecided answers only would be no result. The
runner stops such a step too, from the engine's count of certified verdicts; this check counts the paper's own
final verdicts (a point the engine certifies feasible but whose gain has ``rho(H(K)) >= 1`` is undecided here).
"""

from __future__ import annotations

import time

import numpy as np
import pandas as pd

from ...errors import ModelError
from . import estimators as est
from . import expectations as xp
from .exact import ExactMoments, exact_moments_auto, find_split
from .lmis import GilbertElliottLMI, as_verdict, rebuild_solve, sinopoli_lmi_threshold, thm5_lower_bound
from .model import LinearSystem, observability_index, parity_bound_example2, prop1_bound, spectral_abs
from .certificates import (
    certificate_grid, critical_distance, decide_certified, iid_instability_end, parity_structure, true_critical_curve,
    two_reception_bound,
)
from .stability import classify_growth, decide_estimator, refine_long_horizon

__all__ = [
    "critical_curves_step", "lmi_checks_step", "iid_line_step", "exact_moments_step", "stability_map_step",
    "sample_paths_step", "expectations_step", "load_moments", "tight_variants_step", "asymptote_holdout_step",
]


def _require_decisions(step: str, n_decided: int, n_total: int, statuses) -> None:
    """Stop a step none of whose LMI questions a certificate decided (a capped or failing solver).

    Parameters
    ----------
    step : str
        The step's name, for the message.
    n_decided, n_total : int
        LMI questions decided (feasible or infeasible, certified) and asked.
    statuses : iterable of str
        The solver statuses met.

    Raises
    ------
    ModelError
        When ``n_total > 0`` and ``n_decided == 0``.
    """
    if n_total > 0 and n_decided == 0:
        seen = ", ".join(sorted({str(x).split(":")[0] for x in statuses})) or "none"
        raise ModelError(f"markov step {step}: all {n_total} LMI decisions are undecided (solver statuses: {seen}); "
                         "no certificate decided any point, so the step has no result")


def _verdict(r):
    """The table's verdict: ``feasible`` only with ``rho(H(K)) < 1`` too (see :func:`.lmis.thm5_lower_bound`)."""
    return as_verdict(r).verdict


def _system(ex):
    return LinearSystem.from_config(ex)


def _q_grid(lam, n_points, margin):
    q_nec = 1.0 - 1.0 / lam ** 2
    return np.linspace(q_nec + margin, 1.0 - margin, n_points), q_nec


def _reference(name, ex, q):
    """Known critical failure rate where theory gives it (see module docstring)."""
    kind = ex.get("reference", "none")
    lam = spectral_abs(ex["A"])
    q = np.asarray(q, dtype=float)
    if kind == "nondegenerate":
        return np.where(lam ** 2 * (1 - q) < 1, 1.0, 0.0), "non-degenerate: MSS iff |lambda|^2(1-q)<1 [18], so p_c=1"
    if kind == "parity":
        return np.minimum(parity_bound_example2(lam, q), 1.0), "parity renewal condition (our derivation)"
    return np.full(q.shape, np.nan), ""


# ----------------------------------------------------------------------------- Theorem 5 curves
def critical_curves_step(params, inputs, outputs):
    """Proposition 1 (eq. 8) and Theorem 5 (eq. 12) curves p(q) for every example, plus the LMI benchmark.

    On each example's q grid (from the necessary bound 1 - 1/|lambda|^2 plus ``q_margin`` to
    1 - ``q_margin``): Proposition 1's bound, Theorem 5's certified bisection for its lower bound
    on p (up to ``p_uncapped_max`` when l_o = 2, else 1), and the closed-form reference curve.
    The benchmark times the parametrised LMI against one rebuilt for every solve.

    Parameters
    ----------
    params : dict
        The ``markov`` configuration's ``examples`` (``A``, ``C``, ``Q``, ``R``, ``Sigma0``, ``reference`` of each)
        and ``curves`` (``q_points``, ``q_margin``, ``bisection_tol``, ``p_uncapped_max``, ``benchmark_solves``).
    inputs : dict
        Only the step's code (no table is read).
    outputs : dict
        ``table`` (``results/markov/critical_curves.csv``) and ``benchmark``
        (``results/markov/lmi_benchmark.csv``).

    Returns
    -------
    dict
        ``{"table": DataFrame, "benchmark": DataFrame, "provenance": {"n_solves": int}}``: one row
        per example and q (bounds capped at 1 and uncapped, the bisection's bracket, statuses and
        evidence), and three timing rows per example.
    """
    cc = params["curves"]
    rows, bench = [], []
    for name, ex in params["examples"].items():
        A, C = np.asarray(ex["A"], float), np.asarray(ex["C"], float)
        lam = spectral_abs(A)
        l_o = observability_index(A, C)
        qs, q_nec = _q_grid(lam, cc["q_points"], cc["q_margin"])
        prop = prop1_bound(lam, qs, l_o)
        ref, ref_text = _reference(name, ex, qs)
        lmi = GilbertElliottLMI(A, C, l_o)
        p_max = cc["p_uncapped_max"] if l_o == 2 else 1.0
        t0 = time.perf_counter()
        for q, pp, pr in zip(qs, prop, ref):
            res = thm5_lower_bound(lmi, float(q), p_max, cc["bisection_tol"])
            rows.append({
                "example": name, "q": q, "q_necessary": q_nec, "necessary_ok": bool(lam ** 2 * (1 - q) < 1),
                "p_prop1": min(pp, 1.0), "p_prop1_uncapped": pp,
                "p_thm5": min(res["p_lower"], 1.0), "p_thm5_uncapped": res["p_lower"], "p_thm5_upper": res["p_upper"],
                "thm5_saturated": res["saturated"], "thm5_n_solves": res["n_solves"],
                "thm5_n_uncertified": res["n_uncertified"], "thm5_statuses": "|".join(res["statuses"]),
                "rho_H_at_lower": res["rho_at_lower"], "p_reference": pr, "reference": ref_text,
                "thm5_certified": res["certified"] or res["saturated"], "thm5_n_undecided": res["n_undecided"],
                "thm5_lower_evidence": res["lower_evidence"], "thm5_upper_evidence": res["upper_evidence"],
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
            rebuild_solve(A, C, float(p), float(qs[len(qs) // 2]), l_o)
        t_build = time.perf_counter() - t2
        bench += [
            {"example": name, "mode": "parametrised (compiled once, cp.Parameter)", "n_solves": nb, "seconds": t_param,
             "solves_per_second": nb / t_param},
            {"example": name, "mode": "rebuilt every solve", "n_solves": nb, "seconds": t_build,
             "solves_per_second": nb / t_build},
            {"example": name, "mode": "theorem-5 sweep (parametrised)", "n_solves": lmi.n_solves - nb,
             "seconds": elapsed, "solves_per_second": (lmi.n_solves - nb) / elapsed},
        ]
    n_solves = int(sum(r["thm5_n_solves"] for r in rows))
    _require_decisions("critical_curves", n_solves - int(sum(r["thm5_n_undecided"] for r in rows)), n_solves,
                       [x for r in rows for x in r["thm5_statuses"].split("|")])
    return {"table": pd.DataFrame(rows), "benchmark": pd.DataFrame(bench), "provenance": {"n_solves": n_solves}}


def lmi_checks_step(params, inputs, outputs):
    """Point checks of Theorem 2 (iv) and Theorem 5 that the paper states (Section 5).

    Parameters
    ----------
    params : dict
        The ``markov`` configuration's ``examples`` (``A``, ``C``, ``Q``, ``R``, ``Sigma0``, ``reference`` of each)
        and ``checks`` (``points``: name, example, p, q of each LMI solve; ``tight``: name, example,
        q of each tight bisection; ``tight_tol``).
    inputs : dict
        Only the step's code (no table is read).
    outputs : dict
        ``table`` (``results/markov/lmi_checks.csv``).

    Returns
    -------
    dict
        ``{"table": DataFrame}``: one row per point check and two per tight check (at the
        bisection's lower and upper ends), with the solve's status, verdict, evidence and margins.
    """
    ck = params["checks"]
    rows = []
    for item in ck["points"]:
        ex = params["examples"][item["example"]]
        A, C = np.asarray(ex["A"], float), np.asarray(ex["C"], float)
        lmi = GilbertElliottLMI(A, C)
        p = float(item["p"])
        r = lmi.solve(p, float(item["q"]))
        verdict = _verdict(r)
        rows.append({"check": item["name"], "example": item["example"], "p": p, "q": item["q"], "status": r.status,
                     "verdict": verdict, "evidence": r.evidence,
                     "margin": r.margin, "solver_feasible": r.solver_feasible, "certified": verdict != "undecided",
                     "rho_H": r.rho_H, "lyap_margin": r.lyap_margin})
    for item in ck["tight"]:
        ex = params["examples"][item["example"]]
        A, C = np.asarray(ex["A"], float), np.asarray(ex["C"], float)
        lmi = GilbertElliottLMI(A, C)
        res = thm5_lower_bound(lmi, float(item["q"]), 1.0, ck["tight_tol"])
        for label, p in (("tight_lower", res["p_lower"]), ("tight_upper", res["p_upper"])):
            r = lmi.solve(float(p), float(item["q"]))
            verdict = _verdict(r)
            rows.append({"check": f"{item['name']}_{label}", "example": item["example"], "p": p, "q": item["q"],
                         "status": r.status, "verdict": verdict, "evidence": r.evidence,
                         "margin": r.margin, "solver_feasible": r.solver_feasible,
                         "certified": verdict != "undecided", "rho_H": r.rho_H, "lyap_margin": r.lyap_margin})
    _require_decisions("lmi_checks", sum(r["certified"] for r in rows), len(rows), [r["status"] for r in rows])
    return {"table": pd.DataFrame(rows)}


def tight_variants_step(params, inputs, outputs):
    """The tight Theorem 5 bisections (eq. 12) repeated at every tolerance of ``checks.tight_tol_variants``.

    Table ``tight_variants.csv``: ``check, example, q, tol, p_lower, p_upper, certified, n_solves, n_undecided,
    statuses``; the claims on ``p_underline`` are re-judged across these tolerances.

    Parameters
    ----------
    params : dict
        The ``markov`` configuration's ``examples`` (``A``, ``C`` of each example) and ``checks``
        (``tight``: the checks' name, example and q; ``tight_tol_variants``: the tolerances).
    inputs : dict
        Only the step's code (no table is read).
    outputs : dict
        ``table`` (``results/markov/tight_variants.csv``).

    Returns
    -------
    dict
        ``{"table": DataFrame}``, one row per tight check and tolerance.
    """
    ck = params["checks"]
    rows = []
    for item in ck["tight"]:
        ex = params["examples"][item["example"]]
        lmi = GilbertElliottLMI(np.asarray(ex["A"], float), np.asarray(ex["C"], float))
        for tol in ck["tight_tol_variants"]:
            res = thm5_lower_bound(lmi, float(item["q"]), 1.0, float(tol))
            rows.append({"check": item["name"], "example": item["example"], "q": item["q"], "tol": float(tol),
                         "p_lower": res["p_lower"], "p_upper": res["p_upper"], "certified": res["certified"],
                         "n_solves": res["n_solves"], "n_undecided": res["n_undecided"],
                         "statuses": "|".join(res["statuses"])})
    _require_decisions("tight_variants", sum(r["n_solves"] - r["n_undecided"] for r in rows),
                       sum(r["n_solves"] for r in rows), [x for r in rows for x in r["statuses"].split("|")])
    return {"table": pd.DataFrame(rows)}


def iid_line_step(params, inputs, outputs):
    """The i.i.d. line p + q = 1 (Remark 4): Sinopoli's bounds on lambda_c and Theorem 5's crossing.

    Per example: the lower bound 1 - 1/|lambda|^2, Sinopoli's LMI upper bound (certified
    bisection, its infeasible end raised where a lower bound certifies divergence), the q at which
    Theorem 5's LMI becomes feasible on the line, and the reference lambda_c where the example has
    one; ``consistent`` checks the reference lies within the bounds (to ``tol``).

    Parameters
    ----------
    params : dict
        The ``markov`` configuration's ``examples`` (``A``, ``C``, ``Q``, ``R``, ``Sigma0``, ``reference`` of each)
        and ``iid`` (``tol``: the bisections' tolerance).
    inputs : dict
        Only the step's code (no table is read).
    outputs : dict
        ``table`` (``results/markov/iid_line.csv``).

    Returns
    -------
    dict
        ``{"table": DataFrame}``, one row per example.
    """
    from ...engines.certify import bisect_certified  # scipy.sparse: only the LMI steps need the engine

    tol = params["iid"]["tol"]
    rows, brackets = [], []
    for name, ex in params["examples"].items():
        A, C = np.asarray(ex["A"], float), np.asarray(ex["C"], float)
        lam = spectral_abs(A)
        lower = 1.0 - 1.0 / lam ** 2
        upper, _, sin_br = sinopoli_lmi_threshold(A, C, tol)
        # the LMI implies mean-square stability, so it is infeasible wherever a lower bound certifies divergence
        unstable_end, unstable_evidence = iid_instability_end(A, C, ex["Q"])
        infeasible_end = float(np.fmax(sin_br.infeasible_end, unstable_end))
        lmi = GilbertElliottLMI(A, C)
        # feasibility at (p, q) = (1 - q, q) is monotone in q: p falls while p_underline(q) rises
        res = bisect_certified(lambda q: as_verdict(lmi.solve(1.0 - q, q)), lower + 1e-6, 1.0 - 1e-6, tol=tol,
                               feasible_above=True)
        brackets += [sin_br, res]
        kind = ex.get("reference", "none")
        if kind == "nondegenerate":
            ref, text = lower, "non-degenerate: lambda_c = 1 - 1/|lambda|^2 (Mo & Sinopoli)"
        elif kind == "parity":
            ref, text = 1.0 - 1.0 / lam ** 4, "parity argument: lambda_c = 1 - 1/|lambda|^4"
        else:
            ref, text = np.nan, ""
        rows.append({"example": name, "lambda_lower": lower, "lambda_lmi_upper": upper,
                     "lambda_lmi_upper_infeasible_end": sin_br.infeasible_end, "lambda_lmi_certified": sin_br.certified,
                     "lambda_lmi_infeasible_certified_end": infeasible_end,
                     "lambda_lmi_infeasible_evidence": (unstable_evidence if not unstable_end < infeasible_end
                                                        else "Sinopoli LMI bisection (certified infeasible end)"),
                     "lambda_lmi_bracket_width": upper - infeasible_end,
                     "q_thm5_on_iid_line": res.feasible_end, "q_thm5_infeasible_end": res.infeasible_end,
                     "q_thm5_certified": res.certified, "lambda_c_reference": ref, "reference": text,
                     "consistent": bool(lower - tol <= ref <= min(upper, res.feasible_end) + tol)})
    verdicts = [v for br in brackets for v in br.verdicts.values()]
    _require_decisions("iid_line", sum(v.verdict != "undecided" for v in verdicts), len(verdicts),
                       [v.solver_status for v in verdicts])
    return {"table": pd.DataFrame(rows)}


def exact_moments_step(params, inputs, outputs):
    """Exact E||P_k|| polynomials over all channel paths, k <= depth + 1.

    See :func:`.exact.exact_moments`; computed on the decoupled blocks where :func:`.exact.find_split`
    finds a split (Example II).

    Parameters
    ----------
    params : dict
        The ``markov`` configuration's ``examples`` (``A``, ``C``, ``Q``, ``R``, ``Sigma0``, ``reference`` of each)
        and ``exact`` (``depth``: the number of tree levels).
    inputs : dict
        Only the step's code (no table is read).
    outputs : dict
        ``table`` (``results/markov/exact_moments.csv``).

    Returns
    -------
    dict
        ``{"table": DataFrame}``: columns ``example, depth, n11, n10, n01, n00, sum_norm,
        sum_trace`` (the rows of :class:`.exact.ExactMoments`), with a ``depth = 0`` row holding
        ``||P_1||`` and ``tr P_1``; read back by :func:`load_moments`.
    """
    frames = []
    for name, ex in params["examples"].items():
        em = exact_moments_auto(_system(ex), np.asarray(ex["Sigma0"], float), params["exact"]["depth"])
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


def load_moments(table: pd.DataFrame, example: str) -> ExactMoments:
    """Rebuild :class:`~netrepro.papers.markov.exact.ExactMoments` from ``exact_moments.csv``.

    Parameters
    ----------
    table : pandas.DataFrame
        The table of :func:`exact_moments_step`.
    example : str
        The example whose rows are read.

    Returns
    -------
    ExactMoments
        The polynomials for depths 1..max depth, and ``||P_1||``, ``tr P_1`` from the ``depth = 0`` row.
    """
    sub = table[table["example"] == example]
    head = sub[sub["depth"] == 0].iloc[0]
    cols = ["n11", "n10", "n01", "n00", "sum_norm", "sum_trace"]
    coef = [sub[sub["depth"] == d][cols].to_numpy(float) for d in range(1, int(sub["depth"].max()) + 1)]
    return ExactMoments(coef, float(head["sum_norm"]), float(head["sum_trace"]))


def _estimator_map(em, ex, e_idx, P, Qg, mp, z):
    """The estimator cross-check of the map (exact extrapolation, then the long-horizon estimator)."""
    opts = mp["refine"]
    means = em.mean(P, Qg, "norm")
    rate, last, verdict = classify_growth(means, mp["bounded_tol"], mp["unbounded_tol"])
    exact_method = f"exact E||P_k|| over all 2^{em.depth - 1} channel paths (k<={em.depth + 1}), extrapolated growth"
    f = pd.DataFrame({"verdict_estimator": verdict.ravel(), "growth_rate_exact": rate.ravel(),
                      "growth_rate_last": last.ravel(), "mean_norm_last": means[..., -1].ravel(),
                      "growth_rate_long": np.nan, "rel_halfwidth_long": np.nan, "method_estimator": exact_method})
    todo = np.flatnonzero(f.verdict_estimator.to_numpy() == "undecided")
    if opts["enabled"] and len(todo):
        rng = np.random.default_rng([opts["seed"], e_idx])
        r_long, rel, v_long = refine_long_horizon(_system(ex), np.asarray(ex["Sigma0"], float),
                                                  P.ravel()[todo], Qg.ravel()[todo], opts, rng, z)
        f.loc[todo, "growth_rate_long"] = r_long
        f.loc[todo, "rel_halfwidth_long"] = rel
        decided = todo[v_long != "undecided"]
        f.loc[decided, "verdict_estimator"] = v_long[v_long != "undecided"]
        f.loc[decided, "method_estimator"] = (f"conditional estimator of E tr P_k, k<={opts['horizon'] + 1}, "
                                              f"{opts['n_paths']} paths, 95% half-width < {opts['rel_tol']:g} of the mean")
        f.loc[todo[v_long == "undecided"], "method_estimator"] = "undecided: exact horizon too short, estimator not trusted"
    return f, means


def _sensitivity_rows(name, P, Qg, facts, cert_verdict, far, means, est, mp, system, Sigma0):
    """Re-decide the map across the configured range of every threshold, one at a time."""
    cc, sens = mp["certify"], mp["sensitivity"]
    rows = []
    base_est = est.verdict_estimator.to_numpy().reshape(P.shape)
    long_rate = est.growth_rate_long.to_numpy().reshape(P.shape)
    long_rel = est.rel_halfwidth_long.fillna(np.inf).to_numpy().reshape(P.shape)
    est_args = {"bounded_tol": mp["bounded_tol"], "unbounded_tol": mp["unbounded_tol"],
                "rel_tol": mp["refine"]["rel_tol"], "refine_bounded_tol": mp["refine"]["bounded_tol"],
                "refine_unbounded_tol": mp["refine"]["unbounded_tol"]}

    def row(threshold, value, default, applies, verdict, base):
        rows.append({
            "example": name, "threshold": threshold, "value": value, "is_default": bool(default),
            "applies_to": applies, "n_bounded": int((verdict == "bounded").sum()),
            "n_unbounded": int((verdict == "unbounded").sum()), "n_undecided": int((verdict == "undecided").sum()),
            "n_undecided_far": int(((verdict == "undecided") & far).sum()),
            "n_changed": int((verdict != base).sum()),
            "n_contradict_certified": int((((verdict == "bounded") & (cert_verdict == "unbounded"))
                                          | ((verdict == "unbounded") & (cert_verdict == "bounded"))).sum()),
        })

    for v in sens["rho_margin"]:
        verdict, _ = decide_certified(facts, P, v, cc["growth_margin"])
        row("certify.rho_margin", v, v == cc["rho_margin"], "certified map", verdict, cert_verdict)
    for v in sens["growth_margin"]:
        verdict, _ = decide_certified(facts, P, cc["rho_margin"], v)
        row("certify.growth_margin", v, v == cc["growth_margin"], "certified map", verdict, cert_verdict)
    two_rec = system.A.shape[0] == 2 * system.C.shape[0]
    for v in sens["n_gaps"]:
        alt = dict(facts)
        if two_rec:
            alt["upper"] = two_reception_bound(system, Sigma0, P, Qg, int(v))
        verdict, _ = decide_certified(alt, P, cc["rho_margin"], cc["growth_margin"])
        row("certify.n_gaps", v, v == cc["n_gaps"], "certified map", verdict, cert_verdict)
    for key, cfg_key in (("bounded_tol", "bounded_tol"), ("unbounded_tol", "unbounded_tol"),
                         ("rel_tol", "refine.rel_tol"), ("refine_bounded_tol", "refine.bounded_tol"),
                         ("refine_unbounded_tol", "refine.unbounded_tol")):
        for v in sens[key]:
            verdict = decide_estimator(means, long_rate, long_rel, **dict(est_args, **{key: v}))
            row(cfg_key, v, v == est_args[key], "estimator cross-check", verdict, base_est)
    return rows


def stability_map_step(params, inputs, outputs):
    """Stability map of E||P_k|| on a (p, q) grid, decided by certificates only (:mod:`.certificates`).

    ``verdict`` / ``bounded`` / ``method``: Theorem 1 with a computed gain or the two-reception upper
    bound certify bounded; the loss-run or parity lower bounds certify unbounded; nothing else decides.
    ``dist_critical`` is the distance to the true critical curve (every point at ``>= far`` must be decided).
    The former estimator map (exact extrapolation, long-horizon conditional estimator) is kept as a
    cross-check (``verdict_estimator``); ``map_sensitivity.csv`` re-decides both across their thresholds.

    Parameters
    ----------
    params : dict
        The ``markov`` configuration's ``examples`` (``A``, ``C``, ``Q``, ``R``, ``Sigma0``, ``reference`` of each),
        ``map`` (the grid ``p_min, p_max, p_points, q_min, q_max, q_points``, ``far``, ``certify``
        margins, the estimator map's settings and ``sensitivity``) and ``estimator`` (``interval_z``).
    inputs : dict
        ``moments`` (``results/markov/exact_moments.csv``).
    outputs : dict
        ``table`` (``results/markov/stability_map.csv``) and ``sensitivity``
        (``results/markov/map_sensitivity.csv``).

    Returns
    -------
    dict
        ``{"table": DataFrame, "sensitivity": DataFrame}``: one row per example and grid point,
        and the re-decisions across thresholds.
    """
    table = pd.read_csv(inputs["moments"])
    mp = params["map"]
    cc = mp["certify"]
    ps = np.linspace(mp["p_min"], mp["p_max"], mp["p_points"])
    qs = np.linspace(mp["q_min"], mp["q_max"], mp["q_points"])
    P, Qg = np.meshgrid(ps, qs, indexing="ij")
    frames, sens = [], []
    for e_idx, (name, ex) in enumerate(params["examples"].items()):
        system, Sigma0 = _system(ex), np.asarray(ex["Sigma0"], float)
        facts = certificate_grid(system, Sigma0, P, Qg, cc["n_gaps"])
        verdict, method = decide_certified(facts, P, cc["rho_margin"], cc["growth_margin"])
        curve_q, curve_p = true_critical_curve(ex.get("reference", "none"), spectral_abs(ex["A"]))
        dist = critical_distance(Qg, P, curve_q, curve_p)
        est, means = _estimator_map(load_moments(table, name), ex, e_idx, P, Qg, mp, params["estimator"]["interval_z"])
        growth = np.fmax(facts["loss_growth"], facts["parity_growth"])
        with np.errstate(divide="ignore"):
            p_thm1 = 1.0 / facts["rho1"]
        f = pd.DataFrame({"example": name, "p": P.ravel(), "q": Qg.ravel(), "verdict": verdict.ravel(),
                          "method": method.ravel(), "dist_critical": dist.ravel(), "p_thm1": p_thm1.ravel(),
                          "p_thm1_above_cap": p_thm1.ravel() > 1.0,
                          "upper_bound": facts["upper"].ravel(), "growth_rate": growth.ravel()})
        f = pd.concat([f, est], axis=1)
        f.insert(3, "bounded", f.verdict.map({"bounded": "True", "unbounded": "False"}).fillna(""))
        frames.append(f)
        sens += _sensitivity_rows(name, P, Qg, facts, verdict, dist >= mp["far"], means, est, mp, system, Sigma0)
    return {"table": pd.concat(frames, ignore_index=True), "sensitivity": pd.DataFrame(sens)}


def _estimator_check(system, S0, example, p, q, em, n, horizon, rng, z):
    """Plain sample mean and conditional estimator of E||P_k||: against the exact value at k = depth + 1,
    and against each other at the long horizon ``k = horizon + 1`` (where only the conditional one is trusted)."""
    exact = em.mean(p, q, "norm")
    k = len(exact)
    norms, arrivals = est.plain_mc(system, S0, p, q, n, max(horizon, k - 1), rng)
    rb = est.rb_mean_norm(system, S0, p, q, arrivals)
    plain, rbk = norms[:, k - 1], rb[:, k - 1]
    se_p, se_r = plain.std(ddof=1) / np.sqrt(n), rbk.std(ddof=1) / np.sqrt(n)
    kl = rb.shape[1]
    return {"example": example, "p": p, "q": q, "k": k, "exact_mean": exact[k - 1],
            "plain_mean": plain.mean(), "plain_ci_high": plain.mean() + z * se_p,
            "rb_mean": rbk.mean(), "rb_ci_low": rbk.mean() - z * se_r, "rb_ci_high": rbk.mean() + z * se_r,
            "plain_over_exact": plain.mean() / exact[k - 1], "rb_over_exact": rbk.mean() / exact[k - 1],
            "k_long": kl, "plain_mean_long": norms[:, kl - 1].mean(), "rb_mean_long": rb[:, kl - 1].mean(),
            "plain_over_rb_long": norms[:, kl - 1].mean() / rb[:, kl - 1].mean(), "n_paths": n}


def sample_paths_step(params, inputs, outputs):
    """Sample paths, Monte Carlo bands, plain and conditional means, exact means for Figs 3-6.

    Per figure case: the first path's ``||P_k||`` and ``gamma_k``, the 5/50/95% quantiles and the
    plain mean over ``n_paths`` paths, the conditional estimator (:func:`.estimators.rb_mean_norm`)
    on the first ``rb_paths`` paths up to ``rb_horizon``, and the exact mean where the tree reaches.
    Per estimator point: the plain and conditional estimators against the exact value and each other.

    Parameters
    ----------
    params : dict
        The ``markov`` configuration's ``examples`` (``A``, ``C``, ``Q``, ``R``, ``Sigma0``, ``reference`` of each),
        ``paths`` (``horizon``, ``n_paths``, ``rb_paths``, ``rb_horizon``, ``seed``, ``cases``:
        figure, example, p, q; ``estimator_points``: example, p, q) and ``estimator`` (``interval_z``).
    inputs : dict
        ``moments`` (``results/markov/exact_moments.csv``).
    outputs : dict
        ``table`` (``results/markov/sample_paths.csv``) and ``check`` (``results/markov/estimator_check.csv``).

    Returns
    -------
    dict
        ``{"table": DataFrame, "check": DataFrame}``: one row per case and k = 1..horizon + 1
        (NaN where a column does not reach), and one row per estimator point.
    """
    sp = params["paths"]
    table = pd.read_csv(inputs["moments"])
    rows, checks = [], []
    for case in sp["cases"]:
        ex = params["examples"][case["example"]]
        system = _system(ex)
        S0 = np.asarray(ex["Sigma0"], float)
        p, q = float(case["p"]), float(case["q"])
        rng = np.random.default_rng([sp["seed"], int(case["figure"].replace("fig", ""))])
        norms, arrivals = est.plain_mc(system, S0, p, q, sp["n_paths"], sp["horizon"], rng)
        rb_arr = arrivals[: sp["rb_paths"], : sp["rb_horizon"]]
        rb = est.rb_mean_norm(system, S0, p, q, rb_arr)
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
                                       float(point["p"]), float(point["q"]), em, sp["rb_paths"], sp["rb_horizon"], rng,
                                       params["estimator"]["interval_z"]))
    return {"table": pd.DataFrame(rows), "check": pd.DataFrame(checks)}


def _expectation_rows(case, exact, k_max, cond, asym):
    """Rows of one figure setting: exact, then the first trustworthy method beyond the exact range."""
    K = len(exact)
    rows = [{"k": k, "mean_norm": exact[k - 1], "lo": exact[k - 1], "hi": exact[k - 1], "method": "exact"}
            for k in range(1, min(K, k_max) + 1)]
    ks = np.arange(K + 1, k_max + 1)
    if cond is not None:
        mean, half = cond
        for k in ks:
            rows.append({"k": k, "mean_norm": mean[k - 1], "lo": mean[k - 1] - half[k - 1],
                         "hi": mean[k - 1] + half[k - 1], "method": "estimate_conditional"})
    elif asym is not None:
        mean, lo, hi, limit = asym
        for i, k in enumerate(ks):
            rows.append({"k": k, "mean_norm": mean[i], "lo": lo[i], "hi": hi[i], "method": "asymptote",
                         "limit": limit[0], "limit_lo": limit[1], "limit_hi": limit[2]})
    else:
        rows += [{"k": k, "mean_norm": np.nan, "lo": np.nan, "hi": np.nan, "method": "not_trustworthy"} for k in ks]
    return [{"example": case["example"], "p": float(case["p"]), "q": float(case["q"]), **r} for r in rows]


def expectations_step(params, inputs, outputs):
    """``E||P_k||`` for Figs 3-6 at every ``k`` of the horizon, each value exact, validated or derived.

    Exact range: ``k <= depth + 1`` from ``exact_moments.csv``, or ``k <= split_depth + 1`` where
    :func:`.exact.find_split` splits the system into decoupled blocks (Example II; the exact
    computation on the blocks is ~4 times cheaper). Beyond it: the conditional estimator
    (:func:`.expectations.conditional_estimate`) if the system has no parity lock (its only heavy
    tail, the trailing loss run, is integrated exactly), its ``|z|`` against every exact value is
    at most ``z_max`` and its relative 95% half-width stays below ``rel_tol``; otherwise, for a
    parity-locked system (whose heavy tail the derived rate describes), the asymptote with the
    derived rate (:func:`.expectations.two_step_rate`) if its backtest from
    ``backtest_k0`` brackets the exact values with monotone ratios (:func:`.expectations.asymptote_backtest`);
    otherwise ``not_trustworthy``. The decisions and their numbers go to the provenance.

    Parameters
    ----------
    params : dict
        The ``markov`` configuration's ``examples`` (``A``, ``C``, ``Q``, ``R``, ``Sigma0``, ``reference`` of each),
        ``paths`` (``horizon``, ``cases``), ``expectations`` (``split_depth``, ``n_paths``, ``z_max``,
        ``rel_tol``, ``backtest_k0``, ``seed``) and ``estimator`` (``interval_z``, ``deterministic_rtol``).
    inputs : dict
        ``moments`` (``results/markov/exact_moments.csv``).
    outputs : dict
        ``table`` (``results/markov/expectations.csv``).

    Returns
    -------
    dict
        ``{"table": DataFrame, "provenance": dict}``: columns ``example, p, q, k, mean_norm, lo, hi,
        method, limit, limit_lo, limit_hi``; the provenance holds each figure's decisions.
    """
    sp, xc, es = params["paths"], params["expectations"], params["estimator"]
    table = pd.read_csv(inputs["moments"])
    k_max = sp["horizon"] + 1
    rows, prov, split_moments = [], {}, {}
    for j, case in enumerate(sp["cases"]):
        ex = params["examples"][case["example"]]
        system, S0 = _system(ex), np.asarray(ex["Sigma0"], float)
        p, q = float(case["p"]), float(case["q"])
        name = case["example"]
        if name not in split_moments and find_split(system, S0) is not None:
            split_moments[name] = exact_moments_auto(system, S0, xc["split_depth"])
        em = split_moments.get(name) or load_moments(table, name)
        exact = em.mean(p, q, "norm")[:k_max]
        rate2 = xp.two_step_rate(system.A, system.C, system.Q, p, q)
        info = {"k_exact": len(exact), "rate2": rate2, "block_split": name in split_moments}
        cond = asym = None
        if len(exact) < k_max:
            parity = parity_structure(system.A, system.C, system.Q) is not None
            info["parity_lock"] = parity
            if not parity:
                rng = np.random.default_rng([xc["seed"], j])
                mean, half = xp.conditional_estimate(system, S0, p, q, xc["n_paths"], k_max - 1, rng, es["interval_z"])
                zmax, z_ok = xp.conditional_validation(mean, half, exact, xc["z_max"], es["interval_z"],
                                                       es["deterministic_rtol"])
                rel = float(np.max(half / mean))
                info.update(cond_max_abs_z=zmax, cond_max_rel_halfwidth=rel)
                if z_ok and rel < xc["rel_tol"]:
                    cond = (mean, half)
            if cond is None:
                inside, err, mono = xp.asymptote_backtest(exact, rate2, xc["backtest_k0"])
                a_mean, a_lo, a_hi = xp.asymptote_extrapolation(exact, k_max, rate2)
                width = float(np.max((a_hi - a_lo) / (2 * a_mean)))
                info.update(backtest_inside=inside, backtest_max_rel_err=err, backtest_monotone=mono,
                            asym_max_rel_halfwidth=width)
                if parity and inside and mono:
                    limit = xp.asymptote_limit(exact, rate2)
                    info.update(asym_limit=limit[0], asym_limit_lo=limit[1], asym_limit_hi=limit[2])
                    asym = (a_mean, a_lo, a_hi, limit)
        rows += _expectation_rows(case, exact, k_max, cond, asym)
        prov[case["figure"]] = info
    cols = ["example", "p", "q", "k", "mean_norm", "lo", "hi", "method", "limit", "limit_lo", "limit_hi"]
    return {"table": pd.DataFrame(rows, columns=cols), "provenance": prov}


def asymptote_holdout_step(params, inputs, outputs):
    """Out-of-sample test of the asymptote of ``expectations.csv``: exact ``E||P_k||`` beyond the range it saw.

    For each figure setting whose values beyond the exact range ``k <= K`` come from the asymptote
    (:func:`.expectations.asymptote_extrapolation`, built from the exact values at ``k <= K`` only), the exact
    tree is grown by ``expectations.holdout`` levels (:func:`.exact.exact_moments_auto`, depth ``K - 1 +
    holdout``) and the exact ``E||P_k||`` at ``k = K+1 .. K+holdout`` is held against the asymptote's bracket
    ``[lo, hi]`` of the table (slack ``1e-12`` relative, the rounding of both sums). The bracket claims to hold
    every later value; a value outside refutes it.

    Parameters
    ----------
    params : dict
        The ``markov`` configuration's ``examples``, ``paths`` (``cases``: figure, example, p, q) and
        ``expectations`` (``holdout``: the number of held-out steps).
    inputs : dict
        ``expectations`` (``results/markov/expectations.csv``).
    outputs : dict
        ``table`` (``results/markov/asymptote_holdout.csv``).

    Returns
    -------
    dict
        ``{"table": DataFrame, "provenance": dict}``: one row per held-out ``(figure, k)`` with columns
        ``figure, example, p, q, k, exact_mean, asym_mean, asym_lo, asym_hi, inside``; the provenance gives,
        per example, the depth and the largest relative difference of the deeper tree from the table's exact
        values on the common range (the two computations must agree).
    """
    hold = int(params["expectations"]["holdout"])
    table = pd.read_csv(inputs["expectations"])
    rows, prov, deep = [], {}, {}
    for case in params["paths"]["cases"]:
        name, p, q = case["example"], float(case["p"]), float(case["q"])
        sub = table[(table.example == name) & np.isclose(table.p, p, rtol=0, atol=1e-12)
                    & np.isclose(table.q, q, rtol=0, atol=1e-12)].sort_values("k")
        asym = sub[sub.method == "asymptote"].set_index("k")
        if asym.empty:
            continue
        exact_seen = sub[sub.method == "exact"].mean_norm.to_numpy(float)
        K = len(exact_seen)
        depth = K - 1 + hold
        if (name, depth) not in deep:
            ex = params["examples"][name]
            deep[(name, depth)] = exact_moments_auto(_system(ex), np.asarray(ex["Sigma0"], float), depth)
        exact = deep[(name, depth)].mean(p, q, "norm")
        prov[case["figure"]] = {"depth": depth, "k_seen": K, "max_rel_diff_seen": float(
            np.max(np.abs(exact[:K] / exact_seen - 1.0)))}
        for k in range(K + 1, K + hold + 1):
            if k not in asym.index:
                continue
            a = asym.loc[k]
            value = float(exact[k - 1])
            rows.append({"figure": case["figure"], "example": name, "p": p, "q": q, "k": k, "exact_mean": value,
                         "asym_mean": float(a.mean_norm), "asym_lo": float(a.lo), "asym_hi": float(a.hi),
                         "inside": bool(a.lo * (1 - 1e-12) <= value <= a.hi * (1 + 1e-12))})
    cols = ["figure", "example", "p", "q", "k", "exact_mean", "asym_mean", "asym_lo", "asym_hi", "inside"]
    return {"table": pd.DataFrame(rows, columns=cols), "provenance": prov}
