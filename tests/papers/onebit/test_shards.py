"""Tests of netrepro.papers.onebit.shards: case bookkeeping and the merge of shard files."""

from __future__ import annotations

import numpy as np
import pytest

from netrepro.papers.onebit import shards


def _params():
    return {"estimator": {"one_minus_alpha": [1e-3, 1e-2], "snr_db": [0.0, 2.5], "n_runs": 6, "seed": 100,
                          "crossing": {"one_minus_alpha": [1e-2], "snr_db": [1.0, 2.0, 3.0], "n_runs": 4, "seed": 7,
                                       "degree": 2}}}


def test_cases_keys_seeds_and_sets():
    cases = shards.estimator_cases(_params())
    grid = [c for c in cases if c.case_set == "grid"]
    cross = [c for c in cases if c.case_set == "crossing"]
    assert [c.key for c in grid] == ["a0s0", "a0s1", "a1s0", "a1s1"]
    assert [c.seed for c in grid] == [100, 101, 1100, 1101]          # seed + 1000 i + j
    assert [(c.key, c.seed, c.n_runs) for c in cross] == [("c0s0", 7, 4), ("c0s1", 8, 4), ("c0s2", 9, 4)]
    p = _params()
    p["estimator"].pop("crossing")
    assert all(c.case_set == "grid" for c in shards.estimator_cases(p))


def _shard(path, key, blocks, counts, start):
    arrays = {f"{key}|blocks": np.asarray(blocks), f"{key}|counts": np.asarray(counts)}
    n = int(sum(counts))
    for j, kind in enumerate(shards.ESTIMATOR_KINDS):
        arrays[f"{key}|{kind}"] = np.arange(start, start + n, dtype=float) + 100 * j
    np.savez(path, **arrays)


def test_merge_is_in_block_order_whatever_the_shards(tmp_path):
    # blocks 0, 1 (2 runs each) in the second file, block 2 (1 run) in the first
    _shard(tmp_path / "a.npz", "k", [2], [1], 4)
    _shard(tmp_path / "b.npz", "k", [0, 1], [2, 2], 0)
    out = shards.merged_runs([tmp_path / "a.npz", tmp_path / "b.npz"], "k", with_blocks=True)
    np.testing.assert_array_equal(out["filter_1bit"], [0, 1, 2, 3, 4])
    np.testing.assert_array_equal(out["block"], [0, 0, 1, 1, 2])
    assert "block" not in shards.merged_runs([tmp_path / "b.npz"], "k")
    with pytest.raises(ValueError, match="appears twice"):
        shards.merged_runs([tmp_path / "b.npz", tmp_path / "b.npz"], "k")
