"""Issue 37: the fixed-path swap, the replayed evader, the registered Kalman band and the stroke statistics."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from netrepro.errors import InputError
from netrepro.papers.hinf import steps
from netrepro.papers.hinf.evidence import registered_band, swap_verdicts
from netrepro.papers.hinf.model import bonferroni_z, resolve_scenario, simulate, window_means
from netrepro.papers.hinf.motion import path_statistics

from .conftest import tiny_section


def test_design_consensus_maps_p_only_to_pi_without_integral_gain():
    assert steps.design_consensus("p_only") == {"K_i": 0.0, "design": "pi"}
    assert steps.design_consensus("pi_reset") == {"design": "pi_reset"}


@pytest.fixture(scope="module")
def swap_runs():
    cfg = tiny_section()
    cfg["loop_swap"].update(runs=3, settings=[{"label": "nominal", "loops": ["pi", "p_only"]}])
    cfg["scenarios"]["evasive_hinf"]["horizon"] = 30
    return cfg, steps.loop_swap_shard_step({"cfg": cfg, "shard": 0, "n_shards": 1}, {}, {})["table"]


def _closed(cfg, design, driver="decentralized"):
    """An independent closed loop: the decentralized filter of ``design`` only, with its driver."""
    sc = resolve_scenario(cfg, "evasive_hinf", runs=3, seed=int(cfg["loop_swap"]["seed"]),
                          consensus=steps.design_consensus(design))
    sc.update(target="evasive", filters=["local", "decentralized"], driver=driver)
    out = simulate(sc)
    start = int(cfg["claims"]["late_start"])
    return {"local": window_means(out["errors"]["local"], start), design: window_means(out["errors"]["decentralized"], start)}


def test_each_design_on_its_own_loop_equals_its_closed_loop(swap_runs):
    cfg, runs = swap_runs
    for loop in ("pi", "p_only"):
        ref = _closed(cfg, loop)
        got = runs[runs["loop"] == loop].set_index(["filter", "run"])["error"]
        np.testing.assert_array_equal(got.loc[loop].to_numpy(), ref[loop])
        np.testing.assert_array_equal(got.loc["local"].to_numpy(), ref["local"])


def test_a_design_on_another_loops_paths_keeps_its_own_gains(swap_runs):
    # on the p_only loop's paths the PI design must use K_i of the configuration, not the loop's K_i = 0: it then
    # differs from p_only on the same paths (the same value would mean the variant inherited the loop's gains)
    cfg, runs = swap_runs
    g = runs[runs["loop"] == "p_only"].set_index(["filter", "run"])["error"]
    assert float(cfg["consensus"]["K_i"]) > 0
    assert not np.array_equal(g.loc["pi"].to_numpy(), g.loc["p_only"].to_numpy())
    # and the local loop's filters are those of a loop the local filters close
    ref = _closed(cfg, "pi", driver="local")
    loc = runs[runs["loop"] == "local_loop"].set_index(["filter", "run"])["error"]
    np.testing.assert_array_equal(loc.loc["pi"].to_numpy(), ref["pi"])


def _synthetic_runs():
    rng = np.random.default_rng(5)
    rows = []
    for loop in ("pi", "pi_reset", "local_loop"):
        for f in ("local", "pi", "pi_reset"):
            for r in range(6):
                rows.append({"setting": "s", "loop": loop, "filter": f, "run": r, "error": rng.uniform(),
                             "connected_fraction": 0.5, "topology_changes": 3})
    return pd.DataFrame(rows)


def test_swap_comparisons_against_hand_computed_pairs():
    runs = _synthetic_runs()
    t = steps.swap_comparisons(runs, ["pi", "pi_reset"], 0.05)
    # per loop: 2 fixed_paths + 1 vs pi (3 loops); 2 system, 1 system_vs_pi, 2 steering_local
    assert len(t) == 3 * 3 + 2 + 1 + 2
    assert t["z_crit"].iloc[0] == pytest.approx(bonferroni_z(0.05, len(t)))
    e = runs.set_index(["loop", "filter", "run"])["error"].sort_index()
    sys_row = t[(t["comparison"] == "system") & (t["design"] == "pi")].iloc[0]
    # the PI loop's own decentralized filter is filter "pi" on loop "pi"
    d = e.loc[("pi", "pi")].to_numpy() - e.loc[("local_loop", "local")].to_numpy()
    assert sys_row["mean_diff"] == pytest.approx(d.mean())
    assert sys_row["se"] == pytest.approx(d.std(ddof=1) / math.sqrt(len(d)))
    st = t[(t["comparison"] == "steering_local") & (t["loop"] == "pi_reset")].iloc[0]
    assert st["mean_diff"] == pytest.approx((e.loc[("pi_reset", "local")] - e.loc[("local_loop", "local")]).mean())


def test_swap_verdicts_follow_the_tags():
    rows = [("fixed_paths", "pi", "pi", "reversed"), ("fixed_paths", "pi", "p_only", "holds"),
            ("fixed_paths", "local_loop", "pi", "holds"), ("fixed_paths", "local_loop", "p_only", "holds"),
            ("steering_local", "pi", "pi", "holds")]
    sw = pd.DataFrame([{"setting": "s", "comparison": c, "loop": lp, "design": d, "tag": tag} for c, lp, d, tag in rows])
    v = swap_verdicts(sw)
    assert v["loss_on_own_paths"]["s"] is True and v["steering_lowers_local"]["s"] is True
    sw.loc[3, "tag"] = "not significant"  # one design not significantly better on the local loop's paths
    sw.loc[4, "tag"] = "reversed"
    v = swap_verdicts(sw)
    assert v["loss_on_own_paths"]["s"] is False and v["steering_lowers_local"]["s"] is False


def _kb(z_band=10.0, z_w=-10.0, z_best=10.0):
    rows = []
    for kind in ("local", "decentralized"):
        rows.append({"target": "evasive", "kind": kind, "comparison": "gamma=3 vs W_f=1", "W_factor_b": 1.0, "z": z_w})
        for f in (1.5, 2.0, 3.0, 5.0, 8.0):
            rows.append({"target": "evasive", "kind": kind, "comparison": f"gamma=3 vs W_f={f:g}", "W_factor_b": f,
                         "z": z_band if f <= 5 else -50.0})
        rows.append({"target": "evasive", "kind": kind, "comparison": "best vs best", "W_factor_b": 8.0, "z": z_best})
    return pd.DataFrame(rows)


def test_registered_band_family_and_decision():
    b = registered_band(_kb(), 0.05)
    assert b["family"]["evasive"] == 12  # W, 1.5-5 W (4), best vs best, per kind; 8 W exploratory
    assert b["z_crit"]["evasive"] == pytest.approx(bonferroni_z(0.05, 12))
    assert b["holds"]["evasive"] is True  # W_f = 8 (z = -50) is outside the band and not judged
    zc = b["z_crit"]["evasive"]
    assert registered_band(_kb(z_band=zc - 0.01), 0.05)["holds"]["evasive"] is False
    assert registered_band(_kb(z_w=-zc + 0.01), 0.05)["holds"]["evasive"] is False
    assert registered_band(_kb(z_best=zc - 0.01), 0.05)["holds"]["evasive"] is False


def test_replayed_evader_is_a_recorded_evader_path_that_does_not_react():
    cfg = tiny_section()
    sc = resolve_scenario(cfg, "evasive_hinf", runs=2, horizon=60, seed=7)
    with pytest.raises(InputError, match="own seed"):
        steps.recorded_evader_paths(sc, 7)
    path = steps.recorded_evader_paths(sc, 8)
    own = simulate({**sc, "target": "evasive", "seed": 8, "filters": [sc["driver"]]})
    np.testing.assert_array_equal(path, own["target"])  # the closed loop of seed 8
    steps_len = np.linalg.norm(np.diff(path, axis=1), axis=-1)
    np.testing.assert_allclose(steps_len, sc["evader"]["step"], rtol=1e-9)  # an evader's step every time
    replay = simulate({**sc, "target": "replay", "target_path": path, "filters": [sc["driver"]]})
    react = simulate({**sc, "target": "evasive", "filters": [sc["driver"]]})
    np.testing.assert_array_equal(replay["target"], path)
    # the runs' own agents go elsewhere (their noise differs from the recording's) and the path does not follow them
    assert not np.allclose(replay["agents"], react["agents"])
    assert not np.allclose(path, react["target"])


def _one(points):
    return np.asarray(points, dtype=float)[None, :, None, :]


def test_strokes_and_tangential_share_on_hand_made_paths():
    # reversals at pairs 1, 4, 6 (steps: r r l l l r r l): strokes of 3 and 2 steps
    xs = [(1, 0), (1, 0), (-1, 0), (-1, 0), (-1, 0), (1, 0), (1, 0), (-1, 0)]
    pts = np.vstack([[0, 0], np.cumsum(xs, axis=0)])
    st = path_statistics(_one(pts), v_max=1.0)
    assert st["stroke_median"][0] == 2.5 and st["one_step_strokes"][0] == 0.0
    zig = path_statistics(_one(np.vstack([[0, 0], np.cumsum([(1, 0), (-1, 0)] * 3, axis=0)])), v_max=1.0)
    assert zig["stroke_median"][0] == 1.0 and zig["one_step_strokes"][0] == 1.0
    # an agent on a circle about a fixed target moves across the line of sight; straight at it, along it
    ang = np.linspace(0, 1, 6)
    circle = np.stack([10 * np.cos(ang), 10 * np.sin(ang)], -1)
    tgt = np.zeros((1, 6, 2))
    assert path_statistics(_one(circle), 5.0, tgt)["tangential_share"][0] == pytest.approx(
        np.cos(0.1) ** 2, rel=1e-9)  # a chord: cos^2 of half the angle it subtends
    radial = np.stack([np.linspace(10, 5, 6), np.zeros(6)], -1)
    assert path_statistics(_one(radial), 5.0, tgt)["tangential_share"][0] == pytest.approx(0.0, abs=1e-15)


def test_fused_trace_along_an_evaders_path_is_the_value_it_maximised():
    from netrepro.papers.hinf.evader import fused_trace_along

    cfg = tiny_section()
    sc = resolve_scenario(cfg, "evasive_hinf", runs=2, horizon=20, seed=3)
    out = simulate({**sc, "target": "evasive", "filters": [sc["driver"]]})
    # the evader records the value of the move it chose (evader_move); recomputed here from the paths alone
    np.testing.assert_allclose(fused_trace_along(out["target"], out["agents"], sc["model"]), out["fused_trace"][:, 1:],
                               rtol=1e-12)


def test_fused_comparisons_pair_the_targets_by_run():
    rows = []
    for t, base in (("evasive", 2.0), ("evader_replay", 1.0), ("random", 0.5)):
        for lab in ("a", "b"):
            for r in range(5):
                rows.append({"target": t, "phase": "judge", "label": lab, "run": r, "fused_trace": base + 0.1 * r})
    rows.append({"target": "evasive", "phase": "select", "label": "a", "run": 0, "fused_trace": 99.0})
    t = steps.fused_comparisons(pd.DataFrame(rows), 0.05).set_index("target_b")
    assert list(t.index) == ["evader_replay", "random"]
    assert t.loc["evader_replay", "mean_diff"] == pytest.approx(1.0) and t.loc["random", "mean_diff"] == pytest.approx(1.5)
    assert t.loc["random", "fused_a"] == pytest.approx(2.2)  # judge runs only


def test_steering_decision_is_every_setting():
    from netrepro.papers.hinf.evidence import _swap_rows

    rows = []
    for setting, tag in (("nominal", "holds"), ("other", "reversed")):
        for comp, loop, design in (("fixed_paths", "pi", "pi"), ("fixed_paths", "local_loop", "pi"),
                                   ("steering_local", "pi", "pi"), ("system", "pi", "pi")):
            rows.append({"setting": setting, "comparison": comp, "loop": loop, "design": design, "pairing": "seed",
                         "runs": 5, "error_a": 1.0, "error_b": 1.0, "mean_diff": 0.1, "se": 0.01, "z": 10.0,
                         "frac_a_better": 0.5, "connected_fraction": 0.5, "topology_changes": 3.0, "z_crit": 3.0,
                         "tag": tag if comp == "steering_local" else "holds"})
    ev = {(r["quantity"], r.get("variant", "nominal")): r["value"] for r in _swap_rows(pd.DataFrame(rows))}
    assert ev[("loop.steering_lowers_local", "nominal")] is False  # one setting fails: the rule fails
    assert ev[("loop.steering_lowers_local", "setting nominal")] is True
