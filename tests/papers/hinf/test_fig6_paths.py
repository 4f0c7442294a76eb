"""Why Fig 6's paths zig-zag (issue 28): the path statistics, the paired control variants and the cause rule."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from netrepro.pipeline.config import validate_config
from netrepro.errors import ConfigError
from netrepro.papers.hinf import evidence
from netrepro.papers.hinf.motion import path_statistics


def _path(steps_xy, start=(0.0, 0.0)):
    """One run, one agent: positions from a list of steps, shape (1, len + 1, 1, 2)."""
    pts = np.vstack([start, np.asarray(start) + np.cumsum(steps_xy, axis=0)])
    return pts[None, :, None, :]


def test_path_statistics_on_hand_made_paths():
    # back and forth: every pair of consecutive steps reverses; every step has length 1 = v_max (clipped)
    zig = path_statistics(_path([(1, 0), (-1, 0)] * 5), v_max=1.0)
    assert zig["reversal_fraction"][0] == 1.0 and zig["clipped_fraction"][0] == 1.0 and zig["mean_step"][0] == 1.0
    # a square: 90-degree turns are not reversals (the inner product is 0, not negative)
    square = path_statistics(_path([(1, 0), (0, 1), (-1, 0), (0, -1)]), v_max=2.0)
    assert square["reversal_fraction"][0] == 0.0 and square["clipped_fraction"][0] == 0.0
    # 2 reversals among 4 pairs: steps right, right, left(135 deg turn), left, right
    mixed = path_statistics(_path([(1, 0), (1, 0), (-1, 1), (-1, 1), (1, 0)]), v_max=np.sqrt(2))
    assert mixed["reversal_fraction"][0] == pytest.approx(2 / 4)
    assert mixed["clipped_fraction"][0] == pytest.approx(2 / 5)  # the two diagonal steps have length sqrt(2)
    assert mixed["mean_step"][0] == pytest.approx((3 + 2 * np.sqrt(2)) / 5)


def test_path_statistics_are_per_run_and_average_over_agents():
    a = _path([(1, 0), (-1, 0), (1, 0)])       # 2 reversals of 2
    b = _path([(0, 1), (0, 1), (0, 1)])        # none
    two_agents = np.concatenate([a, b], axis=2)              # one run, two agents: 2 of 4
    two_runs = np.concatenate([a, b], axis=0)                # two runs: 1 and 0
    assert path_statistics(two_agents, 5.0)["reversal_fraction"].tolist() == [0.5]
    assert path_statistics(two_runs, 5.0)["reversal_fraction"].tolist() == [1.0, 0.0]


def test_fig6_paths_step_pairs_the_variants(hinf_run):
    cfg, files = hinf_run
    table = pd.read_csv(files["fig6_paths"]).set_index("variant")
    fp = cfg["fig6_paths"]
    assert list(table.index) == ["nominal"] + [v["label"] for v in fp["variants"]]
    assert (table["runs"] == fp["runs"]).all()
    # steering by the truth takes every random number out of the agents' and the target's motion: the runs coincide
    assert table.loc["steer_on_truth", "reversal_se"] == 0.0
    # a tenth of the gain clips fewer steps than the nominal law (Gamma only scales the unclipped step)
    assert table.loc["control.Gamma=2000", "clipped_fraction"] < table.loc["nominal", "clipped_fraction"]
    # the paired difference is the difference of the means (same runs in both arms)
    for v in table.index[1:]:
        assert table.loc[v, "reversal_diff"] == pytest.approx(
            table.loc[v, "reversal_fraction"] - table.loc["nominal", "reversal_fraction"], abs=1e-12)
    paths = pd.read_csv(files["fig6_paths_run0"], dtype={"who": str})
    assert set(paths["who"]) == {"0", "1", "2", "3", "target"}
    assert set(paths["variant"]) == set(table.index)


def _table(truth_share, gain_share, gain_tag="holds"):
    nominal = 0.06
    rows = [("nominal", nominal, ""), ("steer_on_truth", truth_share * nominal, "holds"),
            ("control.Gamma=2000", gain_share * nominal, gain_tag)]
    return pd.DataFrame([{"variant": v, "runs": 20, "reversal_fraction": r, "reversal_se": 0.001,
                          "clipped_fraction": 0.5, "mean_step": 0.3, "topology_changes": 10.0, "error_late": 1.0,
                          "reversal_diff": r - nominal, "z": -5.0, "z_crit": 2.39, "tag": tag} for v, r, tag in rows])


AT = {"truth_variant": "steer_on_truth", "gain_variant": "control.Gamma=2000", "truth_keeps_at_least": 0.5,
      "gain_leaves_at_most": 0.2}


@pytest.mark.parametrize("truth, gain, tag, expected", [
    (0.9, 0.05, "holds", True),
    (0.4, 0.05, "holds", False),            # the truth removes most of the zig-zag: noise would be a cause
    (0.9, 0.3, "holds", False),             # the smaller gain leaves too much
    (0.9, 0.05, "not significant", False),  # ... or not significantly less
])
def test_cause_rule(truth, gain, tag, expected):
    rows = evidence._fig6_path_rows(_table(truth, gain, tag), AT)
    cause = [r for r in rows if r["quantity"] == "fig6.zigzag_cause"]
    assert len(cause) == 1 and cause[0]["value"] is expected
    assert {r.get("variant") for r in rows if r["quantity"] == "fig6.reversals"} == {None, "steer_on_truth",
                                                                                    "control.Gamma=2000"}


def test_bad_variant_key_is_refused_by_the_schema():
    cfg = yaml.safe_load((Path(__file__).resolve().parents[3] / "config" / "test.yaml").read_text())
    validate_config(cfg)
    cfg["hinf"]["fig6_paths"]["variants"][0]["control"] = {"gain": 2.0}
    with pytest.raises(ConfigError, match="gain"):
        validate_config(cfg)
