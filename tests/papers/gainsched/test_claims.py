"""Claims-side steps of `gainsched` on tiny tables: columns and the values they carry over."""

from __future__ import annotations

import numpy as np
import pandas as pd

from netrepro.papers.gainsched.claims import reconstructions_step


def test_reconstructions_carry_the_certified_limits(cfg, tmp_path):
    limits = pd.DataFrame([{"design": d, "sigma2_lo": lo, "sigma2_hi": hi}
                           for d, lo, hi in (("scheduled", 3.25, 4.0), ("fixed_gain", 2.5, 4.0), ("zero", 2.0, 4.0),
                                             ("plant", 3.5, 5.5))])
    exact = pd.DataFrame([{"design": d, "nonlinearity": "mid", "initial_state": "gaussian", "sum_mse": s}
                          for d, s in (("theorem3", 4.0), ("theorem3_S21I", 6.0))])
    limits.to_csv(tmp_path / "s.csv", index=False)
    exact.to_csv(tmp_path / "m.csv", index=False)
    table = reconstructions_step(cfg, {"limits": tmp_path / "s.csv", "exact": tmp_path / "m.csv"}, {})["table"]
    assert {"paper", "key", "value", "reason", "sensitivity"} <= set(table.columns)
    row = table[table["key"] == "system.sigma2"].iloc[0]
    assert "3.25" in row["sensitivity"] and "2.5" in row["sensitivity"] and "5.5" in row["sensitivity"]
    d3 = table[table["key"] == "lmi.realisation"].iloc[0]
    assert "4" in d3["sensitivity"] and "6" in d3["sensitivity"]
    assert np.all(table["paper"] == "gainsched")
