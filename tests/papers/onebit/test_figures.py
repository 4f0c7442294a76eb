"""Tests of netrepro.papers.onebit.figures: every plotting function on tiny tables."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from netrepro.papers.onebit import figures


def _ratios():
    snr = np.array([-10.0, 0.0, 10.0])
    rows = []
    for alpha in (1 - 1e-3, 1 - 1e-5, 1.0):
        rows.append(pd.DataFrame(dict(alpha=alpha, snr_db=snr, efq_db=-2.0, rho_sl_db=-0.9, rho_f_db=-1.0,
                                      rho_s_db=1.5)))
    return pd.concat(rows, ignore_index=True)


def _estimator():
    rows = []
    for kind in ("filter_1bit", "smoother_1bit", "kalman_filter", "rts_smoother"):
        for snr in (-10.0, 0.0):
            rows.append(dict(alpha=0.99, snr_db=snr, kind=kind, mse=0.5, mse_lo=0.45, mse_hi=0.55, bound=0.4,
                             bound_steady=0.4, mse_over_bound=1.25, n_runs=10))
    return pd.DataFrame(rows)


def _transient():
    k = np.array([0, 1, 10, 100])
    return pd.concat([pd.DataFrame(dict(alpha=a, snr_db=s, k=k, var_ratio=1 + 1.0 / (k + 1), efq_ratio=1.0,
                                        j_f_q_ratio=1 + 0.5 / (k + 1), j_f_inf_ratio=1.0))
                      for a in (1 - 1e-3, 1 - 1e-5) for s in (-10.0, 10.0)], ignore_index=True)


def _lag():
    return pd.DataFrame(dict(alpha=[0.999, 0.999], snr_db=[-10.0, 0.0], delta_needed=[10, 30], tol_db=0.01,
                             delta_break_even=[5.0, np.nan]))


def _estimator_ratios():
    return pd.DataFrame([dict(alpha=0.999, snr_db=x, quantity=q, estimate_db=0.5, lo_db=0.3, hi_db=0.7, bound_db=1.0,
                              n_runs=10) for q in ("rho_F", "rho_S", "rho_SL") for x in (-10.0, 0.0)]
                        + [dict(alpha=0.9, snr_db=x, quantity="rho_S", estimate_db=0.1, lo_db=0.0, hi_db=0.2, bound_db=0.1,
                                n_runs=10) for x in (-10.0, 0.0)])


@pytest.mark.parametrize("func,name,table,params", [
    ("figure_rho_sl", "ratios", _ratios, {"fig1_one_minus_alpha": 1e-5}),
    ("figure_rho_s_f", "ratios", _ratios, {}),
    ("figure_estimator", "estimator", _estimator, {}),
    ("figure_convergence", "transient", _transient, {}),
    ("figure_lag", "lag", _lag, {}),
    ("figure_estimator_ratios", "ratios", _estimator_ratios, {}),
])
def test_every_figure_is_written(tmp_path, func, name, table, params):
    path = tmp_path / f"{name}.csv"
    table().to_csv(path, index=False)
    out = tmp_path / "fig.png"
    getattr(figures, func)(params, {name: path}, {"figure": out})
    assert out.is_file() and out.stat().st_size > 1000
