"""Every plotting function of `markov` on the tiny tables: a non-empty figure file."""

from __future__ import annotations

import pytest

from netrepro.pipeline.figurespec import load_figure_specs
from netrepro.papers.markov import figures


@pytest.mark.parametrize("spec", load_figure_specs("markov"), ids=lambda s: s.figure_id)
def test_figure(spec, markov_tables, tmp_path):
    names = {"critical_curves": "curves", "stability_map": "map", "iid_line": "iid", "sample_paths": "paths",
             "sample_paths.check": "check", "expectations": "expectations"}
    inputs = {name: markov_tables[names[ref]] for name, ref in spec.inputs.items()}
    out = tmp_path / f"{spec.figure_id}.png"
    getattr(figures, spec.plot)(spec.params, inputs, {"figure": out})
    assert out.stat().st_size > 1000
