"""Figures of the `gainsched` paper: plotting only, from the result tables."""

from __future__ import annotations

import numpy as np

from ...io import read_table

__all__ = ["figure_errors", "figure_mse", "figure_sensitivity"]

_COLORS = {"paper": "C3", "theorem3": "C0", "theorem3_S21I": "C9", "fixed_gain": "C1", "performance": "C2",
           "performance_fixed": "C8", "tuned_fixed": "C4", "tuned_scheduled": "C5", "trivial": "k"}


def figure_errors(params, inputs, outputs):
    """Figs 1-2: e_i(k) under Algorithm 1: one sample path (as the paper) and the Monte Carlo mean with a band."""
    from ...plotting import new_figure, save_figure

    comp = int(params["component"])
    errors = read_table(inputs["errors"])
    paths = read_table(inputs["paths"])
    show = params["designs"]
    fig, (ax1, ax2) = new_figure(1, 2, figsize=(10, 3.8), sharey=False)
    for d in show:
        pth = paths[paths["design"] == d]
        ax1.plot(pth["k"], pth[f"e{comp}"], marker=".", ms=3, lw=1, color=_COLORS.get(d), label=d)
        er = errors[errors["design"] == d]
        ax2.plot(er["k"], er[f"e{comp}_mean"], lw=1.5, color=_COLORS.get(d), label=f"{d} mean")
        ax2.fill_between(er["k"], er[f"e{comp}_lo"], er[f"e{comp}_hi"], color=_COLORS.get(d), alpha=0.15)
    ax1.set(xlabel="k", ylabel=f"$e_{comp}(k)$", title="one sample path")
    ax2.set(xlabel="k", ylabel=f"$e_{comp}(k)$", title=f"mean over runs, central {params['band']:.0%} band")
    ax1.legend(fontsize=8)
    ax2.legend(fontsize=8)
    save_figure(fig, outputs["figure"])
    return {}


def figure_mse(params, inputs, outputs):
    """Fig S1: E||e(k)||^2 per design (log scale) and sum_k E||e||^2 for fixed and Gaussian initial states."""
    from ...plotting import new_figure, save_figure

    errors = read_table(inputs["errors"])
    summary = read_table(inputs["summary"])
    fig, (ax1, ax2) = new_figure(1, 2, figsize=(12, 4.2), layout="constrained")
    for d, er in errors.groupby("design", sort=False):
        ax1.semilogy(er["k"], er["mse"], color=_COLORS.get(d), label=d, lw=1.2)
    ax1.set(xlabel="k", ylabel=r"$E\|e(k)\|^2$ (fixed $x_0$)")
    ax1.legend(fontsize=7)
    piv = summary.pivot(index="design", columns="initial_state", values="sum_mse")
    piv = piv.loc[[d for d in dict.fromkeys(summary["design"])]]
    y = np.arange(len(piv))
    ax2.barh(y - 0.2, piv["fixed_x0"], height=0.4, label="fixed $x_0$")
    ax2.barh(y + 0.2, piv["gaussian"], height=0.4, label=r"$x_0\sim N(0, I)$")
    ax2.set_yticks(y, piv.index)
    ax2.invert_yaxis()
    ax2.set(xlabel=r"$\sum_k E\|e(k)\|^2$")
    ax2.legend(fontsize=8)
    save_figure(fig, outputs["figure"])
    return {}


def figure_sensitivity(params, inputs, outputs):
    """Fig S2: Theorem 3 margin against sigma^2, scheduled and fixed gains, with the plant's MS-stability limit."""
    from ...plotting import new_figure, save_figure

    sens = read_table(inputs["sensitivity"])
    fig, ax = new_figure(figsize=(6.4, 4))
    for variant, mk in (("scheduled", "o-"), ("fixed", "x--")):
        g = sens[(sens["variant"] == variant) & (sens["kind"] == "grid")]
        ax.plot(g["sigma2"], g["margin"], mk, label=f"Theorem 3, {variant}")
    lim = sens[sens["kind"] == "sigma2_max"].set_index("variant")["sigma2"]
    for variant, ls, col in (("scheduled", ":", "C0"), ("fixed", "-.", "C1"), ("plant_ms_limit", "-", "0.3")):
        if variant in lim:
            ax.axvline(lim[variant], ls=ls, color=col, lw=1.2,
                       label=f"largest feasible $\\sigma^2$, {variant}: {lim[variant]:.3g}" if variant != "plant_ms_limit"
                       else f"plant MS-stability limit: {lim[variant]:.3g}")
    ax.axhline(0, color="k", lw=0.8)
    ax.axvline(params["sigma2"], color="C3", lw=1, label=r"reconstructed $\sigma^2$")
    ax.set(xlabel=r"$\sigma^2$", ylabel="LMI margin t (capped)")
    ax.legend(fontsize=8)
    save_figure(fig, outputs["figure"])
    return {}
