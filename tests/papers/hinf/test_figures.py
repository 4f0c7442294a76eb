"""Every `hinf` plotting function on the tables of a tiny run: a non-empty file is written."""

from __future__ import annotations

import pytest

from netrepro.pipeline.figurespec import load_figure_specs
from netrepro.papers.hinf import figures

SPECS = load_figure_specs("hinf")
INPUT_FILES = {  # figures.yaml input (rule[.output]) -> file of the tiny run
    "noise_model": "noise_model", "tables.errors": "errors", "tables.single": "single",
    "tables.trajectories": "trajectories", "tables.summary": "summary", "sensitivity": "sensitivity",
    "sensitivity_evasive": "sensitivity_evasive", "consensus_check": "consensus", "fig2_horizon": "per_agent",
    "fig2_horizon.series": "series", "paired_evasive": "paired_evasive", "network": "network",
    "network.connectivity": "connectivity", "loop_variants": "loop_variants", "loop_swap": "loop_swap", "kalman_best": "kalman_best",
    "fig6_paths": "fig6_paths", "fig6_paths.paths": "fig6_paths_run0",
}


def test_every_listed_function_exists():
    assert {s.plot for s in SPECS} <= set(figures.__all__)
    assert set(figures.__all__) <= {s.plot for s in SPECS}


@pytest.mark.parametrize("spec", SPECS, ids=[s.figure_id for s in SPECS])
def test_figure_written(spec, hinf_run, tmp_path):
    _, files = hinf_run
    inputs = {name: files[INPUT_FILES[ref]] for name, ref in spec.inputs.items()}
    out = tmp_path / f"{spec.figure_id}.png"
    getattr(figures, spec.plot)(spec.params, inputs, {"figure": out})
    assert out.is_file() and out.stat().st_size > 1000
