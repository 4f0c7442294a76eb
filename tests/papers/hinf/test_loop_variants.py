"""Issue 28: the consensus designs, the control targets, the Kalman design-W copies and the sharded steps."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from netrepro.errors import InputError
from netrepro.papers.hinf import steps
from netrepro.papers.hinf.model import resolve_scenario, simulate

from .conftest import run_sharded, tiny_section


def _static(design, **kw):
    cfg = tiny_section()
    sc = resolve_scenario(cfg, "fig2", runs=3, horizon=25, consensus={"design": design}, **kw)
    sc["filters"] = ["local", "decentralized", "centralized"]
    return simulate(sc)


def test_reset_design_equals_pi_when_the_graph_never_changes():
    # stationary agents: no topology change, so resetting the integral states at changes changes nothing
    a, b = _static("pi"), _static("pi_reset")
    assert int(b["topology_changes"].sum()) == 0
    np.testing.assert_array_equal(a["errors"]["decentralized"], b["errors"]["decentralized"])


def test_exact_component_on_a_connected_graph_is_the_centralized_filter():
    # the Fig-2 path graph is connected: the exact sums are the centralized information, eq (9) = eq (6)
    out = _static("exact_component")
    dec, cen = out["errors"]["decentralized"], out["errors"]["centralized"]
    np.testing.assert_allclose(dec, np.broadcast_to(cen, dec.shape), rtol=0, atol=1e-9)


def test_unknown_design_is_refused():
    with pytest.raises(InputError, match="unknown consensus design"):
        _static("median")


def test_drift_target_moves_straight_with_the_evader_step():
    cfg = tiny_section()
    sc = resolve_scenario(cfg, "evasive_hinf", runs=3, horizon=10)
    sc["target"] = "drift"
    out = simulate(sc)
    steps_ = np.diff(out["target"], axis=1)
    np.testing.assert_allclose(np.linalg.norm(steps_, axis=-1), sc["evader"]["step"], rtol=1e-12)
    np.testing.assert_allclose(steps_, np.broadcast_to(steps_[:, :1], steps_.shape), atol=1e-12)


def test_kalman_copy_with_its_own_W_matches_a_run_designed_for_that_W():
    cfg = tiny_section()
    sc = resolve_scenario(cfg, "fig2", runs=3, horizon=20)
    sc["filters"] = ["kalman_local", "copy"]
    out = simulate({**sc, "filter_base": {"copy": "kalman_local"}, "filter_W_factor": {"copy": 3.0}})
    ref = simulate({**sc, "filters": ["kalman_local"], "W_filter": 3.0 * np.asarray(sc["W_filter"])})
    np.testing.assert_array_equal(out["errors"]["copy"], ref["errors"]["kalman_local"])


@pytest.mark.parametrize("name, shard_step, merge_step", [
    ("loop_variants", steps.loop_variants_shard_step, steps.loop_variants_merge_step),
    ("kalman_best", steps.kalman_best_shard_step, steps.kalman_best_merge_step)])
def test_sharded_results_do_not_depend_on_the_shard_count(tmp_path, name, shard_step, merge_step):
    cfg = tiny_section()
    one = run_sharded(shard_step, merge_step, cfg, 1, tmp_path, name)["table"]
    three = run_sharded(shard_step, merge_step, cfg, 3, tmp_path, name)["table"]
    pd.testing.assert_frame_equal(one, three)
