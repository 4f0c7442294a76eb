import numpy as np
import pandas as pd

from netrepro.pipeline.io import write_table
from netrepro.papers.intermittent import figures


def _bounds():
    rows = []
    for lam in (0.4556, 0.6556):
        k = np.arange(5)
        rows.append(pd.DataFrame({"lam": lam, "k": k, "s": 1.0 + k, "r": 2.0 + k, "report_estimate": 1.5 + k,
                                  "mean": 1.6 + k, "mean_lo": 1.5 + k, "mean_hi": 1.7 + k}))
    return pd.concat(rows, ignore_index=True)


def test_figure_bounds(tmp_path):
    write_table(_bounds(), tmp_path / "b.csv")
    for which in ("stable", "unstable"):
        out = tmp_path / f"{which}.png"
        for normalised in (False, True):
            figures.figure_bounds({"which": which, "normalised": normalised}, {"bounds": str(tmp_path / "b.csv")},
                                  {"figure": str(out)})
            assert out.stat().st_size > 0


def test_figure_region(tmp_path):
    region = pd.DataFrame({"lambda1": [0.0, 0.5, 1.0], "lambda2c_lower": [0.5, 0.1, 0.0],
                           "lambda2c_upper": [0.5, 0.1, 0.0]})
    sim = pd.DataFrame({"lambda1": 0.3, "lambda2": [0.4, 0.2], "side": ["stable", "unstable"]})
    dense = pd.DataFrame({"lambda1": [0.0, 0.25, 5 / 9, 1.0], "lambda2c_lower": [5 / 9, 0.4, 0.0, 0.0]})
    write_table(region, tmp_path / "r.csv")
    write_table(sim, tmp_path / "s.csv")
    write_table(dense, tmp_path / "d.csv")
    for show in (False, True):
        out = tmp_path / f"{show}.png"
        figures.figure_region({"show_upper": show}, {"region": str(tmp_path / "r.csv"), "closed_form": str(tmp_path / "d.csv"),
                                                     "simulation": str(tmp_path / "s.csv")}, {"figure": str(out)})
        assert out.stat().st_size > 0


def test_figure_estimators(tmp_path):
    k = np.arange(4)
    mc = pd.concat([pd.DataFrame({"lam": lam, "k": k, "cond_mean": 1.0 + k, "cond_lo": 0.9 + k, "cond_hi": 1.1 + k,
                                  "plain_mean": 0.8 + k, "plain_lo": 0.7 + k, "plain_hi": 0.9 + k, "n_paths": 10,
                                  "exact_mean": 1.0 + k})
                    for lam in (0.4, 0.6)])
    exact = pd.concat([pd.DataFrame({"lam": lam, "k": k[:3], "mean_exact": 1.0 + k[:3]}) for lam in (0.4, 0.6)])
    write_table(mc, tmp_path / "mc.csv")
    write_table(exact, tmp_path / "ex.csv")
    out = tmp_path / "s1.png"
    figures.figure_estimators({}, {"mc": str(tmp_path / "mc.csv"), "exact": str(tmp_path / "ex.csv")},
                              {"figure": str(out)})
    assert out.stat().st_size > 0


def test_figure_stationary(tmp_path):
    lam = np.array([0.56, 0.7, 0.9, 1.0])
    curve = pd.DataFrame({"lam": lam, "stationary_mean": [100.0, 2.0, 1.0, 0.8], "s_limit": [10.0, 0.3, 0.12, 0.1],
                          "r_limit": [120.0, 2.5, 1.05, 0.8], "tail_index": [1.01, 1.5, 2.8, np.inf],
                          "variance_finite": [False, False, True, True]})
    write_table(curve, tmp_path / "c.csv")
    out = tmp_path / "s2.png"
    figures.figure_stationary({}, {"curve": str(tmp_path / "c.csv")}, {"figure": str(out)})
    assert out.stat().st_size > 0
