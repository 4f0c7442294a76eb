"""Figures of the `gainsched` paper: plotting only, from the result tables."""

from __future__ import annotations

import numpy as np

from ...io import read_table

__all__ = ["figure_errors", "figure_mse", "figure_sensitivity"]

_COLORS = {"paper": "C3", "theorem3": "C0", "theorem3_S21I": "C9", "fixed_gain": "C1", "performance": "C2",
           "performance_fixed": "C8", "tuned_fixed": "C4", "tuned_scheduled": "C5", "zero": "k",
           "performance_tied": "C8", "tuned_exact": "C6"}


def figure_errors(params, inputs, outputs):
    """Figs 1-2: e_i(k) under Algorithm 1: one sample path (as the paper), and the Monte Carlo mean with a band
    for the configured x0 and for x(0) ~ N(0, I); cut at ``k_max`` where the errors have decayed."""
    from ...plotting import new_figure, save_figure

    comp = int(params["component"])
    kmax = int(params.get("k_max", 10 ** 9))
    errors = read_table(inputs["errors"])
    errors = errors[errors["k"] <= kmax]
    paths = read_table(inputs["paths"])
    paths = paths[paths["k"] <= kmax]
    if "initial_state" not in errors:
        errors = errors.assign(initial_state="fixed_x0")
    show = params["designs"]
    fig, (ax1, ax2, ax3) = new_figure(1, 3, figsize=(15, 4.0), sharey=False)
    for d in show:
        pth = paths[paths["design"] == d]
        ax1.plot(pth["k"], pth[f"e{comp}"], marker=".", ms=3, lw=1, color=_COLORS.get(d), label=d)
        for ax, start in ((ax2, "fixed_x0"), (ax3, "gaussian")):
            er = errors[(errors["design"] == d) & (errors["initial_state"] == start)]
            if er.empty:
                continue
            ax.plot(er["k"], er[f"e{comp}_mean"], lw=1.5, color=_COLORS.get(d), label=f"{d} mean")
            ax.fill_between(er["k"], er[f"e{comp}_lo"], er[f"e{comp}_hi"], color=_COLORS.get(d), alpha=0.15)
    ax1.set(xlabel="k", ylabel=f"$e_{comp}(k)$", title="one sample path, configured $x_0$")
    ax2.set(xlabel="k", ylabel=f"$e_{comp}(k)$", title=f"configured $x_0$: mean, central {params['band']:.0%} band")
    ax3.set(xlabel="k", ylabel=f"$e_{comp}(k)$", title=f"$x(0)\\sim N(0, I)$: mean, central {params['band']:.0%} band")
    ax1.legend(fontsize=8)
    ax3.legend(fontsize=8)
    save_figure(fig, outputs["figure"])
    return {}


def figure_mse(params, inputs, outputs):
    """Fig S1: exact E||e(k)||^2 per design (linear f, log scale) and sum_k E||e||^2, exact and Monte Carlo (sine f)."""
    from ...plotting import new_figure, save_figure

    per_k = read_table(inputs["exact_mse"])
    exact = read_table(inputs["exact"])
    summary = read_table(inputs["summary"])
    f_show, start = params.get("nonlinearity", "mid"), params.get("initial_state", "gaussian")
    fig, (ax1, ax2) = new_figure(1, 2, figsize=(12, 4.4), layout="constrained")
    sel = per_k[(per_k["nonlinearity"] == f_show) & (per_k["initial_state"] == start)]
    kmax = int(params.get("k_max", sel["k"].max()))
    for d, er in sel.groupby("design", sort=False):
        er = er[er["k"] <= kmax]
        ax1.semilogy(er["k"], er["mse"], color=_COLORS.get(d), label=d, lw=1.2)
    ax1.set(xlabel="k", ylabel=r"$E\|e(k)\|^2$ (exact)",
            title=f"exact second moments, f = {f_show}, x(0) {'~ N(0, I)' if start == 'gaussian' else '= x0'}")
    ax1.legend(fontsize=7)
    designs = list(dict.fromkeys(exact["design"]))
    y = np.arange(len(designs))
    for off, st, lab in ((-0.2, "x0", "configured $x_0$"), (0.2, "gaussian", r"$x_0\sim N(0, I)$")):
        sub = exact[exact["initial_state"] == st].pivot(index="design", columns="nonlinearity", values="sum_mse")
        sub = sub.loc[designs]
        lo = sub[["F1", "F2", "mid"]].min(axis=1)
        hi = sub[["F1", "F2", "mid"]].max(axis=1)
        ax2.barh(y + off, sub["mid"], height=0.4, label=f"exact, f = mid, {lab}",
                 xerr=np.vstack([sub["mid"] - lo, hi - sub["mid"]]), error_kw={"lw": 0.8, "capsize": 2})
    mc = summary[summary["initial_state"] == "gaussian"].set_index("design").reindex(designs)
    if "sum_mse_se" in mc:
        ax2.errorbar(mc["sum_mse"], y + 0.2, xerr=2 * mc["sum_mse_se"], fmt="k.", ms=4, lw=0.8,
                     label=r"Monte Carlo, sine f, $x_0\sim N(0, I)$ ($\pm$2 s.e.)")
    ax2.set_yticks(y, designs)
    ax2.invert_yaxis()
    ax2.set(xlabel=r"$\sum_{k=0}^{K} E\|e(k)\|^2$ (whiskers: range over f in {F1, F2, mid})")
    ax2.legend(fontsize=7)
    save_figure(fig, outputs["figure"])
    return {}


def figure_sensitivity(params, inputs, outputs):
    """Fig S2: certified feasibility against sigma^2 per design, with the certified brackets of the limits."""
    from ...plotting import new_figure, save_figure

    sens = read_table(inputs["sensitivity"])
    limits = read_table(inputs["limits"]).set_index("design")
    fig, (ax, ax2) = new_figure(1, 2, figsize=(11, 4.2), layout="constrained")
    styles = {"scheduled": ("C0", "o"), "fixed_gain": ("C1", "s"), "zero": ("k", "^"), "plant": ("0.4", "D")}
    fill = {"feasible": "full", "undecided": "none", "infeasible": "none"}
    for d, (col, mk) in styles.items():
        g = sens[(sens["variant"] == d) & (sens["kind"] == "grid")]
        if g.empty:
            continue
        ax.plot(g["sigma2"], g["margin"].clip(lower=-0.1), "-", color=col, lw=0.8, alpha=0.6)
        for verdict, sub in g.groupby("verdict"):
            ax.plot(sub["sigma2"], sub["margin"].clip(lower=-0.1), ls="none", marker="x" if verdict == "infeasible"
                    else mk, fillstyle=fill.get(verdict, "none"), color=col, label=f"{d}: {verdict}")
    ax.axhline(0, color="k", lw=0.6)
    ax.axvline(params["sigma2"], color="C3", lw=1, label=r"reconstructed $\sigma^2$")
    ax.set(xlabel=r"$\sigma^2$", ylabel="solver margin t (capped; information only)",
           title="our verdict per point (filled feasible, open undecided, x infeasible)")
    ax.legend(fontsize=6, ncol=2)
    names = [d for d in styles if d in limits.index]
    y = np.arange(len(names))
    for yi, d in zip(y, names):
        lo, hi = limits.loc[d, "sigma2_lo"], limits.loc[d, "sigma2_hi"]
        col = styles[d][0]
        ax2.plot([lo, hi], [yi, yi], "-", color=col, lw=4, alpha=0.4)
        ax2.plot([lo], [yi], "o", color=col)
        ax2.plot([hi], [yi], "x", color=col, ms=8)
        ax2.annotate(f"[{lo:.5g}, {hi:.5g}]", (lo, yi), textcoords="offset points", xytext=(-70, 6), fontsize=7)
    ax2.set_yticks(y, names)
    ax2.invert_yaxis()
    ax2.set(xlabel=r"$\sigma^2$", title=r"certified bracket of the largest $\sigma^2$")
    save_figure(fig, outputs["figure"])
    return {}
