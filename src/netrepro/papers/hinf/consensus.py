"""Communication graph (eq (25)) and the discrete PI dynamic consensus estimator, eq (5), of the `hinf` paper.

Each agent runs eq (5) on its local informations ``u_i = (C_i^T M_i^{-1} C_i, C_i^T M_i^{-1} y_i)``
so that its state ``v_i`` tracks their network average, eqs (7)-(8).
"""

from __future__ import annotations

import numpy as np

from .noise import plane_norm

__all__ = [
    "adjacency", "laplacian", "pi_consensus_step", "pi_consensus_modes", "pi_consensus_spectral_radius",
    "consensus_h_max", "run_pi_consensus", "pi_consensus_time_constants", "CONSENSUS_DESIGNS",
    "complete_laplacian", "component_membership", "component_sums", "topology_changed",
]

# how the decentralized filter's averages (7)-(8) are formed (issue 28): the paper's PI consensus (5) whose
# integral states carry over topology changes; the same with the integral states reset at each change; exact
# sums over each agent's connected piece of the graph (25); the PI consensus (5) on a complete graph
CONSENSUS_DESIGNS = ("pi", "pi_reset", "exact_component", "complete")


def adjacency(positions, radius: float):
    """Communication links of eq (25): ``l_ij = 1`` iff ``|p_i - p_j| <= r`` (no self loops).

    Parameters
    ----------
    positions : ndarray, shape ``(..., N, 2)``
        Agent positions ``p_i`` in the plane (same length unit as ``radius``), a stack of runs allowed.
    radius : float
        Communication radius ``r``.

    Returns
    -------
    ndarray, shape ``(..., N, N)``
        0/1 floats, zero diagonal.
    """
    p = np.asarray(positions, dtype=float)
    d = plane_norm(p[..., :, None, :] - p[..., None, :, :])  # np.linalg.norm(axis=-1), bit for bit
    adj = (d <= radius).astype(float)
    n = p.shape[-2]
    adj[..., np.arange(n), np.arange(n)] = 0.0
    return adj


def laplacian(adj):
    """Graph Laplacian ``diag(adj 1) - adj``.

    Parameters
    ----------
    adj : ndarray, shape ``(..., N, N)``
        Adjacency (link weights, e.g. the 0/1 links of eq (25) from :func:`adjacency`), zero diagonal.

    Returns
    -------
    ndarray, shape ``(..., N, N)``
        The Laplacian: each agent's degree on the diagonal, ``-adj`` off it.
    """
    deg = adj.sum(-1)
    lap = -adj.copy()
    n = adj.shape[-1]
    lap[..., np.arange(n), np.arange(n)] = deg
    return lap


def pi_consensus_step(v, w, u, lap, gamma_c: float, h: float, K_p: float, K_i: float):
    """One step of the discrete PI dynamic consensus estimator, eq (5).

    .. math::

        v_i(k+1) &= (1-\\gamma h) v_i(k) - h K_p \\sum_{j\\in N_i}[v_i - v_j]
                    + h K_i \\sum_{j \\in N_i}[w_i - w_j] + \\gamma h u_i(k) \\\\
        w_i(k+1) &= w_i(k) - h K_i \\sum_{j \\in N_i} [v_i - v_j]

    Parameters
    ----------
    v, w, u : ndarray, shape ``(..., N, d)``
        Estimator states and inputs (``d`` signal components per agent).
    lap : ndarray, shape ``(..., N, N)``
        Graph Laplacian; ``(lap @ v)_i = sum_j l_ij (v_i - v_j)``.
    gamma_c, h, K_p, K_i : float
        The design parameter gamma of eq (5) (not the H-infinity gamma), step, gains.

    Returns
    -------
    v, w : ndarray, shape ``(..., N, d)``
        The states at ``k + 1``.
    """
    Lv = lap @ v
    Lw = lap @ w
    v_new = (1.0 - gamma_c * h) * v - h * K_p * Lv + h * K_i * Lw + gamma_c * h * u
    w_new = w - h * K_i * Lv
    return v_new, w_new


def pi_consensus_modes(lam, gamma_c: float, h: float, K_p: float, K_i: float):
    """Eigenvalue moduli of eq (5) on the Laplacian eigenvector of eigenvalue ``lam``.

    On that eigenvector the pair ``(v, w)`` evolves by
    ``[[1 - gamma h - h K_p lam, h K_i lam], [-h K_i lam, 1]]``. For ``lam = 0``
    the ``w`` component is conserved (``sum_i w_i`` is invariant and never reaches ``v``),
    so only the ``v`` eigenvalue ``1 - gamma h`` matters.

    Parameters
    ----------
    lam : array_like
        Laplacian eigenvalues.
    gamma_c, h, K_p, K_i : float
        Parameters of eq (5).

    Returns
    -------
    ndarray, shape ``lam.shape`` (at least 1-d)
        The spectral radius of the 2x2 block of each ``lam``.
    """
    lam = np.atleast_1d(np.asarray(lam, dtype=float))
    out = np.empty_like(lam)
    for n, l in enumerate(lam):
        if abs(l) < 1e-10:
            out[n] = abs(1.0 - gamma_c * h)
        else:
            F = np.array([[1.0 - gamma_c * h - h * K_p * l, h * K_i * l], [-h * K_i * l, 1.0]])
            out[n] = np.max(np.abs(np.linalg.eigvals(F)))
    return out


def pi_consensus_spectral_radius(lap, gamma_c, h, K_p, K_i) -> float:
    """Spectral radius of eq (5) on a fixed graph (the conserved ``sum w`` mode excluded).

    Parameters
    ----------
    lap : ndarray, shape ``(N, N)``
        Graph Laplacian.
    gamma_c, h, K_p, K_i : float
        Parameters of eq (5).

    Returns
    -------
    float
        The largest mode modulus; eq (5) is stable iff it is < 1.
    """
    lam = np.linalg.eigvalsh(np.asarray(lap, dtype=float))
    return float(pi_consensus_modes(lam, gamma_c, h, K_p, K_i).max())


def consensus_h_max(lap, gamma_c, K_p, K_i, h_hi: float = 10.0, tol: float = 1e-6) -> float:
    """Largest ``h`` such that eq (5) is stable for every step in ``(0, h]`` on graph ``lap``.

    Scans a fine grid for the first unstable ``h`` and refines by bisection. Small ``h``
    is always stable: for ``lam > 0`` the block has trace ``2 - h(gamma + K_p lam)`` and
    determinant ``1 - h(gamma + K_p lam) + h^2 K_i^2 lam^2``, so its eigenvalues are
    ``1 - h (gamma + K_p lam)/2 + O(h^2)`` inside the unit circle.

    Parameters
    ----------
    lap : ndarray, shape ``(N, N)``
        Graph Laplacian of the fixed communication graph.
    gamma_c, K_p, K_i : float
        Parameters of eq (5).
    h_hi : float
        Upper end of the scan.
    tol : float
        Bisection tolerance on ``h``.

    Returns
    -------
    float
        ``h_max`` (``h_hi`` if every scanned ``h`` is stable).
    """
    grid = np.linspace(0.0, h_hi, 4001)[1:]
    rho = np.array([pi_consensus_spectral_radius(lap, gamma_c, h, K_p, K_i) for h in grid])
    bad = np.nonzero(rho >= 1.0)[0]
    if bad.size == 0:
        return float(h_hi)
    if bad[0] == 0:
        lo, hi = 0.0, grid[0]
    else:
        lo, hi = grid[bad[0] - 1], grid[bad[0]]
    while hi - lo > tol:
        mid = 0.5 * (lo + hi)
        if pi_consensus_spectral_radius(lap, gamma_c, mid, K_p, K_i) < 1.0:
            lo = mid
        else:
            hi = mid
    return float(lo)


def run_pi_consensus(u, lap, gamma_c, h, K_p, K_i, n_iter: int, v0=None):
    """State ``v`` of eq (5) after ``n_iter`` steps with constant inputs on a fixed graph.

    ``v0`` defaults to ``u`` (each agent starts from its own input), ``w0 = 0``. With
    constant inputs (5) is the affine iteration ``z+ = F z + g`` on ``z = [v; w]``, so ``n_iter``
    steps are computed exactly as a power of the augmented matrix ``[[F, g], [0, I]]``
    (``O(log n_iter)`` products): the slow integral mode of a path graph needs ~10^5 steps.

    Parameters
    ----------
    u : ndarray, shape ``(N, d)``
        Constant inputs.
    lap : ndarray, shape ``(N, N)``
        Graph Laplacian of the fixed communication graph.
    gamma_c, h, K_p, K_i : float
        Parameters of eq (5).
    n_iter : int
        Number of steps.
    v0 : ndarray, shape ``(N, d)``, optional
        Initial state (default ``u``).

    Returns
    -------
    ndarray, shape ``(N, d)``
        ``v(n_iter)`` (inf/nan if the iteration diverged).
    """
    u = np.asarray(u, dtype=float)
    lap = np.asarray(lap, dtype=float)
    n, d = u.shape
    v = u.copy() if v0 is None else np.asarray(v0, dtype=float)
    eye = np.eye(n)
    F = np.block([[(1 - gamma_c * h) * eye - h * K_p * lap, h * K_i * lap], [-h * K_i * lap, eye]])
    aug = np.zeros((2 * n + d, 2 * n + d))
    aug[:2 * n, :2 * n] = F
    aug[:n, 2 * n:] = gamma_c * h * u  # column j of g multiplies the j-th unit "1" state
    aug[2 * n:, 2 * n:] = np.eye(d)
    z0 = np.vstack([v, np.zeros((n, d)), np.eye(d)])
    with np.errstate(over="ignore", invalid="ignore"):
        z = np.linalg.matrix_power(aug, int(n_iter)) @ z0
    return z[:n]


def pi_consensus_time_constants(lam, gamma_c: float, h: float, K_p: float, K_i: float):
    """Time constants (in iterations of eq (5)) of the consensus error on each Laplacian eigenvector.

    The error ``v - mean(u)`` on the eigenvector of eigenvalue ``lam > 0`` decays like ``rho^k`` with
    ``rho`` the spectral radius of the block of :func:`pi_consensus_modes`; its time constant is
    ``tau = -1 / ln rho``. For small ``lam`` the slow root is ``1 - h K_i^2 lam^2 / (gamma + K_p lam) + O(h^2)``:
    on a path graph (small algebraic connectivity ``lam_2``) the integral action is very slow.
    ``lam = 0`` gives the decay ``1 - gamma h`` of the mean. With ``K_i = 0`` the ``w`` states stay at
    zero and only ``1 - gamma h - h K_p lam`` acts on ``v``.

    Parameters
    ----------
    lam : array_like
        Laplacian eigenvalues.
    gamma_c, h, K_p, K_i : float
        Parameters of eq (5).

    Returns
    -------
    rho, tau : ndarray, shape ``lam.shape`` (at least 1-d)
        Mode moduli and time constants (inf for ``rho >= 1``).
    """
    if K_i == 0:
        rho = np.abs(1.0 - gamma_c * h - h * K_p * np.atleast_1d(np.asarray(lam, dtype=float)))
    else:
        rho = pi_consensus_modes(lam, gamma_c, h, K_p, K_i)
    with np.errstate(divide="ignore"):
        tau = np.where(rho < 1.0, -1.0 / np.log(np.minimum(rho, 1.0)), np.inf)
    return rho, tau


def complete_laplacian(n: int):
    """Laplacian ``n I - 1 1^T`` of the complete graph on ``n`` agents.

    Parameters
    ----------
    n : int
        Number of agents.

    Returns
    -------
    ndarray, shape ``(n, n)``
        ``n - 1`` on the diagonal (each agent's degree), -1 elsewhere.
    """
    return n * np.eye(n) - np.ones((n, n))


def component_membership(adj):
    """Which agents share a connected piece of the graph: ``m_ij = 1`` iff ``j`` is reachable from ``i``.

    Computed by repeated boolean squaring of ``I + adj`` (paths of length up to ``N - 1``).

    Parameters
    ----------
    adj : ndarray, shape ``(..., N, N)``
        0/1 adjacency of eq (25).

    Returns
    -------
    ndarray, shape ``(..., N, N)``
        0/1 floats, ones on the diagonal.
    """
    a = np.asarray(adj, dtype=float)
    n = a.shape[-1]
    reach = ((a + np.eye(n)) > 0).astype(float)
    steps = 1
    while steps < n - 1:
        reach = ((reach @ reach) > 0).astype(float)
        steps *= 2
    return reach


def component_sums(u, adj):
    """Exact sums of the agents' inputs over each agent's connected piece: ``sum_{j ~ i} u_j``.

    With exact sums over the whole (connected) graph, eq (9) with ``N C~ = sum_j u_j`` is the
    centralized filter (6); over a piece it is the centralized filter of that piece.

    Parameters
    ----------
    u : ndarray, shape ``(..., N, d)``
        The agents' inputs (one row per agent), a stack of runs allowed.
    adj : ndarray, shape ``(..., N, N)``
        0/1 adjacency of eq (25), matching ``u``'s leading shape.

    Returns
    -------
    ndarray, shape ``(..., N, d)``
        Row ``i``: the sum of ``u_j`` over the agents ``j`` of ``i``'s piece (``i`` included).
    """
    return component_membership(adj) @ np.asarray(u, dtype=float)


def topology_changed(adj_old, adj_new):
    """Whether the graph (25) changed between two steps (any link added or lost), per run.

    Parameters
    ----------
    adj_old, adj_new : ndarray, shape ``(..., N, N)``
        0/1 adjacency of eq (25) at the earlier and the later step.

    Returns
    -------
    ndarray of bool, shape ``adj.shape[:-2]``
        True for the runs whose graph differs.
    """
    return np.any(np.asarray(adj_old) != np.asarray(adj_new), axis=(-2, -1))
