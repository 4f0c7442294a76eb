"""Every plotting function of `gainsched` on tiny tables: a non-empty figure file."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from netrepro.pipeline.figurespec import load_figure_specs
from netrepro.papers.gainsched import figures

DESIGNS = ["paper", "theorem3", "performance", "tuned_scheduled", "zero"]


@pytest.fixture
def tables(tmp_path):
    ks = np.arange(6)
    rows, paths, summary = [], [], []
    for i, d in enumerate(DESIGNS):
        for k in ks:
            m = 0.5 ** k * (1 + 0.1 * i)
            for st in ("fixed_x0", "gaussian"):
                rows.append({"design": d, "initial_state": st, "k": k, "e1_mean": m, "e2_mean": -m, "e1_lo": m - 0.1,
                             "e1_hi": m + 0.1, "e2_lo": -m - 0.1, "e2_hi": -m + 0.1, "mse": 2 * m * m + 1e-3,
                             "e1_rms": m, "e2_rms": m})
            paths.append({"design": d, "k": k, "p": 0.5, "e1": m, "e2": -m})
        summary += [{"design": d, "initial_state": s, "sum_mse": 1.0 + i} for s in ("fixed_x0", "gaussian")]
        summary[-1]["sum_mse_se"] = summary[-2]["sum_mse_se"] = 0.1
    exact, exact_k = [], []
    for i, d in enumerate(DESIGNS):
        for f in ("F1", "F2", "mid"):
            for st in ("gaussian", "x0"):
                exact.append({"design": d, "nonlinearity": f, "initial_state": st, "sum_mse": 2.0 + i, "final_mse": 1e-9})
                exact_k += [{"design": d, "nonlinearity": f, "initial_state": st, "k": k, "mse": 2 * 0.5 ** k} for k in ks]
    sens = [{"variant": v, "sigma2": s2, "status": "optimal", "margin": 0.1 - 0.02 * s2, "certified_slack": 0.1,
             "plant_radius": 0.5, "verdict": verdict, "kind": "grid"}
            for v in ("scheduled", "fixed_gain", "zero", "plant")
            for s2, verdict in ((0.5, "feasible"), (1.0, "undecided"), (2.0, "infeasible"))]
    sens.append({"variant": "plant", "sigma2": 4.0, "status": "not solved", "margin": np.nan, "certified_slack": np.nan,
                 "plant_radius": 1.1, "verdict": "infeasible", "kind": "grid"})
    limits = [{"design": d, "sigma2_max": 3.0, "sigma2_lo": 3.0, "sigma2_hi": 3.1, "certified": True, "role": role}
              for d, role in (("scheduled", "sufficient"), ("fixed_gain", "sufficient"), ("zero", "sufficient"),
                              ("plant", "sufficient"), ("plant_necessary", "necessary"))]
    out = {}
    for name, frame in (("errors", rows), ("paths", paths), ("summary", summary), ("sensitivity", sens),
                        ("exact", exact), ("exact_k", exact_k), ("limits", limits)):
        out[name] = tmp_path / f"{name}.csv"
        pd.DataFrame(frame).to_csv(out[name], index=False)
    return out


@pytest.mark.parametrize("spec", load_figure_specs("gainsched"), ids=lambda s: s.figure_id)
def test_figure(spec, tables, tmp_path):
    names = {"simulation.errors": "errors", "simulation.paths": "paths", "simulation.error_summary": "summary",
             "sensitivity": "sensitivity", "exact_moments": "exact", "exact_moments.per_k": "exact_k",
             "sensitivity.limits": "limits"}
    inputs = {name: tables[names[ref]] for name, ref in spec.inputs.items()}
    out = tmp_path / f"{spec.figure_id}.png"
    getattr(figures, spec.plot)(spec.params, inputs, {"figure": out})
    assert out.stat().st_size > 1000
