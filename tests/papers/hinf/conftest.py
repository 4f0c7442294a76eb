"""A tiny run of every `hinf` step, shared by the step, evidence and figure tests."""

from __future__ import annotations

import copy
from pathlib import Path

import pandas as pd
import pytest
import yaml

from netrepro.papers.hinf import steps
from netrepro.papers.hinf.model import SCENARIOS

ROOT = Path(__file__).resolve().parents[3]


def tiny_section() -> dict:
    """config/test.yaml's hinf section, shrunk further (few runs, short horizons, small sweeps)."""
    sec = copy.deepcopy(yaml.safe_load((ROOT / "config" / "test.yaml").read_text())["hinf"])
    for sc in sec["scenarios"].values():
        sc["runs"], sc["horizon"] = 6, 40
    sec["noise_check"]["n_samples"] = 20000
    sec["errata"]["n_samples"] = 20000
    sec["attenuation"].update(horizon=30, runs=3)
    sv = sec["sensitivity"]
    sv.update(runs=4, horizon=30, gamma=[1.5, 3.0], gamma_c=[0.5], K_p=[0.4], K_i=[0.2], h=[0.5], iters=[1])
    sec["claims"]["late_start"] = 20
    sec["paired"].update(runs=6)
    sec["fig2_horizon"].update(runs=4, horizons=[30, 40], scenarios=["fig2", "fig3"])
    sec["loop_variants"].update(runs=4, reconstructions=sec["loop_variants"]["reconstructions"][::2])
    sec["kalman_best"].update(select_runs=3, judge_runs=4, W_factors=[1.0, 2.0], gamma_factors=[1.05])
    sec["loop_swap"].update(runs=4, settings=sec["loop_swap"]["settings"][:2])
    return sec


def run_sharded(shard_step, merge_step, cfg, n_shards, d, name):
    """The shards of a sharded step and its merge; returns the merge's tables."""
    paths = []
    for shard in range(n_shards):
        path = d / f"{name}_shard{shard}of{n_shards}.csv"
        shard_step({"cfg": cfg, "shard": shard, "n_shards": n_shards}, {}, {})["table"].to_csv(path, index=False)
        paths.append(path)
    return merge_step(cfg, {"shards": paths}, {})


def _write(tables: dict, outputs: dict) -> None:
    for key, path in outputs.items():
        tables[key].to_csv(path, index=False)


@pytest.fixture(scope="session")
def hinf_run(tmp_path_factory):
    """``(section, {name: path})`` of every table of a tiny run."""
    cfg = tiny_section()
    d = tmp_path_factory.mktemp("hinf")
    files = {}

    def run(fn, params, inputs, names):
        outs = {n: d / f"{fn.__name__}_{n}.csv" for n in names}
        _write(fn(params, inputs, outs), outs)
        files.update(outs)

    run(steps.noise_model_step, cfg, {}, ["table", "fit"])
    files["noise_model"], files["noise_fit"] = files.pop("table"), files.pop("fit")
    run(steps.consensus_check_step, cfg, {}, ["table"])
    files["consensus"] = files.pop("table")
    run(steps.attenuation_step, cfg, {}, ["table", "checks"])
    files["attenuation"] = files.pop("table")
    pieces = {}
    for scen in SCENARIOS:
        tabs = steps.simulate_step({"scenario": scen, "cfg": cfg}, {}, {})
        for kind in ("errors", "single", "trajectories", "summary", "per_run"):
            p = d / f"sim_{scen}_{kind}.csv"
            tabs[kind].to_csv(p, index=False)
            pieces[f"{kind}_{scen}"] = p
        files[f"per_run_{scen}"] = pieces[f"per_run_{scen}"]
    run(steps.tables_step, {}, pieces, ["errors", "single", "trajectories", "summary", "paired"])
    run(steps.sensitivity_step, cfg, {}, ["table"])
    files["sensitivity"] = files.pop("table")
    run(steps.sensitivity_evasive_step, cfg, {}, ["table"])
    files["sensitivity_evasive"] = files.pop("table")
    run(steps.paired_evasive_step, cfg, {}, ["table"])
    files["paired_evasive"] = files.pop("table")
    run(steps.fig2_horizon_step, cfg, {}, ["table", "series", "modes"])
    files["per_agent"] = files.pop("table")
    paired = files["paired"]
    run(steps.evader_check_step, cfg, {}, ["table", "paired"])
    files["evader"], files["evader_paired"] = files.pop("table"), files.pop("paired")
    files["paired"] = paired
    run(steps.fig5_control_step, cfg, {}, ["table"])
    files["fig5_control"] = files.pop("table")
    run(steps.evasive_network_step, cfg, {}, ["table"])
    files["evasive_network"] = files.pop("table")
    for name, shard_step, merge_step in (("loop_variants", steps.loop_variants_shard_step, steps.loop_variants_merge_step),
                                         ("loop_swap", steps.loop_swap_shard_step, steps.loop_swap_merge_step),
                                         ("kalman_best", steps.kalman_best_shard_step, steps.kalman_best_merge_step)):
        files[name] = d / f"{name}.csv"
        merged = run_sharded(shard_step, merge_step, cfg, 2, d, name)
        merged["table"].to_csv(files[name], index=False)
        if "fused" in merged:
            files["evader_fused"] = d / "evader_fused.csv"
            merged["fused"].to_csv(files["evader_fused"], index=False)
        if "runs" in merged:
            files[f"{name}_runs"] = d / f"{name}_runs.csv"
            merged["runs"].to_csv(files[f"{name}_runs"], index=False)
    run(steps.network_step, cfg, {"trajectories": files["trajectories"]}, ["table", "connectivity"])
    files["network"] = files.pop("table")
    run(steps.fig6_paths_step, cfg, {}, ["table", "paths"])
    files["fig6_paths"], files["fig6_paths_run0"] = files.pop("table"), files.pop("paths")
    return cfg, files


def read(files, name) -> pd.DataFrame:
    return pd.read_csv(files[name])
