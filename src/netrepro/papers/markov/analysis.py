"""Brute-force ``E||P_k||`` over every channel path (eq. 3), and the finite-``k`` monotonicity in ``p``
behind the proof of Proposition 2 (erratum E10, findings ``prop2_finite_k`` and ``prop2_stationary``).

Independent of :mod:`.exact`, which groups the same paths by their transition counts: the two
agree to rounding (tests), so each checks the other.
"""

from __future__ import annotations

import numpy as np

from .model import LinearSystem, riccati_g, riccati_h

__all__ = ["enumerate_norms", "transition_codes", "path_weights", "mean_norm_enumerated", "mean_norms_enumerated",
           "monotonicity_violation"]


def enumerate_norms(system: LinearSystem, Sigma0, k_max: int):
    """``||P_k||`` on every channel path ``gamma_1..gamma_{k-1}``, ``k = 1..k_max`` (recursion under eq. 3).

    ``P_{k+1} = g(P_k)`` if ``gamma_k = 1`` else ``h(P_k)`` (eqs. 4-5, the model's maps). Brute force
    over all ``2^(k-1)`` paths, independent of :mod:`.exact` (which groups paths by transition counts).

    Parameters
    ----------
    system : LinearSystem
        ``A, C, Q, R``.
    Sigma0 : array_like
        ``P_1``.
    k_max : int
        Largest ``k``.

    Returns
    -------
    list of (ndarray, ndarray)
        Per ``k``: the paths ``(2^(k-1), k-1)`` of 0/1 and ``||P_k||`` on each.
    """
    A, C, Q, R = (np.asarray(x, float) for x in (system.A, system.C, system.Q, system.R))
    P = np.asarray(Sigma0, float)[None]
    G = np.zeros((1, 0), dtype=int)
    out = [(G, np.linalg.eigvalsh(P)[:, -1])]
    for _ in range(1, k_max):
        P = np.concatenate([riccati_h(P, A, Q), riccati_g(P, A, C, Q, R)])
        G = np.concatenate([np.c_[G, np.zeros(len(G), int)], np.c_[G, np.ones(len(G), int)]])
        out.append((G, np.linalg.eigvalsh(P)[:, -1]))
    return out


def transition_codes(G) -> np.ndarray:
    """Transition of every step of each path ``G``: 0 for 1 -> 1, 1 for 1 -> 0, 2 for 0 -> 1, 3 for 0 -> 0 (eq. 3).

    Parameters
    ----------
    G : ndarray
        ``(N, t)`` paths of 0/1, ``t >= 1``.

    Returns
    -------
    ndarray
        ``(N, t - 1)`` integer codes (independent of ``p, q``: computed once per set of paths).
    """
    a, b = G[:, :-1], G[:, 1:]
    return np.where(a == 1, np.where(b == 1, 0, 1), np.where(b == 1, 2, 3))


def path_weights(G, p: float, q: float, gamma1: int, codes=None) -> np.ndarray:
    """Probability of each path ``G`` (rows ``gamma_1..gamma_t``) given ``gamma_1``, under eq. (3).

    Parameters
    ----------
    G : ndarray
        ``(N, t)`` paths of 0/1.
    p, q : float
        Failure and recovery rates.
    gamma1 : int
        The conditioning initial state.
    codes : ndarray, optional
        :func:`transition_codes` of ``G`` (computed here if not given).

    Returns
    -------
    ndarray
        ``(N,)`` weights (zero for paths starting elsewhere).
    """
    if G.shape[1] == 0:
        return np.ones(len(G))
    if codes is None:
        codes = transition_codes(G)
    step = np.array([1 - p, p, q, 1 - q], dtype=float)[codes]  # the step probabilities of eq. (3)
    return np.where(G[:, 0] == gamma1, 1.0, 0.0) * np.prod(step, axis=1)


def mean_norm_enumerated(paths, p: float, q: float, start: str = "gamma1", codes=None) -> np.ndarray:
    """``E||P_k||``, ``k = 1..k_max``, from :func:`enumerate_norms` (the expectation of Section 4 over eq. 3).

    Parameters
    ----------
    paths : list
        From :func:`enumerate_norms`.
    p, q : float
        Failure and recovery rates.
    start : {"gamma1", "stationary"}
        ``gamma_1 = 1`` (the paper's convention below eq. 3) or ``gamma_1`` drawn from the
        stationary law ``P(gamma = 1) = q / (p + q)`` (the proof of Proposition 2).
    codes : list, optional
        :func:`transition_codes` of each ``G`` of ``paths`` (for many ``p, q`` on the same paths).

    Returns
    -------
    ndarray
        ``(k_max,)``.
    """
    codes = codes if codes is not None else [None] * len(paths)
    one = np.array([w @ n for w, n in ((path_weights(G, p, q, 1, c), n) for (G, n), c in zip(paths, codes))])
    if start == "gamma1":
        return one
    zero = np.array([w @ n for w, n in ((path_weights(G, p, q, 0, c), n) for (G, n), c in zip(paths, codes))])
    zero[0] = one[0]
    pi1 = q / (p + q)
    return pi1 * one + (1 - pi1) * zero


def _is_enumeration_tree(paths) -> bool:
    """Whether ``paths`` holds the paths of :func:`enumerate_norms` in its order (level ``i``: the level
    ``i - 1`` paths with a 0 appended, then with a 1 appended; level 1: ``[[0], [1]]``)."""
    G = np.zeros((1, 0), dtype=int)
    for i, (Gi, _) in enumerate(paths):
        if i:
            G = np.concatenate([np.c_[G, np.zeros(len(G), int)], np.c_[G, np.ones(len(G), int)]])
        if np.shape(Gi) != G.shape or not np.array_equal(Gi, G):
            return False
    return True


def mean_norms_enumerated(paths, ps, q: float, start: str = "gamma1") -> np.ndarray:
    """:func:`mean_norm_enumerated` for every ``p`` of ``ps`` (one row each), the same numbers bit for bit.

    On the paths of :func:`enumerate_norms` (checked; other ``paths`` go through
    :func:`mean_norm_enumerated` itself) the weight of eq. (3) of a path of level ``i`` is its parent's
    product of step probabilities times the probability of the one new step, for all ``p`` at once:
    the same products in the same order as :func:`path_weights` (``numpy.prod`` multiplies left to
    right), without gathering every step of every path again at each level; each ``E||P_k||`` is the
    same dot product of weights and norms.

    Parameters
    ----------
    paths : list
        From :func:`enumerate_norms`.
    ps : array_like
        Failure rates.
    q : float
        Recovery rate.
    start : {"gamma1", "stationary"}
        As :func:`mean_norm_enumerated`.

    Returns
    -------
    ndarray
        ``(len(ps), k_max)``.
    """
    ps = np.asarray(ps, dtype=float).ravel()
    if not _is_enumeration_tree(paths):
        return np.array([mean_norm_enumerated(paths, p, q, start) for p in ps]).reshape(len(ps), len(paths))
    # columns: the step probabilities of transition codes 0..3 of transition_codes (1->1, 1->0, 0->1, 0->0)
    step = np.stack([1 - ps, ps, np.full_like(ps, q), np.full_like(ps, 1 - q)], axis=1)
    gammas = (1,) if start == "gamma1" else (1, 0)
    means = {g: np.empty((len(ps), len(paths))) for g in gammas}
    prod = np.ones((len(ps), 1))     # products of the step probabilities of each path, level by level
    for i, (G, n) in enumerate(paths):
        if i >= 2:                   # append 0 (codes 1 from 1, 3 from 0), then 1 (codes 0 from 1, 2 from 0)
            last = G[: len(G) // 2, -2] == 1
            prod = np.concatenate([prod * np.where(last, step[:, 1:2], step[:, 3:4]),
                                   prod * np.where(last, step[:, 0:1], step[:, 2:3])], axis=1)
        elif i == 1:
            prod = np.ones((len(ps), 2))
        for g in gammas:
            w = prod if i == 0 else np.where(G[:, 0] == g, 1.0, 0.0) * prod
            for j in range(len(ps)):
                means[g][j, i] = w[j] @ n
    one = means[1]
    if start == "gamma1":
        return one
    zero = means[0]
    zero[:, 0] = one[:, 0]
    pi1 = (q / (ps + q))[:, None]
    return pi1 * one + (1 - pi1) * zero


def monotonicity_violation(means, ps, rtol: float = 0.0):
    """Largest ``(E_{p2}||P_k|| - E_{p1}||P_k||) / E_{p1}||P_k||`` over ``p2 < p1`` on a grid (proof of Prop. 2).

    A value computed on a grid is a lower bound on the largest excess over all ``p2 < p1`` (the
    supremum over the continuum can only be larger).

    Parameters
    ----------
    means : ndarray
        ``(len(ps), K)``: ``E_p||P_k||`` for increasing ``ps``.
    ps : array_like
        Increasing failure rates.
    rtol : float
        Relative excesses up to this are rounding and count as none (``markov.prop2.rtol``).

    Returns
    -------
    dict
        ``violation`` (0 means monotone to ``rtol``), ``p1``, ``p2``, ``k``, ``e_p1``, ``e_p2``.
    """
    ps = np.asarray(ps, float)
    runmax = np.maximum.accumulate(means, axis=0)
    arg = np.zeros(means.shape, dtype=int)
    for i in range(1, len(ps)):  # index of the running maximum (small grids)
        arg[i] = np.where(means[i] >= runmax[i - 1], i, arg[i - 1])
    viol = (runmax - means) / means
    viol = np.where(viol > rtol, viol, 0.0)
    i, k = np.unravel_index(np.argmax(viol), viol.shape)
    j = arg[i, k]
    return {"violation": float(viol[i, k]), "p1": float(ps[i]), "p2": float(ps[j]), "k": int(k + 1),
            "e_p1": float(means[i, k]), "e_p2": float(means[j, k])}
