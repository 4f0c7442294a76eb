"""Figures of `intermittent` (plotting only: read tables, draw, save)."""

from __future__ import annotations

import numpy as np

from ...pipeline.io import read_table
from ...figures.plotting import OKABE_ITO, new_figure, save_figure

__all__ = ["figure_bounds", "figure_region", "figure_estimators", "figure_stationary"]


def figure_bounds(params, inputs, outputs):
    """Figs 1 and 2: s_k, r_k, the report's estimate and the exact E(p_k) (its band collapses: lo = hi).

    With ``normalised: true`` a second panel shows each curve divided by the exact E(p_k), where the
    curves that coincide on a logarithmic axis separate.
    """
    table = read_table(inputs["bounds"])
    stable = params["which"] == "stable"
    normalised = bool(params.get("normalised", False))
    lam_c = table["lam"].min() + (table["lam"].max() - table["lam"].min()) / 2
    data = table[(table["lam"] > lam_c) == stable].sort_values("k")
    if normalised:
        fig, (ax, ax_n) = new_figure(1, 2, figsize=(11.0, 4.0))
    else:
        fig, ax = new_figure()
    k = data["k"]
    curves = (("r", "-", OKABE_ITO["vermillion"], "upper bound $r_k$ (9)"), ("s", "-", OKABE_ITO["blue"], "lower bound $s_k$ (10)"),
              ("report_estimate", "--", OKABE_ITO["bluish_green"], "report's estimate (corrected)"))
    for col, style, color, label in curves:
        ax.plot(k, data[col], style, color=color, label=label)
    ax.fill_between(k, data["mean_lo"], data["mean_hi"], color="k", alpha=0.2, lw=0)
    ax.plot(k, data["mean"], ":", color="k", label="true $E(p_k)$ (exact)")
    ax.set_xlabel("k")
    ax.set_ylabel("prediction error variance")
    lam = data["lam"].iloc[0]
    ax.set_title(f"$\\lambda = {lam:.4f}$ ({'stable' if stable else 'diverging'} case)")
    if not stable:
        ax.set_yscale("log")
    ax.legend(fontsize=8)
    if normalised:
        for col, style, color, label in curves:
            ax_n.plot(k, data[col] / data["mean"], style, color=color, label=label)
        ax_n.axhline(1.0, color="k", ls=":", lw=1, label="true $E(p_k)$ (exact) = 1")
        ax_n.set_yscale("log")
        ax_n.set_xlabel("k")
        ax_n.set_ylabel("curve / exact $E(p_k)$")
        ax_n.set_title("normalised by the exact $E(p_k)$")
        ax_n.legend(fontsize=8)
    save_figure(fig, outputs["figure"])


def figure_region(params, inputs, outputs):
    """Figs 4 and 5: the closed-form lower bound of lambda_2c (dense grid, kink included), the LMI upper bound
    (markers) and the two exactly decided check points."""
    region = read_table(inputs["region"])
    dense = read_table(inputs["closed_form"]).sort_values("lambda1")
    fig, ax = new_figure(figsize=(5.0, 4.2))
    ax.plot(dense["lambda1"], dense["lambda2c_lower"], "-", color=OKABE_ITO["blue"],
            label="lower bound $\\lambda_{2c}^{lower}$ (closed form)")
    if params["show_upper"]:
        ax.plot(region["lambda1"], region["lambda2c_upper"], "o", mfc="none", color=OKABE_ITO["vermillion"], ms=4,
                label="LMI upper bound $\\lambda_{2c}^{upper}$ (bisection)")
        sim = read_table(inputs["simulation"])
        for side, marker, color, word in (("stable", "^", OKABE_ITO["bluish_green"], "bounded"), ("unstable", "v", OKABE_ITO["orange"], "diverges")):
            pt = sim[sim["side"] == side].iloc[0]
            ax.plot(pt["lambda1"], pt["lambda2"], marker, color=color, ms=8,
                    label=f"check point, exact $E(p_k)$: {word}")
    ax.set_xlabel("$\\lambda_1$")
    ax.set_ylabel("$\\lambda_2$")
    ax.set_xlim(0, 1)
    ax.set_ylim(0, 1)
    ax.legend(fontsize=8)
    save_figure(fig, outputs["figure"])


def figure_estimators(params, inputs, outputs):
    """Fig S1 (ours): the plain sample mean of p_k against the conditional estimator and the exact mean.

    The legend gives the measured coverage of each nominal 95 % band: the fraction of k at which it contains
    the exact E(p_k) (k >= 1; at k = 0 every band is the point p_0).
    """
    mc = read_table(inputs["mc"])
    exact = read_table(inputs["exact"])
    lams = sorted(mc["lam"].unique())
    fig, axes = new_figure(1, len(lams), figsize=(10, 4))
    for ax, lam in zip(np.atleast_1d(axes), lams):
        d = mc[np.isclose(mc["lam"], lam)].sort_values("k")
        e = exact[np.isclose(exact["lam"], lam)]
        late = d[d["k"] >= 1]
        cover = {name: float(np.mean((late[f"{name}_lo"] <= late["exact_mean"])
                                     & (late["exact_mean"] <= late[f"{name}_hi"])))
                 for name in ("cond", "plain")}
        ax.fill_between(d["k"], d["cond_lo"], d["cond_hi"], color=OKABE_ITO["blue"], alpha=0.3, lw=0)
        ax.plot(d["k"], d["cond_mean"], "-", color=OKABE_ITO["blue"],
                label=f"conditional estimator (nominal 95 % band, covers {cover['cond']:.0%} of k)")
        ax.fill_between(d["k"], d["plain_lo"], d["plain_hi"], color=OKABE_ITO["vermillion"], alpha=0.2, lw=0)
        ax.plot(d["k"], d["plain_mean"], "--", color=OKABE_ITO["vermillion"],
                label=f"plain sample mean (nominal 95 % band, covers only {cover['plain']:.0%} of k)")
        ax.plot(e["k"], e["mean_exact"], "k.", ms=4, label="exact")
        ax.set_yscale("log")
        ax.set_xlabel("k")
        ax.set_title(f"$\\lambda = {lam:.4f}$, {int(d['n_paths'].iloc[0])} paths")
        ax.legend(fontsize=7)
    np.atleast_1d(axes)[0].set_ylabel("$E(p_k)$")
    save_figure(fig, outputs["figure"])


def figure_stationary(params, inputs, outputs):
    """Fig S2 (ours): the exact E(p_inf)(lambda) between s*(lambda) and r*(lambda) on (lambda_c, 1], with the
    tail index of p_inf and the range where its variance is infinite."""
    curve = read_table(inputs["curve"]).sort_values("lam")
    fig, (ax, ax_t) = new_figure(1, 2, figsize=(11.0, 4.0))
    lam = curve["lam"]
    ax.plot(lam, curve["r_limit"], "-", color=OKABE_ITO["vermillion"], label="$r^*$ (fixed point of (9))")
    ax.plot(lam, curve["stationary_mean"], "k-", lw=2, label="$E(p_\\infty)$ (exact)")
    ax.plot(lam, curve["s_limit"], "-", color=OKABE_ITO["blue"], label="$s^* = R_1 / (1 - (1 - \\lambda) a^2)$")
    infinite_var = curve[~curve["variance_finite"].astype(bool)]
    for a_ in (ax, ax_t):
        if len(infinite_var):
            a_.axvspan(lam.min(), infinite_var["lam"].max(), color=OKABE_ITO["orange"], alpha=0.12, lw=0,
                       label="variance of $p_\\infty$ infinite")
    if "report_setting" in curve:
        for _, row in curve[curve["report_setting"].astype(bool)].iterrows():
            ax.plot(row["lam"], row["stationary_mean"], "ko", ms=5, mfc="w",
                    label=f"report's stable case $\\lambda = {row['lam']:.4f}$")
            ax_t.plot(row["lam"], row["tail_index"], "ko", ms=5, mfc="w",
                      label=f"report's stable case: $\\alpha = {row['tail_index']:.2f}$")
    ax.set_yscale("log")
    ax.set_xlabel("$\\lambda$")
    ax.set_ylabel("stationary value")
    ax.set_title("stationary mean and its bounds")
    ax.legend(fontsize=8)
    finite = curve[np.isfinite(curve["tail_index"])]
    ax_t.plot(finite["lam"], finite["tail_index"], "k-", label="tail index $\\alpha = \\log(1/(1-\\lambda)) / \\log a^2$")
    ax_t.axhline(1.0, color=OKABE_ITO["blue"], ls="--", lw=1, label="$\\alpha = 1$: mean finite above")
    ax_t.axhline(2.0, color=OKABE_ITO["vermillion"], ls="--", lw=1, label="$\\alpha = 2$: variance finite above")
    ax_t.set_xlabel("$\\lambda$")
    ax_t.set_ylabel("tail index of $p_\\infty$")
    ax_t.set_title("$P(p_\\infty > x) \\sim x^{-\\alpha}$")
    ax_t.legend(fontsize=8)
    save_figure(fig, outputs["figure"])
