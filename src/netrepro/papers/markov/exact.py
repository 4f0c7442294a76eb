"""Exact ``E||P_k||`` and ``E tr P_k`` over all channel paths of the Gilbert-Elliott channel (eq. 3),
as polynomials in ``(p, 1-p, q, 1-q)`` (binary tree of covariances, aggregated by transition counts).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...errors import InputError
from .model import LinearSystem, batched_trace, riccati_g, riccati_h, sym_norm

__all__ = ["ExactMoments", "exact_moments", "BlockSplit", "example2_split", "exact_moments_split", "find_split", "exact_moments_auto"]


def _branch_channel(state, counts):
    """Every path splits into a reception (first half) and a loss (second half).

    ``state`` is the last channel state of each path (True = received); ``counts[:, i]``
    counts its transitions 11 -> 0, 10 -> 1, 01 -> 2, 00 -> 3, which fix the path's probability.
    """
    n_par = len(state)
    new_state = np.concatenate([np.ones(n_par, bool), np.zeros(n_par, bool)])
    counts = np.concatenate([counts, counts])
    # reception half: 1 -> 1 (column 0) or 0 -> 1 (column 2); loss half: 1 -> 0 (column 1) or 0 -> 0 (column 3).
    # Column slices with boolean increments (integers: exact), not a fancy-indexed scatter (~15x faster)
    lost = ~state
    counts[:n_par, 0] += state
    counts[:n_par, 2] += lost
    counts[n_par:, 1] += state
    counts[n_par:, 3] += lost
    return new_state, counts


def _both_maps(P, A, C, Q, R):
    """``np.concatenate([g(P), h(P)])`` (eqs. 5 and 4: every path's reception, then its loss), for 2 states
    and 1 output by the compiled :func:`.kernels.riccati_branch_2x1` (the same numbers)."""
    if P.shape[1:] == (2, 2) and np.shape(C) == (1, 2) and np.shape(R) == (1, 1):
        from .kernels import riccati_branch_2x1  # numba: imported by the steps that build the tree

        return riccati_branch_2x1(P, A, C, Q, R)
    return np.concatenate([riccati_g(P, A, C, Q, R), riccati_h(P, A, Q)])


def _transition_key(counts, d):
    """One integer per path from its four transition counts (each at most ``d``): equal keys, equal probability."""
    return ((counts[:, 0].astype(np.int64) * (d + 1) + counts[:, 1]) * (d + 1) + counts[:, 2]) * (d + 1) + counts[:, 3]



def _transition_groups(counts, d):
    """Paths grouped by their transition counts, as ``np.unique`` of :func:`_transition_key` groups them
    (groups in increasing key order) but without sorting the ``2^(d-1)`` keys: a key is below ``(d+1)^4``,
    so a table of the keys present gives each group's rank, and a key decodes to its counts.

    Returns
    -------
    (group_counts, inv)
        ``(G, 4)`` transition counts of each group; ``inv``: the group of each path.
    """
    key = _transition_key(counts, d)
    base = d + 1
    present = np.zeros(base ** 4, dtype=bool)
    present[key] = True
    uniq = np.flatnonzero(present)
    inv = (np.cumsum(present) - 1)[key]
    group_counts = np.column_stack([uniq // base ** 3, uniq // base ** 2 % base, uniq // base % base, uniq % base])
    return group_counts, inv


@dataclass
class ExactMoments:
    """``E||P_k||`` and ``E tr P_k`` for ``k = 1..depth+1`` as polynomials in the transition probabilities.

    ``coef[d]`` has rows ``(n11, n10, n01, n00, sum_norm, sum_trace)``: over all channel paths
    ``gamma_1 = 1, gamma_2..gamma_d`` with the given transition counts, the sum of ``||P_{d+1}||``
    and ``tr P_{d+1}``. The path probability is ``(1-p)^{n11} p^{n10} q^{n01} (1-q)^{n00}``.

    Parameters
    ----------
    coef : list of ndarray
        Per depth, rows ``(n11, n10, n01, n00, sum_norm, sum_trace)``.
    P1_norm, P1_trace : float
        ``||P_1||`` and ``tr P_1``.
    """

    coef: list
    P1_norm: float
    P1_trace: float

    @property
    def depth(self):
        """Depth of the tree of channel paths.

        Returns
        -------
        int
            Number of tree levels (``E||P_k||`` known for ``k <= depth + 1``).
        """
        return len(self.coef)

    def mean(self, p, q, which="norm") -> np.ndarray:
        """``E||P_k||`` (``which="norm"``) or ``E tr P_k``, ``k = 1..depth+1``, for scalar or array ``p, q``.

        Parameters
        ----------
        p, q : float or array_like
            Failure and recovery rates (broadcast).
        which : {"norm", "trace"}
            The functional of ``P_k``.

        Returns
        -------
        ndarray
            Shape ``broadcast(p, q).shape + (depth + 1,)``.
        """
        p, q = np.broadcast_arrays(np.asarray(p, dtype=float), np.asarray(q, dtype=float))
        col = 4 if which == "norm" else 5
        out = [np.full(p.shape, self.P1_norm if which == "norm" else self.P1_trace)]
        base = np.stack([1 - p, p, q, 1 - q], axis=-1)  # (..., 4)
        for c in self.coef:
            counts = c[:, :4]
            prob = np.prod(base[..., None, :] ** counts, axis=-1)  # (..., n_keys); 0**0 = 1
            out.append(prob @ c[:, col])
        return np.stack(out, axis=-1)


def exact_moments(system: LinearSystem, Sigma0, depth: int) -> ExactMoments:
    """Exact ``E||P_k||`` over all ``2^{k-2}`` channel paths (``gamma_1 = 1``), ``k <= depth + 1``.

    The covariance along a path does not depend on ``(p, q)``; only the path probabilities do.
    The binary tree of covariances is built level by level (batched), and each level is summed by
    transition counts, which yields the expectation as a polynomial in ``(p, q)`` that is then
    evaluated on any grid at negligible cost. Exact (no sampling), so heavy tails are included.

    Parameters
    ----------
    system : LinearSystem
        The system (eqs. 1-2).
    Sigma0 : array_like
        ``P_1``.
    depth : int
        Number of tree levels (``2^{depth-1}`` paths at the last).

    Returns
    -------
    ExactMoments
    """
    A, C, Q, R = system.A, system.C, system.Q, system.R
    P = np.asarray(Sigma0, dtype=float)[None]
    P1 = P[0]
    # level d = 1: gamma_1 = 1 -> P_2 = g(P_1)
    P = riccati_g(P, A, C, Q, R)
    state = np.ones(1, dtype=bool)
    counts = np.zeros((1, 4), dtype=np.int16)
    coef = []
    for d in range(1, depth + 1):
        if d > 1:
            with np.errstate(over="ignore", invalid="ignore"):
                P = _both_maps(P, A, C, Q, R)
            state, counts = _branch_channel(state, counts)
        group_counts, inv = _transition_groups(counts, d)
        s_norm = np.bincount(inv, weights=sym_norm(P), minlength=len(group_counts))
        s_tr = np.bincount(inv, weights=batched_trace(P), minlength=len(group_counts))
        coef.append(np.column_stack([group_counts.astype(float), s_norm, s_tr]))
    return ExactMoments(coef, float(sym_norm(P1[None])[0]), float(np.trace(P1)))




# ----------------------------------------------------------------------------- block split
@dataclass
class BlockSplit:
    """An orthogonal change of state basis ``T`` and of output basis ``U`` that splits the system into
    decoupled blocks: ``T A T'``, ``T Q T'``, ``T Sigma0 T'`` block-diagonal over ``state_blocks`` and
    ``U C T'`` block-diagonal over ``(output_blocks, state_blocks)``, ``U R U'`` over ``output_blocks``.

    Then every ``P_k`` (eqs. 4-5) is block-diagonal in the new basis along every channel path (both
    maps preserve the block structure), ``||P_k|| = max_b ||P_k^b||`` and ``tr P_k = sum_b tr P_k^b``
    (``T`` orthogonal preserves both).

    Parameters
    ----------
    T : ndarray
        ``(n, n)`` orthogonal, rows are the new state coordinates.
    U : ndarray
        ``(m, m)`` orthogonal, rows are the new output coordinates.
    state_blocks, output_blocks : list of list of int
        Index sets of the blocks (same length; an output block may be empty).
    """

    T: np.ndarray
    U: np.ndarray
    state_blocks: list
    output_blocks: list

    def blocks(self, system: LinearSystem, Sigma0, tol: float = 1e-12):
        """The block systems, after checking that the split is exact.

        Parameters
        ----------
        system : LinearSystem
            The system (eqs. 1-2).
        Sigma0 : array_like
            ``P_1``.
        tol : float
            Largest admissible off-block entry (relative to the largest entry).

        Returns
        -------
        list of (A_b, C_b, Q_b, R_b, Sigma0_b)

        Raises
        ------
        InputError
            If ``T`` or ``U`` is not orthogonal or a matrix has an off-block entry.
        """
        T, U = np.asarray(self.T, float), np.asarray(self.U, float)
        for name, M in (("T", T), ("U", U)):
            if not np.allclose(M @ M.T, np.eye(len(M)), atol=tol):
                raise InputError(f"BlockSplit.{name} must be orthogonal")
        At, Qt, St = T @ system.A @ T.T, T @ system.Q @ T.T, T @ np.asarray(Sigma0, float) @ T.T
        Ct, Rt = U @ system.C @ T.T, U @ system.R @ U.T
        sb, ob = self.state_blocks, self.output_blocks
        smask = np.zeros(At.shape, bool)
        cmask = np.zeros(Ct.shape, bool)
        rmask = np.zeros(Rt.shape, bool)
        for s, o in zip(sb, ob):
            smask[np.ix_(s, s)] = True
            cmask[np.ix_(o, s)] = True
            rmask[np.ix_(o, o)] = True
        for name, M, mask in (("A", At, smask), ("Q", Qt, smask), ("Sigma0", St, smask), ("C", Ct, cmask),
                              ("R", Rt, rmask)):
            if np.any(np.abs(M[~mask]) > tol * max(np.abs(M).max(), 1.0)):
                raise InputError(f"BlockSplit does not split {name}: off-block entries")
        return [(At[np.ix_(s, s)], Ct[np.ix_(o, s)], Qt[np.ix_(s, s)], Rt[np.ix_(o, o)], St[np.ix_(s, s)])
                for s, o in zip(sb, ob)]


def example2_split() -> BlockSplit:
    """The split of Example II (eq. 13): ``A = 1.2 diag(1, 1, -1)``, ``C = [[1, 0, 1], [0, 1, 1]]``.

    In the state basis ``u = (e_1 + e_2)/sqrt 2``, ``w = (e_1 - e_2)/sqrt 2``, ``e_3`` (``u, w`` span
    the ``+1.2`` eigenspace) and the output basis ``(y_1 + y_2)/sqrt 2``, ``(y_1 - y_2)/sqrt 2``:
    ``C -> [[1, 0, sqrt 2], [0, 1, 0]]``, ``A -> diag(1.2, 1.2, -1.2)``, and ``Q = R = Sigma0 = I`` stay
    identities. So the dynamics split into a 2-D chain ``(u, e_3)`` with one output (the parity lock
    ``v = sqrt 2 u - e_3``, ``C v = 0``, lives there) and a scalar chain ``w`` with one output.

    Returns
    -------
    BlockSplit
    """
    s = 1.0 / np.sqrt(2.0)
    T = np.array([[s, s, 0.0], [s, -s, 0.0], [0.0, 0.0, 1.0]])
    U = np.array([[s, s], [s, -s]])
    return BlockSplit(T, U, [[0, 2], [1]], [[0], [1]])


def exact_moments_split(system: LinearSystem, Sigma0, depth: int, split: BlockSplit) -> ExactMoments:
    """:func:`exact_moments` on the decoupled blocks of ``split``: the same tree of channel paths, each
    block's covariance propagated by its own (smaller) Riccati maps (eqs. 4-5), and per path
    ``||P|| = max_b ||P^b||``, ``tr P = sum_b tr P^b``.

    Parameters
    ----------
    system : LinearSystem
        The system (eqs. 1-2).
    Sigma0 : array_like
        ``P_1``.
    depth : int
        Number of tree levels.
    split : BlockSplit
        A split checked by :meth:`BlockSplit.blocks`.

    Returns
    -------
    ExactMoments
        Identical (to rounding) to ``exact_moments(system, Sigma0, depth)``.
    """
    blocks = split.blocks(system, Sigma0)
    Ps = [riccati_g(S[None], A, C, Q, R) for A, C, Q, R, S in blocks]
    state = np.ones(1, dtype=bool)
    counts = np.zeros((1, 4), dtype=np.int16)
    coef = []
    for d in range(1, depth + 1):
        if d > 1:
            with np.errstate(over="ignore", invalid="ignore"):
                Ps = [_both_maps(P, A, C, Q, R) for P, (A, C, Q, R, _) in zip(Ps, blocks)]
            state, counts = _branch_channel(state, counts)
        group_counts, inv = _transition_groups(counts, d)
        norm = np.max(np.stack([sym_norm(P) if P.shape[-1] > 1 else P[:, 0, 0] for P in Ps]), axis=0)
        tr = sum(batched_trace(P) for P in Ps)
        s_norm = np.bincount(inv, weights=norm, minlength=len(group_counts))
        s_tr = np.bincount(inv, weights=tr, minlength=len(group_counts))
        coef.append(np.column_stack([group_counts.astype(float), s_norm, s_tr]))
    S0 = np.asarray(Sigma0, float)
    return ExactMoments(coef, float(sym_norm(S0[None])[0]), float(np.trace(S0)))


def find_split(system: LinearSystem, Sigma0):
    """The known block split (:func:`example2_split`) if it splits this system exactly, else ``None``.

    Parameters
    ----------
    system : LinearSystem
        The system (eqs. 1-2).
    Sigma0 : array_like
        ``P_1``.

    Returns
    -------
    BlockSplit or None
    """
    if system.A.shape != (3, 3) or system.C.shape != (2, 3):
        return None
    split = example2_split()
    try:
        split.blocks(system, Sigma0)
    except InputError:
        return None
    return split


def exact_moments_auto(system: LinearSystem, Sigma0, depth: int) -> ExactMoments:
    """:func:`exact_moments_split` where :func:`find_split` finds a split, else :func:`exact_moments`.

    Parameters
    ----------
    system : LinearSystem
        The system (eqs. 1-2).
    Sigma0 : array_like
        ``P_1``.
    depth : int
        Number of tree levels.

    Returns
    -------
    ExactMoments
    """
    split = find_split(system, Sigma0)
    if split is None:
        return exact_moments(system, Sigma0, depth)
    return exact_moments_split(system, Sigma0, depth, split)
