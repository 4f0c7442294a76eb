import numpy as np
import pandas as pd
import pytest

from netrepro.papers.intermittent import two_sensor as ts

A = 1.5


def test_two_sensor_lmi_equals_lower_bound():
    grid = np.array([0.0, 0.3, 0.5, 0.8])
    upper = pd.DataFrame(ts.two_sensor_upper_bound(grid, A, tol=1e-5))
    assert np.allclose(upper["lambda2c_upper"], ts.two_sensor_lower_bound(grid, A), atol=1e-4)
    assert (upper["certified_radius"] < 1).all()


def test_lower_bound_is_zero_when_one_sensor_suffices():
    assert ts.two_sensor_lower_bound(0.6, A) == 0.0
    assert ts.two_sensor_lower_bound(0.0, A) == pytest.approx(1 - 1 / A**2)


def test_modes_follow_the_arrival_pattern_order():
    modes = ts.two_sensor_modes()
    assert modes[0] is None and [m.shape for m in modes[1:]] == [(1, 1), (1, 1), (2, 1)]
