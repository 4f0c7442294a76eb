"""Steps of the `gainsched` paper on tiny inputs."""

from __future__ import annotations

import numpy as np

from netrepro.papers.gainsched.steps import MATRICES, gains_from_table, gains_table


def test_gains_table_round_trip(sys, paper):
    tab = gains_table("paper", paper)
    assert list(tab.columns) == ["design", "matrix", "row", "col", "value"]
    back = gains_from_table(tab, "paper", sys)
    for k in MATRICES:
        np.testing.assert_array_equal(getattr(back, k), getattr(paper, k))
