"""Figures of the `gainsched` paper: plotting only, from the result tables."""

from __future__ import annotations

import numpy as np

from ...pipeline.io import read_table
from ...figures.plotting import COLOURS, OKABE_ITO

__all__ = ["figure_errors", "figure_mse", "figure_sensitivity"]

# each design: an Okabe-Ito colour and a line style (designs of close colours differ in line style;
# a design's `_flipped` variant, H -> -H, is drawn in its colour with its flipped line style)
_O = OKABE_ITO
_STYLES = {"paper": (COLOURS["paper"], "-"), "theorem3": (_O["blue"], "-"), "theorem3_S21I": (_O["sky_blue"], "-."),
           "fixed_gain": (_O["orange"], "-."), "performance": (_O["bluish_green"], "-."),
           "performance_fixed": (_O["bluish_green"], ":"), "tuned_fixed": (_O["reddish_purple"], ":"),
           "tuned_scheduled": (_O["yellow"], "-"), "zero": (_O["black"], "-"),
           "performance_tied": (_O["bluish_green"], ":"), "tuned_exact": (_O["black"], "--")}
_COLORS = {d: c for d, (c, _) in _STYLES.items()}
_LINES = {d: ls for d, (_, ls) in _STYLES.items()}
_FLIPPED = {"-": "--", "-.": ":", ":": "-."}


def figure_errors(params, inputs, outputs):
    """Figs 1-2: e_i(k) under Algorithm 1: one sample path (as the paper), the Monte Carlo mean with a band
    for the configured x0, and the Monte Carlo RMS error sqrt(E e_i(k)^2) for x(0) ~ N(0, I) (whose mean
    error is zero by symmetry); cut at ``k_max`` where the errors have decayed."""
    from ...figures.plotting import new_figure, save_figure

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
        ax1.plot(pth["k"], pth[f"e{comp}"], marker=".", ms=3, lw=1, color=_COLORS.get(d), ls=_LINES.get(d, "-"),
                 label=d)
        er = errors[(errors["design"] == d) & (errors["initial_state"] == "fixed_x0")]
        if not er.empty:
            ax2.plot(er["k"], er[f"e{comp}_mean"], lw=1.5, color=_COLORS.get(d), ls=_LINES.get(d, "-"),
                     label=f"{d} mean")
            ax2.fill_between(er["k"], er[f"e{comp}_lo"], er[f"e{comp}_hi"], color=_COLORS.get(d), alpha=0.15)
        # x(0) ~ N(0, I): the mean error is zero for every design by symmetry; the RMS error is what differs
        er = errors[(errors["design"] == d) & (errors["initial_state"] == "gaussian")]
        if not er.empty:
            ax3.plot(er["k"], er[f"e{comp}_rms"], lw=1.5, color=_COLORS.get(d), ls=_LINES.get(d, "-"), label=d)
    ax1.set(xlabel="k", ylabel=f"$e_{comp}(k)$", title="one sample path, configured $x_0$")
    ax2.set(xlabel="k", ylabel=f"$e_{comp}(k)$", title=f"configured $x_0$: mean, central {params['band']:.0%} band")
    ax3.set(xlabel="k", ylabel=f"$\\sqrt{{E\\,e_{comp}(k)^2}}$",
            title="$x(0)\\sim N(0, I)$: RMS error (the mean is 0 by symmetry)")
    ax1.legend(fontsize=8)
    ax3.legend(fontsize=8)
    save_figure(fig, outputs["figure"])
    return {}


def figure_mse(params, inputs, outputs):
    """Fig S1: exact E||e(k)||^2 per design (linear f, log scale) and sum_k E||e||^2, exact and Monte Carlo (sine f)."""
    from ...figures.plotting import new_figure, save_figure

    per_k = read_table(inputs["exact_mse"])
    exact = read_table(inputs["exact"])
    summary = read_table(inputs["summary"])
    f_show, start = params.get("nonlinearity", "mid"), params.get("initial_state", "gaussian")
    fig, (ax1, ax2) = new_figure(1, 2, figsize=(12, 4.4), layout="constrained")
    sel = per_k[(per_k["nonlinearity"] == f_show) & (per_k["initial_state"] == start)]
    kmax = int(params.get("k_max", sel["k"].max()))
    for d, er in sel.groupby("design", sort=False):
        er = er[er["k"] <= kmax]
        base = d.removesuffix("_flipped")  # the same filter with H -> -H: its design's colour, another line style
        ls = _LINES.get(base, "-")
        ax1.semilogy(er["k"], er["mse"], color=_COLORS.get(base), ls=_FLIPPED.get(ls, "--") if base != d else ls,
                     label=d, lw=1.2)
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
    """Fig S2: certified feasibility against sigma^2 per design, with the certified brackets of the limits.

    Left: the solver margin per grid point (information only; points not solved because the
    class's necessary condition fails are drawn at the clip level -0.1). Right: the certified
    brackets, sufficient (LMI) and necessary (worst linear gain of the class) ends, for the
    paper's class (3) and for componentwise sectors.
    """
    from ...figures.plotting import new_figure, save_figure

    sens = read_table(inputs["sensitivity"])
    limits = read_table(inputs["limits"]).set_index("design")
    fig, (ax, ax2) = new_figure(1, 2, figsize=(12, 4.4), layout="constrained")
    styles = {"scheduled": (_O["blue"], "o"), "fixed_gain": (_O["orange"], "s"), "zero": (_O["black"], "^"),
              "printed_gains": (COLOURS["paper"], "v"), "plant": ("0.4", "D"), "plant_necessary": ("0.4", "P"),
              "plant_componentwise": (_O["sky_blue"], "d"), "plant_componentwise_necessary": (_O["sky_blue"], "X")}
    fill = {"feasible": "full", "undecided": "none", "infeasible": "none"}
    for d, (col, mk) in styles.items():
        g = sens[(sens["variant"] == d) & (sens["kind"] == "grid")].sort_values("sigma2")
        if g.empty:
            continue
        margin = g["margin"].clip(lower=-0.1).fillna(-0.1)
        ax.plot(g["sigma2"], margin, "-", color=col, lw=0.8, alpha=0.6)
        for verdict, idx in g.groupby("verdict").groups.items():
            ax.plot(g.loc[idx, "sigma2"], margin.loc[idx], ls="none", marker="x" if verdict == "infeasible" else mk,
                    fillstyle=fill.get(verdict, "none"), color=col, label=f"{d}: {verdict}")
    ax.axhline(0, color="k", lw=0.6)
    zoom = float(params.get("zoom_from", 0.0))
    below = sens[(sens["kind"] == "grid") & (sens["sigma2"] < zoom)]
    if zoom > 0 and not below.empty:  # the limit region; the points below are summarised in the title
        ax.set_xlim(zoom, float(sens["sigma2"].max()) + 0.05)
        n_ok = int((below["verdict"] == "feasible").sum())
        where = f"$\\sigma^2$ < {zoom:g}: {n_ok} of {len(below)} grid points feasible (incl. the reconstructed {params['sigma2']:g})"
    else:
        ax.axvline(params["sigma2"], color=COLOURS["paper"], lw=1, label=r"reconstructed $\sigma^2$")
        where = "filled feasible, open undecided, x infeasible"
    ax.set(xlabel=r"$\sigma^2$", ylabel="solver margin t (information only)",
           title=f"verdict per grid point (filled feasible, x infeasible)\n{where}")
    ax.legend(fontsize=6, ncol=2)
    names = [d for d in styles if d in limits.index]
    y = np.arange(len(names))
    for yi, d in zip(y, names):
        lo, hi = limits.loc[d, "sigma2_lo"], limits.loc[d, "sigma2_hi"]
        col = styles[d][0]
        ax2.plot([lo, hi], [yi, yi], "-", color=col, lw=4, alpha=0.4)
        ax2.plot([lo], [yi], "o", color=col)
        ax2.plot([hi], [yi], "x", color=col, ms=8)
        ax2.annotate(f"[{lo:.6g}, {hi:.6g}]", (hi, yi), textcoords="offset points", xytext=(6, -3), fontsize=7)
    ax2.set_yticks(y, [f"{d} ({limits.loc[d, 'role']})" if "role" in limits else d for d in names])
    ax2.invert_yaxis()
    ends = limits.loc[names, ["sigma2_lo", "sigma2_hi"]].to_numpy(dtype=float)
    lo_all, hi_all = np.nanmin(ends), np.nanmax(ends)
    ax2.set_xlim(lo_all - 0.1 * (hi_all - lo_all), hi_all + 0.6 * (hi_all - lo_all))
    ax2.set(xlabel=r"$\sigma^2$", title=r"certified brackets of the largest $\sigma^2$ (o feasible end, x infeasible end)")
    save_figure(fig, outputs["figure"])
    return {}
