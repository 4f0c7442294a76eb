"""Monte Carlo tuned gains of the form (9): a yardstick of what the filter structure can achieve.

Not a result of the paper: the gains are tuned by Nelder-Mead on common random numbers
for a named nonlinearity, without any worst-case guarantee.
"""

from __future__ import annotations

import numpy as np

from .model import Gains, System, draw_noise, simulate_draws
from .moments import error_mse, mode_matrices, second_moments

__all__ = ["tune_gains", "tune_gains_exact", "sum_mse", "exact_cost", "best_exact_gains"]


def tune_gains(sys: System, p_seq, n_runs: int, seed: int, nonlinearity: str, scheduled: bool, maxiter: int,
               start: Gains | None = None):
    """Gains of form (9) minimising the Monte Carlo sum_k E||e(k)||^2 (x0 ~ N(0, I)), Nelder-Mead.

    Common random numbers (one generator state per evaluation) make the cost
    a deterministic smooth-ish function of the gains. Starts from ``start``
    (default zero gains, the trivial estimate). Not a result of the paper: a yardstick.

    Parameters
    ----------
    sys : System
        The plant (1), (2), (6), its sector (3) and noise variance.
    p_seq : ndarray (K,)
        p(0..K-1) of the cost horizon.
    n_runs : int
        Monte Carlo runs of :func:`~netrepro.papers.gainsched.model.simulate`.
    seed : int
        Seed of the initial states (``seed``) and of the noise (``seed + 1``).
    nonlinearity : str
        Kind of the sector nonlinearity.
    scheduled : bool
        Tune Gf, Hf as well (else they are zero).
    maxiter : int
        Nelder-Mead iterations.
    start : Gains, optional
        Starting gains (default zero gains).

    Returns
    -------
    tuple
        The gains and ``{"cost", "n_eval", "start_cost"}``.
    """
    n, m = sys.n, sys.m
    x0 = np.random.default_rng(seed).standard_normal((n_runs, n))

    def unpack(v):
        G0 = v[: n * n].reshape(n, n)
        H0 = v[n * n: n * n + n * m].reshape(n, m)
        if scheduled:
            off = n * n + n * m
            Gf = v[off: off + n * n].reshape(n, n)
            Hf = v[off + n * n:].reshape(n, m)
        else:
            Gf, Hf = np.zeros((n, n)), np.zeros((n, m))
        return Gains(G0, Gf, H0, Hf)

    # common random numbers: every evaluation sees the draws of a fresh default_rng(seed + 1), drawn once here
    # (simulate_draws is bit-identical with simulate(..., np.random.default_rng(seed + 1), ...))
    draws = draw_noise(np.random.default_rng(seed + 1), len(p_seq), n_runs)

    def cost(v):
        return sum_mse(simulate_draws(sys, unpack(v), p_seq, x0, draws, nonlinearity))

    from scipy.optimize import minimize

    dim = (n * n + n * m) * (2 if scheduled else 1)
    v0 = np.zeros(dim)
    if start is not None:
        parts = [start.G0.ravel(), start.H0.ravel()] + ([start.Gf.ravel(), start.Hf.ravel()] if scheduled else [])
        v0 = np.concatenate(parts)
    res = minimize(cost, v0, method="Nelder-Mead",
                   options={"maxiter": int(maxiter), "xatol": 1e-4, "fatol": 1e-6, "adaptive": True})
    best = res.x if res.fun <= cost(v0) else v0
    return unpack(best), {"cost": float(min(res.fun, cost(v0))), "n_eval": int(res.nfev), "start_cost": cost(v0)}


def sum_mse(e) -> float:
    """Monte Carlo sum_k E||e(k)||^2 of errors ``e`` (runs, K+1, n): ``float((e ** 2).sum(-1).mean(0).sum())``.

    For n = 2 the squared norms are formed as e_1^2 + e_2^2 directly, the same two roundings as
    numpy's sum over a last axis of length 2 (about 8x faster than the reduction over that short
    axis); the mean over runs and the sum over k are numpy's own, on an array of the same layout,
    so the value is bit-identical. Other n: the expression above.

    Parameters
    ----------
    e : ndarray (runs, K+1, n)
        Estimation errors e(k) per run (from :func:`.model.simulate`).

    Returns
    -------
    float
        sum over k of the mean over runs of ||e(k)||^2.
    """
    e = np.asarray(e, dtype=float)
    if e.ndim == 3 and e.shape[2] == 2:
        e1, e2 = e[:, :, 0], e[:, :, 1]
        return float((e1 * e1 + e2 * e2).mean(0).sum())
    return float((e ** 2).sum(-1).mean(0).sum())


def tune_gains_exact(sys: System, p_seq, F, X0, scheduled: bool, maxiter: int, start: Gains | None = None):
    """Gains of form (9) minimising the exact sum_k E||e(k)||^2 for f = F z (second-moment recursion), Nelder-Mead.

    No sampling: the cost is the exact recursion of :mod:`.moments`, so the optimum is not a Monte
    Carlo artefact. Tuned for one linear f and one p(k) sequence: a yardstick, with no guarantee for
    other f in the sector (compare the certified performance design).

    Parameters
    ----------
    sys : System
        The plant (1), (2), (6), its sector (3) and noise variance.
    p_seq : ndarray (K,)
        p(0..K-1) of the cost horizon.
    F : ndarray (nz, nz)
        Linear gain of f.
    X0 : ndarray (2n, 2n)
        Initial second moment of [x; x_f].
    scheduled : bool
        Tune Gf, Hf as well (else they are zero).
    maxiter : int
        Nelder-Mead iterations.
    start : Gains, optional
        Starting gains (default zero gains).

    Returns
    -------
    tuple
        The gains and ``{"cost", "n_eval", "start_cost"}``.
    """
    from scipy.optimize import minimize

    n, m = sys.n, sys.m

    def unpack(v):
        G0 = v[: n * n].reshape(n, n)
        H0 = v[n * n: n * n + n * m].reshape(n, m)
        if scheduled:
            off = n * n + n * m
            return Gains(G0, v[off: off + n * n].reshape(n, n), H0, v[off + n * n:].reshape(n, m))
        return Gains(G0, np.zeros((n, n)), H0, np.zeros((n, m)))

    def cost(v):
        M1, M0, W = mode_matrices(sys, unpack(v), p_seq, F)
        return float(error_mse(second_moments(M1, M0, W, p_seq, sys.sigma2, X0)).sum())

    dim = (n * n + n * m) * (2 if scheduled else 1)
    v0 = np.zeros(dim)
    if start is not None:
        parts = [start.G0.ravel(), start.H0.ravel()] + ([start.Gf.ravel(), start.Hf.ravel()] if scheduled else [])
        v0 = np.concatenate(parts)
    res = minimize(cost, v0, method="Nelder-Mead",
                   options={"maxiter": int(maxiter), "xatol": 1e-6, "fatol": 1e-9, "adaptive": True})
    c0 = cost(v0)
    best = res.x if res.fun <= c0 else v0
    return unpack(best), {"cost": float(min(res.fun, c0)), "n_eval": int(res.nfev), "start_cost": c0}


def exact_cost(sys: System, gains: Gains, p_seq, F, X0) -> float:
    """Exact sum_{k=0}^{K} E||e(k)||^2 of (10) for f = F z by the second-moment recursion of :mod:`.moments`.

    The recursion X(k+1) = p M1 X M1^T + (1-p) M0 X M0^T + sigma^2 W X W^T for one system, on
    vec(X) with the operators p M1 (x) M1 + (1-p) M0 (x) M0 + sigma^2 W (x) W built for all k at
    once (the cost function of the tuning; :func:`.moments.second_moments` is the batched matrix
    form, an independent computation of the same values).

    Parameters
    ----------
    sys : System
        The plant (1), (2), (6) with its sector (3), noise variance and bounds of p(k).
    gains : Gains
        The filter gains of (9).
    p_seq : array_like (K,)
        The scheduled p(k) = Prob{xi(k) = 1} of (7), one per step; its length is the horizon.
    F : ndarray (nz, nz)
        Linear gain of f: f(z) = F z.
    X0 : ndarray (2n, 2n)
        E z̄(0) z̄(0)^T.

    Returns
    -------
    float
        The sum over the horizon of E||x(k) - x_f(k)||^2, starting from ``X0``.
    """
    M1, M0, W = mode_matrices(sys, gains, p_seq, F)
    p = np.asarray(p_seq, dtype=float)
    K, d = M1.shape[0], M1.shape[1]

    def kron(A):  # (A X A^T) in row-major vec(X): kron(A, A), for a stack of A
        return np.einsum("...ij,...lm->...iljm", A, A).reshape(A.shape[:-2] + (d * d, d * d))

    ops = p[:, None, None] * kron(M1) + (1.0 - p)[:, None, None] * kron(M0) + float(sys.sigma2) * kron(W)[None]
    n = sys.n
    c = np.zeros((d, d))  # tr(X_xx) + tr(X_ff) - tr(X_xf) - tr(X_fx) = E||x - x_f||^2 for symmetric X
    c[np.arange(d), np.arange(d)] = 1.0
    c[np.arange(n), n + np.arange(n)] = -1.0
    c[n + np.arange(n), np.arange(n)] = -1.0
    c = c.ravel()
    x = np.asarray(X0, dtype=float).ravel()
    total = float(c @ x)
    for k in range(K):  # one system: 16 x 16 matrix-vector products, the operators built at once
        x = ops[k] @ x
        total += float(c @ x)
    return total


def _pack(gains: Gains, scheduled: bool) -> np.ndarray:
    parts = [gains.G0.ravel(), gains.H0.ravel()] + ([gains.Gf.ravel(), gains.Hf.ravel()] if scheduled else [])
    return np.concatenate(parts)


def _unpack(v, n: int, m: int, scheduled: bool) -> Gains:
    G0 = v[: n * n].reshape(n, n)
    H0 = v[n * n: n * n + n * m].reshape(n, m)
    if scheduled:
        off = n * n + n * m
        return Gains(G0, v[off: off + n * n].reshape(n, n), H0, v[off + n * n:].reshape(n, m))
    return Gains(G0, np.zeros((n, n)), H0, np.zeros((n, m)))


def best_exact_gains(sys: System, p_seq, F, X0, scheduled: bool, starts, gtol: float = 1e-9):
    """The best gains of form (9) found for the exact sum_k E||e(k)||^2, BFGS from several starts.

    The exact cost (:func:`exact_cost`) is a smooth function of the gains, so a quasi-Newton
    method converges to a local minimum from each start; the best over the starts is returned
    (a local search: an upper bound on the family's optimum, not the optimum itself). With
    ``scheduled`` False, Gf = Hf = 0 (fixed gains; a start's Gf, Hf are ignored).

    Parameters
    ----------
    sys : System
        The plant (1), (2), (6) with its sector (3), noise variance and bounds of p(k).
    p_seq : array_like (K,)
        The scheduled p(k) = Prob{xi(k) = 1} of (7), one per step; its length is the horizon.
    F : ndarray (nz, nz)
        Linear gain of f.
    X0 : ndarray (2n, 2n)
        Initial second moment E z̄(0) z̄(0)^T of the augmented state (10).
    scheduled : bool
        Whether the gains depend on p (Gf, Hf free, the gain-scheduled filter) or are fixed (Gf = Hf = 0).
    starts : sequence of (str, Gains)
        Named starting gains.
    gtol : float
        BFGS gradient tolerance.

    Returns
    -------
    tuple
        ``(gains, {"cost", "start", "n_eval", "costs"})``: the best gains, their cost, the name of
        the start that reached them, the total number of cost evaluations and the cost per start.

    Raises
    ------
    GainschedError
        Without starts.
    """
    from scipy.optimize import minimize

    from .model import GainschedError

    if not starts:
        raise GainschedError("best_exact_gains needs at least one start")
    n, m = sys.n, sys.m

    def cost(v):
        return exact_cost(sys, _unpack(v, n, m, scheduled), p_seq, F, X0)

    best, n_eval, costs = None, 0, {}
    for name, start in starts:
        v0 = _pack(start, scheduled)
        res = minimize(cost, v0, method="BFGS", options={"gtol": float(gtol)})
        n_eval += int(res.nfev)
        c0 = cost(v0)
        x, c = (res.x, float(res.fun)) if res.fun <= c0 else (v0, c0)
        costs[name] = c
        if best is None or c < best[1]:
            best = (x, c, name)
    x, c, name = best
    return _unpack(x, n, m, scheduled), {"cost": c, "start": name, "n_eval": n_eval, "costs": costs}
