import pandas as pd

from netrepro.papers.intermittent import claims

A, R1, R2, P0 = 1.5, 0.1, 0.5, 10.0


def test_errata_corrections_are_right_and_printed_forms_wrong():
    cfg = {"scalar": dict(a=A, R1=R1, R2=R2, Ep0=P0), "two_sensor": {"sigma2": [0.2, 0.5]}}
    rows = pd.DataFrame(claims.errata_rows(cfg))
    numeric = rows.dropna(subset=["residual_printed"])
    assert len(rows) >= 10 and len(numeric) >= 8
    assert (numeric["residual_corrected"] < 1e-5).all()
    assert (numeric["residual_printed"] > 1e-3).all()


def test_settle_step():
    assert claims._settle_step([5.0, 2.0, 1.05, 1.0, 1.0]) == 3  # 1.05 is 5% off: settled from k = 3
    assert claims._settle_step([1.0, 1.0]) == 0


def test_reconstructions_name_every_unstated_key():
    cfg = {"scalar": dict(a=A, R1=R1, R2=R2, Ep0=P0, horizon=60),
           "two_sensor": dict(sigma2=[0.2, 0.5], lambda1_grid=51, R1=0.1)}
    table = claims.reconstructions_step(cfg, {}, {})["table"]
    assert {"scalar.Ep0", "two_sensor.sigma2"} <= set(table["key"])
