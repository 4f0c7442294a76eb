"""Figures of the `onebit` paper: plotting only, from the tables of :mod:`.steps`."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from ...figures.plotting import OKABE_ITO, new_figure, palette, save_figure

__all__ = ["figure_rho_sl", "figure_rho_s_f", "figure_estimator", "figure_convergence", "figure_lag",
           "figure_estimator_ratios"]


def _db(x):
    return 10.0 * np.log10(x)


def _alpha_label(alpha):
    """Legend text of an alpha: 1 - 10^n, or the limit."""
    if alpha == 1.0:
        return r"$\alpha \to 1$"
    n = math.log10(1.0 - alpha)
    return rf"$\alpha = 1 - 10^{{{n:.0f}}}$" if abs(n - round(n)) < 1e-6 else rf"$\alpha = {alpha:g}$"


def _new_fig(figsize=(6.4, 4.0)):
    return new_figure(figsize=figsize)


def figure_rho_sl(params, inputs, outputs):
    """Fig 1: rho_SL vs SNR for alpha = 1 - 1e-5 (with the other alphas and the limit, thin)."""
    rat = pd.read_csv(inputs["ratios"])
    fig, ax = _new_fig()
    a_main = 1.0 - params["fig1_one_minus_alpha"]
    for i, (alpha, g) in enumerate(rat.groupby("alpha")):
        main = np.isclose(alpha, a_main, rtol=0, atol=1e-15)
        lab = _alpha_label(alpha)
        if alpha == 1.0:   # the limit lies on the main curve over most of the axis: dashed on top, markers offset
            ax.plot(g["snr_db"], g["rho_sl_db"], color="k", lw=1.2, ls="--", marker="o", mfc="none", ms=4,
                    markevery=(5, 10), zorder=5, label=lab)
            continue
        ax.plot(g["snr_db"], g["rho_sl_db"], color=palette(i), lw=2.0 if main else 1.0, ls="-" if main else ":",
                marker="s" if not main else None, ms=3, markevery=(0, 10), label=lab)
    ax.axhline(5 * math.log10(2 / math.pi), color="0.5", lw=0.8, ls="-.", label=r"$\sqrt{2/\pi}$ (-0.98 dB)")
    ax.set_xlabel(r"SNR = $\sigma^2_{\theta,\infty}/\sigma^2_\eta$ [dB]")
    ax.set_ylabel(r"$\rho_{SL}$ [dB]")
    ax.set_title(r"Fig 1: 1-bit loss of smoothing, $\rho_{SL}$")
    ax.legend()
    save_figure(fig, outputs["figure"])
    return {}


def figure_rho_s_f(params, inputs, outputs):
    """Fig 2: rho_S and rho_F vs SNR as alpha -> 1 (limit bold, finite alphas thin)."""
    rat = pd.read_csv(inputs["ratios"])
    fig, ax = _new_fig()
    finite = sorted(a for a in rat["alpha"].unique() if a != 1.0)
    style = {a: dict(s=c_s, f=c_f, marker=mk) for a, c_s, c_f, mk in zip(finite, (OKABE_ITO["sky_blue"], OKABE_ITO["bluish_green"], OKABE_ITO["reddish_purple"]), (OKABE_ITO["orange"], OKABE_ITO["reddish_purple"], OKABE_ITO["yellow"]),
                                                                      ("^", "s", "D"))}
    for alpha, g in rat.groupby("alpha"):
        lim = alpha == 1.0
        lab = _alpha_label(alpha)
        st = style.get(alpha, {})
        kw = dict(lw=2.0, ls="-") if lim else dict(lw=0.9, ls=":", marker=st["marker"], ms=4, markevery=(0, 8))
        ax.plot(g["snr_db"], g["rho_s_db"], color=OKABE_ITO["blue"] if lim else st["s"], label=rf"$\rho_S$, {lab}", **kw)
        kw = dict(kw, markevery=(4, 8)) if not lim else kw
        ax.plot(g["snr_db"], g["rho_f_db"], color=OKABE_ITO["vermillion"] if lim else st["f"], label=rf"$\rho_F$, {lab}",
                **(kw if lim else dict(kw, mfc="none")))
    ax.axhline(0.0, color="k", lw=0.8)
    ax.axhline(10 * math.log10(2 * math.sqrt(2 / math.pi)), color="k", lw=0.8, ls="--", label="+2.03 dB")
    ax.set_xlabel(r"SNR = $\sigma^2_{\theta,\infty}/\sigma^2_\eta$ [dB]")
    ax.set_ylabel("information ratio [dB]")
    ax.set_title(r"Fig 2: $\rho_S$ and $\rho_F$ ($\alpha \to 1$)")
    ax.legend(fontsize=7, ncol=2)
    save_figure(fig, outputs["figure"])
    return {}


def figure_estimator(params, inputs, outputs):
    """Fig S1: MSE of the grid filter/smoother (1-bit) and Kalman/RTS with 95% CIs next to the bounds."""
    est = pd.read_csv(inputs["estimator"])
    if "case_set" in est:
        est = est[est["case_set"] == "grid"]       # the crossing SNRs are shown in Fig S4
    est = est[est["alpha"] == est["alpha"].max()]  # the simulated alpha closest to one
    fig, (ax, ax2) = new_figure(1, 2, figsize=(10.0, 4.0))
    styles = {"filter_1bit": (OKABE_ITO["vermillion"], "o"), "smoother_1bit": (OKABE_ITO["blue"], "s"), "kalman_filter": (OKABE_ITO["orange"], "^"),
              "rts_smoother": (OKABE_ITO["bluish_green"], "v")}
    for i, (kind, g) in enumerate(est.groupby("kind", sort=False)):
        col, mk = styles[kind]
        x = g["snr_db"] + 0.3 * (i - 1.5)
        m, lo, hi = _db(g["mse"]), _db(g["mse_lo"]), _db(g["mse_hi"])
        ax.errorbar(x, m, yerr=[m - lo, hi - m], color=col, marker=mk, ls="none", label=f"MSE, {kind}")
        ax.plot(g["snr_db"], _db(g["bound"]), color=col, lw=1.0)
        b = _db(g["bound"])
        ax2.errorbar(x, m - b, yerr=[m - lo, hi - m], color=col, marker=mk, ls="-", lw=0.8, label=kind)
    ax.set_xlabel("SNR [dB]")
    ax.set_ylabel(r"MSE (markers, 95% CI) and BCRB (lines) [dB re $\sigma_\eta^2$]")
    ax.legend(fontsize=7)
    ax2.axhline(0.0, color="k", lw=0.8)
    ax2.set_xlabel("SNR [dB]")
    ax2.set_ylabel("MSE / BCRB [dB]")
    ax2.legend(fontsize=7)
    fig.suptitle(rf"Fig S1: near-optimal estimators vs the bounds ($\alpha = {est['alpha'].iloc[0]:g}$)")
    save_figure(fig, outputs["figure"])
    return {}


def figure_convergence(params, inputs, outputs):
    """Fig S2: transients of Var[theta_k], E[F_q(theta_k)] and J_{k|k,q} (iterate / fixed point)."""
    tr = pd.read_csv(inputs["transient"])
    alphas = sorted(tr["alpha"].unique())
    fig, axes = new_figure(1, len(alphas), figsize=(4.2 * len(alphas), 3.8), squeeze=False)
    for ax, alpha in zip(axes[0], alphas):
        sub = tr[tr["alpha"] == alpha]
        for j, (snr, g) in enumerate(sub.groupby("snr_db")):
            g = g[g["k"] > 0]
            # past the fourth SNR the palette's colours come close under colour vision deficiencies: dashed
            ax.loglog(g["k"], np.abs(g["j_f_q_ratio"] - 1) + 1e-17, color=palette(j), ls="-" if j < 4 else "--",
                      label=f"{snr:g} dB")
            ax.loglog(g["k"], np.abs(g["var_ratio"] - 1) + 1e-17, color=palette(j), ls=":")
        ax.set_xlabel("k")
        ax.set_title(_alpha_label(alpha), fontsize=9)
        ax.set_ylim(1e-16, 1e4)
        ax.legend(fontsize=7)
    axes[0][0].set_ylabel("relative distance to the fixed point")
    fig.suptitle(r"Fig S2: $|J_{k|k,q}/\tilde J_{k|k,q} - 1|$ (solid) and $|\mathrm{Var}\,\theta_k/\sigma^2_{\theta,\infty} - 1|$ "
                 r"(dotted) from $\sigma_{\theta_0} = 1$", fontsize=10, y=1.04)
    save_figure(fig, outputs["figure"])
    return {}


def figure_lag(params, inputs, outputs):
    """Fig S3: smoothing lag Delta needed (0.01 dB) vs SNR."""
    lag = pd.read_csv(inputs["lag"])
    fig, ax = _new_fig(figsize=(9.0, 4.0))
    for i, (alpha, g) in enumerate(lag.groupby("alpha")):
        ax.semilogy(g["snr_db"], g["delta_needed"], marker=".", color=palette(i), label=_alpha_label(alpha))
        if "delta_break_even" in g:
            ax.semilogy(g["snr_db"], g["delta_break_even"], ls="--", color=palette(i),
                        label=rf"break-even $\Delta$ ($J_{{k|k+\Delta,q}} > J_{{k|k,\infty}}$), {_alpha_label(alpha)}")
    if "crossing" in inputs:   # where the real smoother no longer breaks even: its rho_S = 0 dB crossing (issue 37)
        cr = pd.read_csv(inputs["crossing"]).set_index(["alpha", "curve"])["snr_db_crossing"]
        for i, (alpha, _) in enumerate(lag.groupby("alpha")):
            if (alpha, "estimate") not in cr.index or not np.isfinite(cr[(alpha, "estimate")]):
                continue
            e, lo, hi = cr[(alpha, "estimate")], cr[(alpha, "lo")], cr[(alpha, "hi")]
            ax.axvspan(lo, hi, color=palette(i), alpha=0.15, lw=0)
            ax.axvline(e, color=palette(i), lw=1.2, ls="-.",
                       label=rf"real 1-bit smoother no longer breaks even: {e:.2f} dB [{lo:.2f}, {hi:.2f}], "
                             rf"{_alpha_label(alpha)}")
    ax.set_xlabel("SNR [dB]")
    ax.set_ylabel(r"lag $\Delta$ for %g dB" % lag["tol_db"].iloc[0])
    ax.set_title(r"Fig S3: smoothing delay $\Delta$ needed (solid), break-even lag of the bound (dashed), "
                 "where the real smoother stops breaking even (dash-dot, 95 % band)", fontsize=9)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)   # outside: covers no curve
    save_figure(fig, outputs["figure"])
    return {}


def figure_estimator_ratios(params, inputs, outputs):
    """Fig S4: rho_F, rho_S, rho_SL from the estimators' MSEs (paired-bootstrap 95 % intervals) next to the bound.

    The crossing SNRs' rho_S are crosses, their local fit a dashed curve; the achievable rho_S = 0 dB
    crossing (local fit, bootstrap interval) is a diamond with its interval on the 0 dB line, the
    bound's crossing a vertical tick. With ``bounds`` (``ratios.csv``), the alpha -> 1 limit of the
    achievable rho_S, 2/E[(sigma_eta^2 F_q)^(-1/2)], is the black dash-dot curve (issue 37).
    """
    allrat = pd.read_csv(inputs["ratios"])
    cross_pts = allrat[allrat["case_set"] == "crossing"] if "case_set" in allrat else allrat.iloc[:0]
    allrat = allrat[allrat["case_set"] == "grid"] if "case_set" in allrat else allrat
    a_main = allrat["alpha"].max()
    rat = allrat[allrat["alpha"] == a_main]
    fig, ax = _new_fig(figsize=(10.0, 4.4))
    colors = {"rho_F": OKABE_ITO["vermillion"], "rho_S": OKABE_ITO["blue"], "rho_SL": OKABE_ITO["bluish_green"]}
    others = allrat[(allrat["alpha"] != a_main) & (allrat["quantity"] == "rho_S")]
    ranked = sorted(set(allrat["alpha"]) | set(cross_pts["alpha"]), reverse=True)

    def alpha_colour(alpha):  # one colour per alpha, the main (largest) blue; apart under CVD (issue 41)
        order = (OKABE_ITO["blue"], OKABE_ITO["orange"], OKABE_ITO["bluish_green"], OKABE_ITO["sky_blue"])
        return order[ranked.index(alpha) % len(order)] if alpha in ranked else OKABE_ITO["reddish_purple"]

    for alpha, g in others.groupby("alpha", sort=False):
        g = g.sort_values("snr_db")
        ax.errorbar(g["snr_db"], g["estimate_db"], yerr=[g["estimate_db"] - g["lo_db"], g["hi_db"] - g["estimate_db"]],
                    color=alpha_colour(alpha), marker="s", mfc="none", ls="none", label=rf"$\rho_S$ from MSEs, $\alpha = {alpha:g}$")
        ax.plot(g["snr_db"], g["bound_db"], color=alpha_colour(alpha), lw=0.8, ls=":", label=rf"$\rho_S$ bound, $\alpha = {alpha:g}$")
    names = {"rho_F": r"$\rho_F$", "rho_S": r"$\rho_S$", "rho_SL": r"$\rho_{SL}$"}
    for i, (qty, g) in enumerate(rat.groupby("quantity", sort=False)):
        g = g.sort_values("snr_db")
        x = g["snr_db"] + 0.15 * (i - 1)
        ax.errorbar(x, g["estimate_db"], yerr=[g["estimate_db"] - g["lo_db"], g["hi_db"] - g["estimate_db"]],
                    color=colors[qty], marker="o", ls="none", label=f"{names[qty]} from MSEs")
        ax.plot(g["snr_db"], g["bound_db"], color=colors[qty], lw=1.0, label=f"{names[qty]} bound (47)-(49)")
    for alpha, g in cross_pts[cross_pts["quantity"] == "rho_S"].groupby("alpha", sort=False):
        col = alpha_colour(alpha)
        ax.errorbar(g["snr_db"], g["estimate_db"], yerr=[g["estimate_db"] - g["lo_db"], g["hi_db"] - g["estimate_db"]],
                    color=col, marker="x", ls="none", ms=5,
                    label=rf"$\rho_S$ at the crossing SNRs, $\alpha = {alpha:g}$ ({int(g['n_runs'].min())} runs)")
    fits = {}
    if "crossing" in inputs:
        crt = pd.read_csv(inputs["crossing"])
        if "coefs" in crt:
            for r in crt[(crt["curve"] == "estimate") & crt["coefs"].notna()].itertuples():
                xs = np.linspace(r.fit_snr_lo, r.fit_snr_hi, 60)
                fits[r.alpha] = (xs, np.polyval([float(c) for c in str(r.coefs).split()], xs))
        for alpha, (xs, ys) in fits.items():
            col = alpha_colour(alpha)
            ax.plot(xs, ys, color=col, lw=1.0, ls="--", label=rf"local fit of $\rho_S$, $\alpha = {alpha:g}$")
    lim = None
    if "bounds" in inputs:
        b = pd.read_csv(inputs["bounds"])
        if "rho_s_achievable_db" in b:
            lim = b[(b["alpha"] == 1.0) & np.isfinite(b["rho_s_achievable_db"])].sort_values("snr_db")
            lim = lim[lim["rho_s_achievable_db"] > -12.0]
            ax.plot(lim["snr_db"], lim["rho_s_achievable_db"], color="k", lw=1.4, ls="-.",
                    label=r"$\alpha \to 1$ achievable limit $2/E[F_q^{-1/2}]$ ($\sigma_\eta = 1$)")
    if "crossing" in inputs:
        cr = pd.read_csv(inputs["crossing"]).set_index(["alpha", "curve"])["snr_db_crossing"]
        for alpha in sorted({a for a, _ in cr.index}, reverse=True):
            col = alpha_colour(alpha)
            e, lo, hi = cr[(alpha, "estimate")], cr[(alpha, "lo")], cr[(alpha, "hi")]
            if np.isfinite(e):
                ax.errorbar([e], [0.0], xerr=[[e - lo], [hi - e]], color=col, marker="D", ms=6, capsize=3, zorder=6,
                            label=rf"achievable crossing {e:.2f} dB [{lo:.2f}, {hi:.2f}], $\alpha = {alpha:g}$")
            ax.plot([cr[(alpha, "bound")]], [0.0], color=col, marker="|", ms=14, mew=2, ls="none", zorder=6,
                    label=rf"bound crossing {cr[(alpha, 'bound')]:.2f} dB, $\alpha = {alpha:g}$")
    if len(cross_pts):   # zoom on the crossing SNRs (the empty lower left of the axes)
        ins = ax.inset_axes([0.04, 0.06, 0.4, 0.45])
        rs = pd.concat([cross_pts, allrat])
        rs = rs[(rs["quantity"] == "rho_S") & rs["alpha"].isin(cross_pts["alpha"].unique())]
        lo_x, hi_x = cross_pts["snr_db"].min() - 1.2, cross_pts["snr_db"].max() + 0.7
        rs = rs[(rs["snr_db"] >= lo_x) & (rs["snr_db"] <= hi_x)]
        for alpha, g in rs.groupby("alpha"):
            col = alpha_colour(alpha)
            ins.errorbar(g["snr_db"], g["estimate_db"], yerr=[g["estimate_db"] - g["lo_db"], g["hi_db"] - g["estimate_db"]],
                         color=col, marker="x", ls="none", ms=4, lw=0.8)
            if "crossing" in inputs:
                e, lo, hi = cr[(alpha, "estimate")], cr[(alpha, "lo")], cr[(alpha, "hi")]
                ins.errorbar([e], [0.0], xerr=[[e - lo], [hi - e]], color=col, marker="D", ms=5, capsize=3)
            if alpha in fits:
                ins.plot(*fits[alpha], color=col, lw=0.8, ls="--")
        if lim is not None:
            near = lim[(lim["snr_db"] >= lo_x) & (lim["snr_db"] <= hi_x)]
            ins.plot(near["snr_db"], near["rho_s_achievable_db"], color="k", lw=1.0, ls="-.")
        if len(rs):   # the data decide the range; the limit's plunge towards 3 dB leaves the inset
            ins.set_ylim(min(rs["lo_db"].min(), 0.0) - 0.3, rs["hi_db"].max() + 0.3)
        ins.axhline(0.0, color="k", lw=0.6)
        ins.set_xlim(lo_x, hi_x)
        ins.tick_params(labelsize=6)
        ins.set_title(r"$\rho_S$ near its crossing", fontsize=7)
    ax.axhline(0.0, color="k", lw=0.8)
    ax.set_xlabel(r"SNR = $\sigma^2_{\theta,\infty}/\sigma^2_\eta$ [dB]")
    ax.set_ylabel("ratio [dB]")
    others_txt = ", ".join(f"{a:g}" for a in sorted(others["alpha"].unique(), reverse=True))
    ax.set_title(rf"Fig S4: achievable ratios vs the bound ($\alpha = {a_main:g}$; $\rho_S$ also at {others_txt})",
                 fontsize=9)
    ax.legend(fontsize=6, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
    save_figure(fig, outputs["figure"])
    return {}
