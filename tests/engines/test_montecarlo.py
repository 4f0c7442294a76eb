import numpy as np
import pytest

from netrepro.engines.montecarlo import merge_block_sums, run_blocks, run_monte_carlo


def _sim(rng, n):
    x = rng.exponential(2.0, size=(n, 3))
    return {"x": x, "x2": x**2}


@pytest.mark.parametrize("chunks", [1, 2, 3, 7])
def test_result_independent_of_chunking(chunks):
    ref = run_monte_carlo(_sim, 10_000, 700, seed=5, n_chunks=1)
    got = run_monte_carlo(_sim, 10_000, 700, seed=5, n_chunks=chunks)
    assert np.array_equal(ref.mean("x"), got.mean("x"))
    assert np.array_equal(ref.std("x2"), got.std("x2"))


def test_shards_merged_in_any_order_equal_single_run():
    ref = run_monte_carlo(_sim, 5000, 500, seed=9)
    parts = [run_blocks(_sim, 5000, 500, 9, blocks=b) for b in ([7, 8, 9], [0, 1, 2, 3], [4, 5, 6])]
    merged = merge_block_sums(parts)
    assert np.array_equal(ref.mean("x"), merged.mean("x"))
    with pytest.raises(ValueError, match="same block"):
        merge_block_sums([parts[0], parts[0]])


def test_parts_without_blocks_are_left_out_of_the_merge():
    # more shards than blocks: some shards get no block (and no keys); first, middle or all empty
    ref = run_monte_carlo(_sim, 5000, 500, seed=9)
    empty = run_blocks(_sim, 5000, 500, 9, blocks=[])
    assert len(empty.blocks) == 0 and not empty.sums
    full = [run_blocks(_sim, 5000, 500, 9, blocks=b) for b in ([0, 1, 2, 3, 4], [5, 6, 7, 8, 9])]
    for parts in ([empty] + full, [full[0], empty, full[1]], full + [empty, empty]):
        merged = merge_block_sums(parts)
        assert np.array_equal(merged.blocks, ref.blocks) and np.array_equal(ref.std("x2"), merged.std("x2"))
    assert len(merge_block_sums([empty, empty]).blocks) == 0
    with pytest.raises(ValueError, match="no part"):
        merge_block_sums([])


def test_mean_and_interval_cover_truth():
    res = run_monte_carlo(_sim, 200_000, 20_000, seed=1)
    m, lo, hi = res.ci("x")
    assert np.all((lo < 2.0) & (2.0 < hi))
    assert np.allclose(m, 2.0, atol=0.02)
    assert res.n == 200_000


def test_different_seeds_differ():
    a = run_monte_carlo(_sim, 1000, 100, seed=1).mean("x")
    b = run_monte_carlo(_sim, 1000, 100, seed=2).mean("x")
    assert not np.array_equal(a, b)


def test_shards_saved_and_loaded_merge_to_single_run(tmp_path):
    from netrepro.engines.montecarlo import load_sums, save_sums, shard_blocks

    ref = run_monte_carlo(_sim, 3000, 400, seed=4)
    for shard in range(3):
        part = run_blocks(_sim, 3000, 400, 4, blocks=shard_blocks(3000, 400, 3, shard))
        save_sums(tmp_path / f"s{shard}.npz", {"a": part})
    merged = merge_block_sums(load_sums(tmp_path / f"s{i}.npz")["a"] for i in (2, 0, 1))
    assert np.array_equal(ref.mean("x"), merged.mean("x")) and merged.n == 3000
