"""Seeded, chunked Monte Carlo whose result does not depend on how work is split.

Paths are grouped in fixed-size *blocks*. Block ``b`` draws from its own
generator ``default_rng(SeedSequence(seed, spawn_key=(b,)))``, so the random
numbers of a block depend only on ``(seed, b)``. A job (or shard, or chunk)
computes per-block sums for a range of blocks; blocks are always combined in
block order, so any split into jobs and chunks yields bit-identical results.

The simulation function has the signature ``fn(rng, n) -> dict[str, ndarray]``
returning per-path values (first axis = path). The driver keeps, per block and
key, the sum and the sum of squares over paths, plus the block maximum.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["block_rng", "n_blocks", "run_blocks", "merge_block_sums", "MonteCarloSums", "run_monte_carlo",
           "shard_blocks", "save_sums", "load_sums"]


def block_rng(seed: int, block: int) -> np.random.Generator:
    """The generator of block ``block`` under root seed ``seed``.

    Parameters
    ----------
    seed : int
        Root seed of the experiment.
    block : int
        Block index.

    Returns
    -------
    numpy.random.Generator
        ``default_rng(SeedSequence(seed, spawn_key=(block,)))``.
    """
    return np.random.default_rng(np.random.SeedSequence(int(seed), spawn_key=(int(block),)))


def n_blocks(n_paths: int, block_size: int) -> int:
    """Number of blocks of ``block_size`` paths that hold ``n_paths`` paths (the last may be short).

    Parameters
    ----------
    n_paths, block_size : int
        Positive path count and block size.

    Returns
    -------
    int
        ``ceil(n_paths / block_size)``.

    Raises
    ------
    ValueError
        If either argument is not positive.
    """
    if n_paths <= 0 or block_size <= 0:
        raise ValueError(f"n_paths and block_size must be positive, got {n_paths}, {block_size}")
    return -(-n_paths // block_size)


def _block_sizes(n_paths, block_size):
    nb = n_blocks(n_paths, block_size)
    sizes = np.full(nb, block_size)
    sizes[-1] = n_paths - block_size * (nb - 1)
    return sizes


@dataclass
class MonteCarloSums:
    """Per-block sums; combine with :func:`merge_block_sums`, read with :meth:`mean` / :meth:`ci`.

    Attributes
    ----------
    blocks : ndarray of int, shape ``(B,)``
        Block indices, in block order.
    counts : ndarray of int, shape ``(B,)``
        Paths per block.
    sums, sumsq, maxima : dict
        Key -> ``(B, ...)`` arrays: per-block sum, sum of squares and maximum over paths.
    """

    blocks: np.ndarray  # (B,) block indices
    counts: np.ndarray  # (B,)
    sums: dict  # key -> (B, ...)
    sumsq: dict
    maxima: dict

    @property
    def n(self) -> int:
        return int(self.counts.sum())

    def mean(self, key):
        return _ordered_sum(self.sums[key]) / self.n

    def std(self, key):
        """Sample standard deviation; inf where a path diverged (never inf - inf = NaN)."""
        m = self.mean(key)
        with np.errstate(invalid="ignore", over="ignore"):
            var = _ordered_sum(self.sumsq[key]) / self.n - m * m
            std = np.sqrt(np.maximum(var, 0.0) * self.n / max(self.n - 1, 1))
        return np.where(np.isinf(m), np.inf, std)

    def ci(self, key, level: float = 0.95):
        """Normal-approximation confidence interval of the mean: ``(mean, lo, hi)``."""
        m = self.mean(key)
        # imported here: shard jobs use this module without an interval, and scipy costs ~0.3 s of import
        from scipy.special import ndtri  # the normal quantile (scipy.stats would cost ~1 s)

        half = ndtri(0.5 + level / 2) * self.std(key) / np.sqrt(self.n)
        with np.errstate(invalid="ignore"):
            lo = np.where(np.isinf(m), m, m - half)
        return m, lo, m + half

    def maximum(self, key):
        return np.max(self.maxima[key], axis=0)


def _ordered_sum(arr):
    # a fixed left-to-right order over blocks: independent of how blocks were chunked
    total = np.zeros_like(arr[0])
    for row in arr:
        total = total + row
    return total


def run_blocks(fn, n_paths: int, block_size: int, seed: int, blocks=None, chunk_blocks: int = 1) -> MonteCarloSums:
    """Run blocks ``blocks`` (default: all) of a Monte Carlo experiment.

    ``chunk_blocks`` blocks' worth of paths are simulated per call of ``fn``
    only when it does not change results: each block still uses its own
    generator, so chunking here only groups the bookkeeping.

    Parameters
    ----------
    fn : callable
        ``fn(rng, n) -> dict[str, ndarray]``, per-path values (first axis = path).
    n_paths, block_size : int
        Total paths and paths per block.
    seed : int
        Root seed (:func:`block_rng`).
    blocks : iterable of int or None
        Which blocks to run (default: all).
    chunk_blocks : int
        Bookkeeping grouping (no effect on results).

    Returns
    -------
    MonteCarloSums
        The per-block sums of the blocks run.
    """
    sizes = _block_sizes(n_paths, block_size)
    blocks = np.arange(len(sizes)) if blocks is None else np.asarray(list(blocks), dtype=int)
    sums, sumsq, maxima = {}, {}, {}
    for i, b in enumerate(blocks):
        values = fn(block_rng(seed, b), int(sizes[b]))
        for key, val in values.items():
            val = np.asarray(val, dtype=float)
            with np.errstate(over="ignore", invalid="ignore"):
                s, s2 = val.sum(axis=0), (val * val).sum(axis=0)
            mx = val.max(axis=0)
            if key not in sums:
                shape = (len(blocks),) + s.shape
                sums[key], sumsq[key], maxima[key] = np.empty(shape), np.empty(shape), np.empty(shape)
            sums[key][i], sumsq[key][i], maxima[key][i] = s, s2, mx
    return MonteCarloSums(blocks=blocks, counts=sizes[blocks], sums=sums, sumsq=sumsq, maxima=maxima)


def merge_block_sums(parts) -> MonteCarloSums:
    """Merge partial results (e.g. from shards), ordering by block index.

    Parameters
    ----------
    parts : iterable of MonteCarloSums
        Results over disjoint sets of blocks, with the same keys. A part without blocks (a shard
        that got none, when there are more shards than blocks) has no keys and is left out.

    Returns
    -------
    MonteCarloSums
        All blocks, in block order.

    Raises
    ------
    ValueError
        If a block appears in two parts, or no part is given.
    """
    given = list(parts)
    if not given:
        raise ValueError("merge_block_sums: no part to merge")
    parts = [p for p in given if len(p.blocks)] or given[:1]
    blocks = np.concatenate([p.blocks for p in parts])
    order = np.argsort(blocks, kind="stable")
    if len(np.unique(blocks)) != len(blocks):
        raise ValueError("merge_block_sums: the same block appears in two parts")
    keys = parts[0].sums.keys()
    cat = lambda attr, k: np.concatenate([getattr(p, attr)[k] for p in parts])[order]  # noqa: E731
    return MonteCarloSums(
        blocks=blocks[order],
        counts=np.concatenate([p.counts for p in parts])[order],
        sums={k: cat("sums", k) for k in keys},
        sumsq={k: cat("sumsq", k) for k in keys},
        maxima={k: cat("maxima", k) for k in keys},
    )


def run_monte_carlo(fn, n_paths: int, block_size: int, seed: int, n_chunks: int = 1) -> MonteCarloSums:
    """All blocks, split into ``n_chunks`` contiguous chunks and merged (same result for any ``n_chunks``).

    Parameters
    ----------
    fn : callable
        ``fn(rng, n) -> dict[str, ndarray]`` (see :func:`run_blocks`).
    n_paths, block_size : int
        Total paths and paths per block.
    seed : int
        Root seed.
    n_chunks : int
        Number of chunks (no effect on results).

    Returns
    -------
    MonteCarloSums
        Every block's sums.
    """
    nb = n_blocks(n_paths, block_size)
    chunks = np.array_split(np.arange(nb), max(1, min(n_chunks, nb)))
    return merge_block_sums(run_blocks(fn, n_paths, block_size, seed, blocks=c) for c in chunks if len(c))


def shard_blocks(n_paths: int, block_size: int, n_shards: int, shard: int) -> np.ndarray:
    """Block indices of shard ``shard`` (0-based) when all blocks are split into ``n_shards`` contiguous shards.

    Parameters
    ----------
    n_paths, block_size : int
        Total paths and paths per block.
    n_shards : int
        Number of shards.
    shard : int
        This shard, ``0 <= shard < n_shards``.

    Returns
    -------
    ndarray of int
        The shard's block indices.

    Raises
    ------
    ValueError
        If ``shard`` is out of range.
    """
    if not 0 <= shard < n_shards:
        raise ValueError(f"shard must be in [0, {n_shards}), got {shard}")
    return np.array_split(np.arange(n_blocks(n_paths, block_size)), n_shards)[shard]


def save_sums(path, named: dict) -> None:
    """Write several :class:`MonteCarloSums` (name -> sums) to one ``.npz`` file, atomically.

    Parameters
    ----------
    path : str or Path
        The ``.npz`` file.
    named : dict
        Name -> :class:`MonteCarloSums` (names and keys must not contain ``|``).
    """
    from ..pipeline.io import atomic_path

    arrays = {}
    for name, res in named.items():
        arrays[f"{name}|blocks"] = res.blocks
        arrays[f"{name}|counts"] = res.counts
        for attr in ("sums", "sumsq", "maxima"):
            for key, val in getattr(res, attr).items():
                arrays[f"{name}|{attr}|{key}"] = val
    with atomic_path(path) as tmp:
        with open(tmp, "wb") as fh:
            np.savez(fh, **arrays)


def load_sums(path) -> dict:
    """Inverse of :func:`save_sums`.

    Parameters
    ----------
    path : str or Path
        A file written by :func:`save_sums`.

    Returns
    -------
    dict
        Name -> :class:`MonteCarloSums`.
    """
    out = {}
    with np.load(path) as data:
        for full in data.files:
            parts = full.split("|")
            entry = out.setdefault(parts[0], {"sums": {}, "sumsq": {}, "maxima": {}})
            if len(parts) == 2:
                entry[parts[1]] = data[full]
            else:
                entry[parts[1]][parts[2]] = data[full]
    return {name: MonteCarloSums(e["blocks"], e["counts"], e["sums"], e["sumsq"], e["maxima"]) for name, e in out.items()}
