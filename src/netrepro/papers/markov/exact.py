"""Exact ``E||P_k||`` and ``E tr P_k`` over all channel paths of the Gilbert-Elliott channel (eq. 3),
as polynomials in ``(p, 1-p, q, 1-q)`` (binary tree of covariances, aggregated by transition counts).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .model import LinearSystem, riccati_g, riccati_h, sym_norm

__all__ = ["ExactMoments", "exact_moments"]


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
            n_par = len(P)
            with np.errstate(over="ignore", invalid="ignore"):
                P_recv = riccati_g(P, A, C, Q, R)
                P_loss = riccati_h(P, A, Q)
            P = np.concatenate([P_recv, P_loss])
            new_state = np.concatenate([np.ones(n_par, bool), np.zeros(n_par, bool)])
            old = np.concatenate([state, state])
            counts = np.concatenate([counts, counts])
            # transition index: 11 -> 0, 10 -> 1, 01 -> 2, 00 -> 3
            idx = np.where(old, np.where(new_state, 0, 1), np.where(new_state, 2, 3))
            counts[np.arange(len(idx)), idx] += 1
            state = new_state
        key = ((counts[:, 0].astype(np.int64) * (d + 1) + counts[:, 1]) * (d + 1) + counts[:, 2]) * (d + 1) + counts[:, 3]
        uniq, first, inv = np.unique(key, return_index=True, return_inverse=True)
        s_norm = np.bincount(inv, weights=sym_norm(P), minlength=len(uniq))
        s_tr = np.bincount(inv, weights=np.trace(P, axis1=-2, axis2=-1), minlength=len(uniq))
        coef.append(np.column_stack([counts[first].astype(float), s_norm, s_tr]))
    return ExactMoments(coef, float(sym_norm(P1[None])[0]), float(np.trace(P1)))


