import numpy as np
import pandas as pd
import pytest

from netrepro.papers.intermittent import two_sensor as ts

A = 1.5


def test_two_sensor_lmi_equals_lower_bound():
    grid = np.array([0.0, 0.3, 0.5, 0.8])
    upper = pd.DataFrame(ts.two_sensor_upper_bound(grid, A, tol=1e-5))
    lower = ts.two_sensor_lower_bound(grid, A)
    assert np.allclose(upper["lambda2c_upper"], lower, atol=1e-4)
    assert upper["certified"].all() and (upper["upper_slack"] > 0).all()
    # the closed form (an independent, exact threshold for C invertible) lies in every certified bracket
    assert (upper["bracket_lower"].fillna(0.0) <= lower + 1e-12).all()
    assert (lower <= upper["lambda2c_upper"] + 1e-12).all()
    inner = upper["bracket_lower"].notna()
    assert upper.loc[inner, "lower_certified_by"].str.startswith("necessary condition violated").all()
    assert upper["upper_certified_by"].str.startswith("eigenvalue check").all()


def test_a_feasible_end_is_truly_feasible_and_an_infeasible_end_truly_infeasible():
    """Independent check of both ends: (1 - l1)(1 - l2) a^2 < 1 is necessary and sufficient for C invertible."""
    for lam1 in (0.1, 0.35):
        row = ts.two_sensor_upper_bound([lam1], A, tol=1e-3)[0]
        assert (1 - lam1) * (1 - row["lambda2c_upper"]) * A * A < 1
        assert (1 - lam1) * (1 - row["bracket_lower"]) * A * A >= 1


def test_lower_bound_is_zero_when_one_sensor_suffices():
    assert ts.two_sensor_lower_bound(0.6, A) == 0.0
    assert ts.two_sensor_lower_bound(0.0, A) == pytest.approx(1 - 1 / A**2)


def test_modes_follow_the_arrival_pattern_order():
    modes = ts.two_sensor_modes()
    assert modes[0] is None and [m.shape for m in modes[1:]] == [(1, 1), (1, 1), (2, 1)]
