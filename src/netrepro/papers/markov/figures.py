"""Figures of the `markov` paper: plotting only, from the tables under ``results/markov/``."""

from __future__ import annotations

import numpy as np
import pandas as pd

from ...figures.plotting import COLOURS, OKABE_ITO, new_figure, save_figure

__all__ = ["figure_plane", "figure_path", "figure_mean", "figure_estimators", "figure_curves"]


# the stability map: colour and shape, so the verdicts are told apart without colour vision too
_MAP_STYLE = {"bounded": (COLOURS["bounded"], "o"), "unbounded": (COLOURS["unbounded"], "x"),
              "undecided": (COLOURS["undecided"], "s")}


def figure_plane(params, inputs, outputs):
    """Fig. 2 made quantitative: the p-q plane of both examples with the curves and the stability map."""
    curves = pd.read_csv(inputs["curves"])
    smap = pd.read_csv(inputs["map"], keep_default_na=False)
    iid = pd.read_csv(inputs["iid"]).set_index("example")
    names = list(params["examples"])
    fig, axes = new_figure(1, len(names), figsize=(5.2 * len(names), 4.6), squeeze=False)
    for ax, name in zip(axes[0], names):
        s = smap[smap.example == name]
        for verdict, (color, marker) in _MAP_STYLE.items():
            sub = s[s.verdict == verdict]
            ax.scatter(sub.q, sub.p, s=7, marker=marker, color=color, alpha=0.55, linewidths=0.8 if marker == "x" else 0,
                       label=f"map: E||P_k|| {verdict}")
        c = curves[curves.example == name]
        ax.plot(c.q, c.p_thm5, color=COLOURS["exact"], lw=2, label="Theorem 5 lower bound p(q)")
        ax.plot(c.q, c.p_prop1, color=OKABE_ITO["blue"], lw=1.5, ls=":", label="Proposition 1 (eq. 8)")
        if c.p_reference.notna().any():
            # drawn last and on top: in Example II it coincides with the Theorem 5 curve
            ax.plot(c.q, c.p_reference, color=COLOURS["reference"], lw=1.6, ls=(0, (2, 2)), zorder=5,
                    label="reference p_c (dashed on top; = Theorem 5 in Example II)")
        qn = c.q_necessary.iloc[0]
        ax.axvline(qn, color=COLOURS["threshold"], lw=1.5, label="necessary |lambda|^2(1-q) = 1 (q in each panel)")
        ax.annotate(f"q = {qn:.3f}", (qn, 0.92), xytext=(4, 0), textcoords="offset points", color=COLOURS["threshold"],
                    fontsize=8, bbox=dict(boxstyle="round,pad=0.15", fc="white", ec="none", alpha=0.9))
        ax.plot([0, 1], [1, 0], color="0.3", lw=1, ls="-.", label="i.i.d. line p + q = 1")
        r = iid.loc[name]
        ax.plot([r.q_thm5_on_iid_line], [1 - r.q_thm5_on_iid_line], "k*", ms=10, label="Thm 5 on the i.i.d. line")
        ax.plot([r.lambda_lmi_upper], [1 - r.lambda_lmi_upper], "v", color=OKABE_ITO["blue"], ms=7, label="Sinopoli LMI bound")
        ax.plot([r.lambda_lower], [1 - r.lambda_lower], "^", color=OKABE_ITO["blue"], ms=7, label="Sinopoli lower bound")
        ax.set_xlim(0, 1)
        ax.set_ylim(0, 1.02)
        ax.set_xlabel("recovery rate q")
        ax.set_ylabel("failure rate p")
        ax.set_title(f"Example {name}")
    axes[0][-1].legend(fontsize=6.5, loc="upper left", bbox_to_anchor=(1.0, 1.0))
    save_figure(fig, outputs["figure"])
    return {}


_METHOD_STYLE = {
    "exact": dict(color=OKABE_ITO["orange"], lw=2.5, ls="-", label="E||P_k|| exact (all channel paths)"),
    "estimate_conditional": dict(color=OKABE_ITO["vermillion"], lw=1.5, ls="-.",
                                 label="E||P_k|| conditional estimator (validated, 95% CI)"),
    "asymptote": dict(color=OKABE_ITO["bluish_green"], lw=1.5, ls="--", label="E||P_k|| continued with the derived rate (bracket)"),
}


def _draw_expectations(ax, x):
    """The trustworthy E||P_k|| of expectations.csv, one style per method; gaps where not trustworthy."""
    for method, style in _METHOD_STYLE.items():
        sub = x[x.method == method]
        if sub.empty:
            continue
        ax.plot(sub.k, sub.mean_norm, **style)
        if method != "exact":
            ax.fill_between(sub.k, sub.lo, sub.hi, color=style["color"], alpha=0.2, lw=0)
    lim = x[(x.method == "asymptote") & np.isfinite(x.limit.astype(float))] if "limit" in x else x.iloc[:0]
    if len(lim):
        r = lim.iloc[0]
        ax.axhline(r.limit, color=_METHOD_STYLE["asymptote"]["color"], lw=1.2, ls="-.",
                   label=f"stable limit of E||P_k|| (derived rate): {r.limit:.4g} [{r.limit_lo:.4g}, {r.limit_hi:.4g}]")
        if np.isfinite([r.limit_lo, r.limit_hi]).all():
            ax.axhspan(r.limit_lo, r.limit_hi, color=_METHOD_STYLE["asymptote"]["color"], alpha=0.1, lw=0)
    bad = x[x.method == "not_trustworthy"]
    if len(bad):
        ax.axvspan(bad.k.min(), bad.k.max(), color="0.85", alpha=0.5, label="E||P_k|| not trustworthy (omitted)")


def _failed_estimates(ax, t, x, plain=False):
    """The conditional (and plain) estimates where they are not the trusted method, labelled as failing."""
    trusted = set(x.k[x.method == "estimate_conditional"]) | set(x.k[x.method == "exact"])
    rb = t[t.rb_mean.notna()]
    if not set(x.method) & {"estimate_conditional"}:
        ax.plot(rb.k, rb.rb_mean, color=OKABE_ITO["vermillion"], lw=0.9, ls=":",
                label="conditional estimator: misses the parity heavy tail (not used)")
    else:
        rb = rb[~rb.k.isin(trusted)]
        if len(rb):
            ax.plot(rb.k, rb.rb_mean, color=OKABE_ITO["vermillion"], lw=0.9, ls=":", label="conditional estimator (not validated)")
    if plain:
        ax.plot(t.k, t.plain_mean, color=OKABE_ITO["blue"], lw=0.9, ls="--",
                label="plain sample mean: misses the heavy tail (not used)")


def figure_path(params, inputs, outputs):
    """Figs. 3-5: a sample path of ||P_k|| and gamma_k, Monte Carlo bands, and the trustworthy E||P_k||."""
    t = pd.read_csv(inputs["paths"])
    t = t[t.figure == params["figure"]]
    x = _setting(inputs, t)
    fig, (ax, ax2) = new_figure(2, 1, figsize=(6.4, 4.8), sharex=True, gridspec_kw={"height_ratios": [3, 1]})
    ax.fill_between(t.k, t.q05, t.q95, color=OKABE_ITO["blue"], alpha=0.15, label="5-95% of ||P_k|| (Monte Carlo)")
    ax.plot(t.k, t.q50, color=OKABE_ITO["blue"], lw=1, ls="--", label="median")
    ax.plot(t.k, t.norm_path, color="k", lw=1.2, label="one sample path ||P_k||")
    _draw_expectations(ax, x)
    _failed_estimates(ax, t, x)
    ax.set_yscale("log")
    ax.set_ylabel("||P_k||")
    p, q = t.p.iloc[0], t.q.iloc[0]
    ax.set_title(f"Example {t.example.iloc[0]}, p = {p}, q = {q}")
    ax.legend(fontsize=6.5)
    g = t.dropna(subset=["gamma"])
    ax2.step(g.k, g.gamma, where="post", color="k", lw=0.8)
    ax2.set_ylim(-0.2, 1.2)
    ax2.set_yticks([0, 1])
    ax2.set_ylabel("gamma_k")
    ax2.set_xlabel("k")
    save_figure(fig, outputs["figure"])
    return {}


def _setting(inputs, t):
    """Rows of expectations.csv for the setting of the sample-path rows ``t``."""
    x = pd.read_csv(inputs["expectations"])
    ex, p, q = str(t.example.iloc[0]), t.p.iloc[0], t.q.iloc[0]
    return x[(x.example.astype(str) == ex) & np.isclose(x.p, p) & np.isclose(x.q, q)].sort_values("k")


def figure_mean(params, inputs, outputs):
    """Fig. 6: divergence of E||P_k|| at (0.99, 0.5) on Example II (trustworthy values; failing estimates)."""
    t = pd.read_csv(inputs["paths"])
    t = t[t.figure == params["figure"]]
    x = _setting(inputs, t)
    fig, ax = new_figure()
    _draw_expectations(ax, x)
    _failed_estimates(ax, t, x, plain=True)
    ax.plot(t.k, t.q50, color="0.5", lw=1, ls=":", label="median ||P_k||")
    ax.set_yscale("log")
    ax.set_xlabel("k")
    ax.set_ylabel("E||P_k||")
    ax.set_title(f"Example {t.example.iloc[0]}, p = {t.p.iloc[0]}, q = {t.q.iloc[0]}")
    ax.legend(fontsize=7)
    save_figure(fig, outputs["figure"])
    return {}


def figure_estimators(params, inputs, outputs):
    """Fig. S1: plain sample mean and conditional estimator against the trustworthy E||P_k|| over the horizon."""
    t = pd.read_csv(inputs["paths"])
    figs = list(dict.fromkeys(t.figure))
    fig, axes = new_figure(1, len(figs), figsize=(3.0 * len(figs), 3.6), squeeze=False, sharey=True)
    for ax, name in zip(axes[0], figs):
        tf = t[t.figure == name]
        x = _setting(inputs, tf).set_index("k")
        ref = x.mean_norm.reindex(tf.k).to_numpy()
        ok = x.method.reindex(tf.k).fillna("not_trustworthy").to_numpy()
        lo = (x.lo.reindex(tf.k) / x.mean_norm.reindex(tf.k)).to_numpy()
        hi = (x.hi.reindex(tf.k) / x.mean_norm.reindex(tf.k)).to_numpy()
        ax.fill_between(tf.k, lo, hi, color=OKABE_ITO["reddish_purple"], alpha=0.2, lw=0, label="trusted value: interval / bracket")
        ax.plot(tf.k, tf.plain_mean.to_numpy() / ref, color=OKABE_ITO["blue"], lw=1, ls="--", label="plain sample mean / trusted")
        ax.plot(tf.k, tf.rb_mean.to_numpy() / ref, color=OKABE_ITO["vermillion"], lw=1, ls=":", label="conditional estimator / trusted")
        for method, style in _METHOD_STYLE.items():
            sel = ok == method
            if sel.any():
                ax.plot(tf.k[sel], np.ones(sel.sum()), color=style["color"], ls=style["ls"], lw=3, alpha=0.6,
                        label=f"trusted by: {method}")
        ax.axhline(1.0, color="k", lw=0.5)
        ax.set_yscale("log")
        ax.set_xlabel("k")
        ax.set_title(f"Ex {tf.example.iloc[0]} ({tf.p.iloc[0]:g}, {tf.q.iloc[0]:g})", fontsize=8)
    axes[0][0].set_ylabel("estimate / trustworthy E||P_k||")
    axes[0][-1].legend(fontsize=6, loc="upper left", bbox_to_anchor=(1.0, 1.0))
    save_figure(fig, outputs["figure"])
    return {}


def figure_curves(params, inputs, outputs):
    """Fig. S2: uncapped Proposition 1 and Theorem 5 bounds (log scale) with the reference critical values p_c."""
    curves = pd.read_csv(inputs["curves"])
    fig, ax = new_figure()
    for name, color in zip(params["examples"], (OKABE_ITO["blue"], OKABE_ITO["bluish_green"], OKABE_ITO["vermillion"])):
        c = curves[curves.example == name]
        ax.plot(c.q, c.p_thm5_uncapped, color=color, lw=2, label=f"Ex {name}: Theorem 5 (uncapped)")
        ax.plot(c.q, c.p_prop1_uncapped, color=color, lw=1, ls="--", label=f"Ex {name}: Proposition 1")
        sat = c[c.thm5_saturated.astype(str).str.lower() == "true"]
        ax.plot(sat.q, sat.p_thm5_uncapped, "^", color=color, ms=5, label=f"Ex {name}: search cap reached")
        ref = c[c.p_reference.notna() & (c.p_reference > 0)]
        if len(ref):
            ax.plot(ref.q, ref.p_reference, color=color, lw=1.2, ls=":", marker="o", ms=2.5,
                    label=f"Ex {name}: reference critical value p_c ({ref.reference.iloc[0].split(':')[0].split(' (')[0]})")
    ax.axhline(1.0, color="k", lw=0.8)
    ax.set_yscale("log")
    ax.set_xlabel("q")
    ax.set_ylabel("bound on p")
    ax.legend(fontsize=7)
    save_figure(fig, outputs["figure"])
    return {}
