"""Figures of `intermittent` (plotting only: read tables, draw, save)."""

from __future__ import annotations

import numpy as np

from ...io import read_table
from ...plotting import new_figure, save_figure

__all__ = ["figure_bounds", "figure_region", "figure_estimators"]


def figure_bounds(params, inputs, outputs):
    """Figs 1 and 2: s_k, r_k, the report's estimate and the exact E(p_k) (its band collapses: lo = hi)."""
    table = read_table(inputs["bounds"])
    stable = params["which"] == "stable"
    lam_c = table["lam"].min() + (table["lam"].max() - table["lam"].min()) / 2
    data = table[(table["lam"] > lam_c) == stable].sort_values("k")
    fig, ax = new_figure()
    k = data["k"]
    ax.plot(k, data["r"], "-", color="C3", label="upper bound $r_k$ (9)")
    ax.plot(k, data["s"], "-", color="C0", label="lower bound $s_k$ (10)")
    ax.plot(k, data["report_estimate"], "--", color="C2", label="report's estimate (corrected)")
    ax.fill_between(k, data["mean_lo"], data["mean_hi"], color="k", alpha=0.2, lw=0)
    ax.plot(k, data["mean"], ":", color="k", label="true $E(p_k)$ (exact)")
    ax.set_xlabel("k")
    ax.set_ylabel("prediction error variance")
    lam = data["lam"].iloc[0]
    ax.set_title(f"$\\lambda = {lam:.4f}$ ({'stable' if stable else 'diverging'} case)")
    if not stable:
        ax.set_yscale("log")
    ax.legend(fontsize=8)
    save_figure(fig, outputs["figure"])


def figure_region(params, inputs, outputs):
    """Figs 4 and 5: lower bound and LMI upper bound of lambda_2c against lambda_1 (plus simulation checks)."""
    region = read_table(inputs["region"])
    fig, ax = new_figure(figsize=(5.0, 4.2))
    ax.plot(region["lambda1"], region["lambda2c_lower"], "-", color="C0", label="lower bound $\\lambda_{2c}^{lower}$")
    if params["show_upper"]:
        ax.plot(region["lambda1"], region["lambda2c_upper"], "o", mfc="none", color="C3", ms=4,
                label="LMI upper bound $\\lambda_{2c}^{upper}$ (bisection)")
        sim = read_table(inputs["simulation"])
        for side, marker, color in (("stable", "^", "C2"), ("unstable", "v", "C1")):
            pt = sim[sim["side"] == side].iloc[0]
            ax.plot(pt["lambda1"], pt["lambda2"], marker, color=color, ms=8, label=f"simulation check: {side}")
    ax.set_xlabel("$\\lambda_1$")
    ax.set_ylabel("$\\lambda_2$")
    ax.set_xlim(0, 1)
    ax.set_ylim(0, 1)
    ax.legend(fontsize=8)
    save_figure(fig, outputs["figure"])


def figure_estimators(params, inputs, outputs):
    """Fig S1 (ours): the plain sample mean of p_k against the conditional estimator and the exact mean."""
    mc = read_table(inputs["mc"])
    exact = read_table(inputs["exact"])
    lams = sorted(mc["lam"].unique())
    fig, axes = new_figure(1, len(lams), figsize=(10, 4))
    for ax, lam in zip(np.atleast_1d(axes), lams):
        d = mc[np.isclose(mc["lam"], lam)].sort_values("k")
        e = exact[np.isclose(exact["lam"], lam)]
        ax.fill_between(d["k"], d["cond_lo"], d["cond_hi"], color="C0", alpha=0.3, lw=0)
        ax.plot(d["k"], d["cond_mean"], "-", color="C0", label="conditional estimator (95% band)")
        ax.fill_between(d["k"], d["plain_lo"], d["plain_hi"], color="C3", alpha=0.2, lw=0)
        ax.plot(d["k"], d["plain_mean"], "--", color="C3", label="plain sample mean (95% band)")
        ax.plot(e["k"], e["mean_exact"], "k.", ms=4, label="exact")
        ax.set_yscale("log")
        ax.set_xlabel("k")
        ax.set_title(f"$\\lambda = {lam:.4f}$, {int(d['n_paths'].iloc[0])} paths")
    np.atleast_1d(axes)[0].set_ylabel("$E(p_k)$")
    np.atleast_1d(axes)[0].legend(fontsize=8)
    save_figure(fig, outputs["figure"])
