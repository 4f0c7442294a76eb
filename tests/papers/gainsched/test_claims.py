"""Claims-side steps of `gainsched` on tiny tables: columns and the values they carry over."""

from __future__ import annotations

import numpy as np
import pandas as pd

from netrepro.papers.gainsched.claims import reconstructions_step


def test_reconstructions_carry_the_sensitivity_limits(cfg, tmp_path):
    sens = pd.DataFrame([{"variant": v, "sigma2": s2, "kind": "sigma2_max"}
                         for v, s2 in (("scheduled", 3.25), ("fixed", 2.5), ("plant_ms_limit", 5.5))])
    summary = pd.DataFrame([{"design": d, "initial_state": "gaussian", "sum_mse": s}
                            for d, s in (("theorem3", 4.0), ("theorem3_S21I", 6.0))])
    sens.to_csv(tmp_path / "s.csv", index=False)
    summary.to_csv(tmp_path / "m.csv", index=False)
    table = reconstructions_step(cfg, {"sensitivity": tmp_path / "s.csv", "summary": tmp_path / "m.csv"}, {})["table"]
    assert {"paper", "key", "value", "reason", "sensitivity"} <= set(table.columns)
    row = table[table["key"] == "system.sigma2"].iloc[0]
    assert "3.25" in row["sensitivity"] and "2.5" in row["sensitivity"] and "5.5" in row["sensitivity"]
    assert np.all(table["paper"] == "gainsched")
