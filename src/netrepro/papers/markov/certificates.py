"""Certificates of boundedness and unboundedness of ``E||P_k||`` over the Gilbert-Elliott channel (eq. 3).

Every decision of the stability map comes from one of these, each a number we compute ourselves:

* **bounded, Theorem 1** (eq. 7): a gain ``K`` with ``rho(H(K)) < 1``. For ``l_o = 2``,
  ``H(K) = p H_1(K)`` (eq. 7 is linear in ``p``), so one ``K`` certifies every
  ``p < 1 / rho(H_1(K))`` at that ``q`` (:func:`thm1_radius`). By Theorem 2 this is exactly
  the feasibility of the LMI (10)-(11), i.e. Theorem 5's ``p_underline(q)``, found without a solver.
* **bounded, two-reception estimator** (:func:`two_reception_bound`): for ``n = 2m`` with
  ``[C; C A^j]`` invertible for every gap ``j`` (a non-degenerate system, Example I), the
  estimator that reconstructs the state from the last two received measurements has an error
  covariance we sum in closed form over the renewal structure of the channel; the Kalman
  filter's ``P_k`` is below it (optimality), so ``sup_k E||P_k|| <= U(p, q) < infinity``.
* **unbounded, loss run** (:func:`loss_run_lower_bound`): ``E||P_k|| >= P(gamma_2..gamma_{k-1} = 0)
  ||h^{k-2}(P_2)|| >= p (1-q)^{k-3} lambda_min(Q) ||A^{k-3}||^2``; it diverges iff
  ``|lambda_A|^2 (1-q) >= 1`` (the necessary condition of [18]).
* **unbounded, parity** (:func:`parity_lower_bound`, Example II): when ``A^2 = lambda^2 I`` and
  ``C v = 0`` for some ``v != 0``, the chain ``xi_t`` (coordinate along ``v`` at even ``t``,
  along ``w = A v / lambda`` at odd ``t``) is measured only at odd times (``C v = 0``), and its mirror
  (``v`` at odd ``t``, ``w`` at even ``t``) only at even times. On the event
  ``E_k`` = {every reception before ``k`` at an odd time} the mirror chain is never measured:
  its variance given the data is ``>= sigma^2 sum_{j<k-1} lambda^{2j}``, so
  ``E||P_k|| >= sigma^2 / ||f||^2 sum_{j<k-1} lambda^{2j} P(E_k)``, growing like
  ``(lambda^4 (pq + (1-q)^2))^{k/2}`` (:func:`parity_growth`). Its boundary
  ``lambda^4 (pq + (1-q)^2) = 1`` is :func:`~.model.parity_bound_example2`, where Theorem 5 is tight.
"""

from __future__ import annotations

import numpy as np

from ...errors import InputError
from .model import H_matrix, LinearSystem, loss_factor, riccati_g, spectral_abs

__all__ = [
    "thm1_radius", "loss_run_growth", "loss_run_lower_bound", "parity_structure", "parity_growth",
    "parity_lower_bound", "two_reception_bound", "critical_distance", "true_critical_curve", "certificate_grid",
    "decide_certified", "iid_instability_end",
]


def thm1_radius(A, C, qs, n_starts: int = 4, seed: int = 0):
    """``min_K rho(H_1(K))`` (eq. 7 at ``p = 1``) by Nelder-Mead for each ``q``; each returned ``K``
    is a certificate: ``rho(H(K)) = p rho(H_1(K)) < 1`` for every ``p < 1 / rho_1``.

    Only ``l_o = 2`` (one gain ``K^{(1)}``), where ``H(K)`` is ``p`` times a matrix independent of ``p``.
    The first ``q`` is searched from ``n_starts`` gains (``0``, ``-A C^+``, random ones); each next ``q``
    starts from the previous optimum only (warm start along the grid; the optimum moves slowly with ``q``).

    Parameters
    ----------
    A, C : array_like
        System and output matrices (``l_o = 2``).
    qs : array_like
        Recovery rates, each with ``|lambda_A|^2 (1-q) < 1``.
    n_starts : int
        Number of starting gains at the first ``q``.
    seed : int
        Seed of the random starts.

    Returns
    -------
    (rho1, K)
        ``rho1``: the radius of the returned gain at each ``q`` (an upper bound of the true minimum,
        recomputed from ``K`` by :func:`~.model.H_matrix`); ``K``: array ``(len(qs), n, m)``.
    """
    from scipy.optimize import minimize  # scipy.optimize: only the stability map needs it (~0.5 s import)

    A, C = np.atleast_2d(np.asarray(A, float)), np.atleast_2d(np.asarray(C, float))
    n, m = A.shape[0], C.shape[0]
    qs = np.atleast_1d(np.asarray(qs, float))
    rng = np.random.default_rng(seed)
    opts = {"xatol": 1e-11, "fatol": 1e-14, "maxiter": 150 * n * m, "maxfev": 150 * n * m}
    warm = {"xatol": 1e-9, "fatol": 1e-13, "maxiter": 60 * n * m, "maxfev": 60 * n * m}
    rhos, gains, prev = [], [], None
    for q in qs:
        LF = loss_factor(A, q).real

        def rho(k):
            M = A + k.reshape(n, m) @ C
            MM = (M[:, None, :, None] * M[None, :, None, :]).reshape(n * n, n * n)  # kron(M, M)
            return float(np.max(np.abs(np.linalg.eigvals(LF @ MM))))

        if prev is None:
            starts = [np.zeros(n * m), (-A @ np.linalg.pinv(C)).ravel()]
            starts += [rng.standard_normal(n * m) for _ in range(max(n_starts - 2, 0))]
        else:
            starts = [prev]
        best = None
        for x0 in starts:
            res = minimize(rho, x0, method="Nelder-Mead", options=opts if prev is None else warm)
            if prev is None:
                res = minimize(rho, res.x, method="Nelder-Mead", options=opts)  # restart: non-smooth radius
            if best is None or res.fun < best.fun:
                best = res
        prev = best.x
        K = best.x.reshape(n, m)
        rhos.append(float(np.max(np.abs(np.linalg.eigvals(H_matrix(A, C, [K], 1.0, q))))))
        gains.append(K)
    return np.array(rhos), np.array(gains)


def loss_run_growth(A, q):
    """Certified growth rate per step of the loss-run lower bound, ``log(|lambda_A|^2 (1-q))``.

    Parameters
    ----------
    A : array_like
        System matrix.
    q : array_like
        Recovery rates.

    Returns
    -------
    ndarray
        The rate (``>= 0`` means ``E||P_k||`` is unbounded).
    """
    lam = spectral_abs(A)
    with np.errstate(divide="ignore"):
        return np.log(lam ** 2 * (1.0 - np.asarray(q, float)))


def loss_run_lower_bound(A, Q, p, q, k):
    """``E||P_k|| >= p (1-q)^{k-3} lambda_min(Q) sum_{s<=k-3} ||A^s||^2`` (eq. 4 along ``gamma_2..gamma_{k-1} = 0``).

    ``h^{k-2}(P_2) >= sum_{s<k-2} A^s Q (A^s)'`` and ``||A^s Q (A^s)'|| >= lambda_min(Q) ||A^s||^2``.

    Parameters
    ----------
    A, Q : array_like
        System matrix and process noise covariance.
    p, q : array_like
        Failure and recovery rates (broadcast).
    k : int
        Time index, ``k >= 3``.

    Returns
    -------
    ndarray
        The lower bound at each ``(p, q)``.
    """
    A, Q = np.atleast_2d(np.asarray(A, float)), np.atleast_2d(np.asarray(Q, float))
    if k < 3:
        raise InputError(f"k must be >= 3, got {k}")
    s = sum(np.linalg.norm(np.linalg.matrix_power(A, j), 2) ** 2 for j in range(k - 2))
    p, q = np.asarray(p, float), np.asarray(q, float)
    return p * (1.0 - q) ** (k - 3) * float(np.linalg.eigvalsh(Q)[0]) * s


def parity_structure(A, C, Q, tol: float = 1e-12):
    """The parity lock of Example II: ``A^2 = lambda^2 I`` and a ``v != 0`` with ``C v = 0``.

    In the basis ``(v, w = A v / lambda, U)`` the span of ``v, w`` is ``A``-invariant, ``A`` swaps
    the two coordinates (times ``lambda``), and ``C v = 0``; the chain ``xi`` (``v``-coordinate at even
    times, ``w``-coordinate at odd times) is measured only at odd times, its mirror (``v`` at odd times)
    only at even times.

    Parameters
    ----------
    A, C, Q : array_like
        System, output and process noise matrices.
    tol : float
        Tolerance of the structural tests ``||A^2 - lambda^2 I||`` and ``||C v||`` (relative).

    Returns
    -------
    dict or None
        ``lam`` (``|lambda|``), ``sigma2`` (smallest conditional variance of the ``xi`` noise given the
        other noise coordinates), ``f_norm2`` (largest ``||f||^2`` of the two coordinate functionals),
        or ``None`` if the structure is absent.
    """
    A, C, Q = (np.atleast_2d(np.asarray(M, float)) for M in (A, C, Q))
    n = A.shape[0]
    lam = spectral_abs(A)
    if np.linalg.norm(A @ A - lam ** 2 * np.eye(n)) > tol * lam ** 2 * n:
        return None
    _, s, vt = np.linalg.svd(C)
    rank = int(np.sum(s > tol * max(s.max(), 1.0)))
    if rank == n:
        return None
    v = vt[-1]
    w = A @ v / lam
    if np.linalg.matrix_rank(np.column_stack([v, w])) < 2:
        return None
    # complete to a basis with the orthogonal complement of span{v, w}
    basis = np.linalg.svd(np.column_stack([v, w]))[0]
    Tinv = np.column_stack([v, w, basis[:, 2:]])
    T = np.linalg.inv(Tinv)  # rows: coordinate functionals a (along v), b (along w), c
    S = T @ Q @ T.T  # noise covariance in (a, b, c) coordinates
    Sinv = np.linalg.inv(S)
    sigma2 = float(min(1.0 / Sinv[0, 0], 1.0 / Sinv[1, 1]))
    f_norm2 = float(max(T[0] @ T[0], T[1] @ T[1]))
    return {"lam": lam, "sigma2": sigma2, "f_norm2": f_norm2}


def parity_growth(lam, p, q):
    """Certified growth rate per step of the parity lower bound, ``log(lambda^4 (pq + (1-q)^2)) / 2``.

    Parameters
    ----------
    lam : float
        ``|lambda|`` of a parity-locked system (:func:`parity_structure`).
    p, q : array_like
        Failure and recovery rates (broadcast).

    Returns
    -------
    ndarray
        The rate (``> 0``: ``E||P_k|| -> infinity``); its zero set is :func:`~.model.parity_bound_example2`.
    """
    p, q = np.asarray(p, float), np.asarray(q, float)
    return 0.5 * np.log(lam ** 4 * (p * q + (1.0 - q) ** 2))


def parity_lower_bound(structure: dict, p, q, k: int):
    """``E||P_k|| >= sigma^2 / ||f||^2 * sum_{j=0}^{k-2} lambda^{2j} * P(E_k)``, exact ``P(E_k)``.

    ``E_k`` = {``gamma_t = 0`` at every even ``t`` in ``[2, k-1]``} given ``gamma_1 = 1``: a two-state
    recursion over the channel (eq. 3), batched over ``(p, q)``.

    Parameters
    ----------
    structure : dict
        From :func:`parity_structure`.
    p, q : array_like
        Failure and recovery rates (broadcast).
    k : int
        Time index, ``k >= 2``.

    Returns
    -------
    ndarray
        The lower bound at each ``(p, q)``.
    """
    p, q = np.broadcast_arrays(np.asarray(p, float), np.asarray(q, float))
    if k < 2:
        raise InputError(f"k must be >= 2, got {k}")
    # probability vector over the channel state (received, lost) at time t, restricted to E_k
    on, off = np.ones(p.shape), np.zeros(p.shape)
    for t in range(2, k):
        on, off = on * (1 - p) + off * q, on * p + off * (1 - q)
        if t % 2 == 0:
            on = np.zeros(p.shape)
    prob = on + off
    lam2 = structure["lam"] ** 2
    growth = sum(lam2 ** j for j in range(k - 1))
    return structure["sigma2"] / structure["f_norm2"] * growth * prob


def two_reception_bound(system: LinearSystem, Sigma0, p, q, n_gaps: int = 400):
    """``U(p, q) >= sup_k E||P_k||`` from the estimator that reconstructs the state from the last two receptions.

    With receptions at ``t_1 < t_2`` (gap ``j``) the estimate ``O_j^{-1} [y_{t_1}; y_{t_2}]``,
    ``O_j = [C A^{-j}; C]``, has error covariance
    ``Sigma_j = O_j^{-1} diag(C A^{-j} W_j A^{-j}' C' + R, R) O_j^{-T}`` with ``W_j = sum_{s<j} A^s Q A^s'``;
    ``i`` steps later (no reception) it is ``A^i Sigma_j A^i' + W_i``. The Kalman ``P_k`` is below it
    (eq. 5 is optimal). Given a reception, the next comes after ``j`` steps with probability
    ``pi_1 = 1-p``, ``pi_j = p (1-q)^{j-2} q``, and ``i - 1`` further losses have probability
    ``s_1 = 1``, ``s_i = p (1-q)^{i-2}``; so, with ``||.|| <= tr``,

    .. math:: U = \\sum_j \\pi_j \\operatorname{tr}(\\Sigma_j G) + \\sum_i s_i \\operatorname{tr} W_i
              + \\operatorname{tr}(P_2 G') + \\ldots,\\quad G = \\sum_i s_i (A^i)' A^i

    where ``G`` solves a Stein equation (closed form), and the ``j``-series is summed to ``n_gaps``
    terms plus a geometric tail bound (ratio of the last terms, which tends to ``|lambda_min(A)|^2 (1-q)``).

    Parameters
    ----------
    system : LinearSystem
        ``n = 2 m`` with ``[C; C A^j]`` invertible for ``j = 1..n_gaps`` (checked).
    Sigma0 : array_like
        ``P_1``.
    p, q : array_like
        Failure and recovery rates (broadcast).
    n_gaps : int
        Number of explicit gap terms.

    Returns
    -------
    ndarray
        ``U`` at each ``(p, q)``; ``inf`` where ``|lambda_A|^2 (1-q) >= 1`` or the tail does not converge.

    Raises
    ------
    InputError
        If ``n != 2 m`` or some ``O_j`` is singular.
    """
    from scipy.linalg import solve_discrete_lyapunov  # imported where used (the stability map)

    A, C, Q, R = system.A, system.C, system.Q, system.R
    n, m = A.shape[0], C.shape[0]
    if n != 2 * m:
        raise InputError(f"two_reception_bound needs n = 2 m, got n = {n}, m = {m}")
    p, q = np.broadcast_arrays(np.asarray(p, float), np.asarray(q, float))
    lam = spectral_abs(A)
    Ainv = np.linalg.inv(A)
    trS, W, Aj, Aij = [], np.zeros_like(A), np.eye(n), np.eye(n)
    for j in range(1, n_gaps + 1):
        W = A @ W @ A.T + Q  # W_j = sum_{s<j} A^s Q A^s'
        Aij = Aij @ Ainv  # A^{-j}
        CAi = C @ Aij
        # row scaling S = diag(s I, I) keeps S O_j well conditioned although C A^{-j} -> 0:
        # O_j^{-1} D O_j^{-T} = (S O_j)^{-1} (S D S) (S O_j)^{-T}
        s = 1.0 / np.linalg.norm(CAi, 2)
        SO = np.vstack([s * CAi, C])
        if np.linalg.cond(SO) > 1e10:
            raise InputError(f"[C A^-{j}; C] is (nearly) singular: the system is degenerate")
        Oi = np.linalg.inv(SO)
        D = np.zeros((n, n))
        D[:m, :m] = s * s * (CAi @ W @ CAi.T + R)
        D[m:, m:] = R
        trS.append(Oi @ D @ Oi.T)
    Sig = np.array(trS)  # (J, n, n)
    P2 = riccati_g(np.asarray(Sigma0, float), A, C, Q, R)
    out = np.full(p.shape, np.inf)
    js = np.arange(1, n_gaps + 1)
    a_j = np.einsum("jab,ba->j", Sig, A.T @ A)  # tr(Sigma_j A'A)
    for qq in np.unique(q):
        sel = q == qq
        if lam ** 2 * (1 - qq) >= 1:
            continue
        pp = p[sel][:, None]
        G0 = solve_discrete_lyapunov(np.sqrt(1 - qq) * A.T, np.eye(n))  # sum_m (1-q)^m (A^m)' A^m
        # G = sum_i s_i (A^i)' A^i = A'A + p A'^2 G0 A^2;  G' = sum_i s_i (A^{i-1})' A^{i-1} = I + p A' G0 A
        b_j = np.einsum("jab,ba->j", Sig, A.T @ A.T @ G0 @ A @ A)
        pij = np.where(js == 1, 1 - pp, pp * qq * (1 - qq) ** np.maximum(js - 2, 0))
        with np.errstate(over="ignore", invalid="ignore"):
            terms = pij * (a_j + pp * b_j)  # (n_p, J)
            ratio = np.where(terms[:, -2] > 0, terms[:, -1] / terms[:, -2], 0.0)
            tail = np.where(ratio < 1, terms[:, -1] * ratio / (1 - ratio), np.inf)
        # sum_i s_i tr W_i = tr Q (1 + p/q) + (p/q) tr(Q A' G0 A); the single-reception paths add at most as much
        trw = np.trace(Q) * (1 + pp[:, 0] / qq) + pp[:, 0] / qq * np.trace(Q @ A.T @ G0 @ A)
        single = np.trace(P2) + pp[:, 0] * np.trace(P2 @ A.T @ G0 @ A)
        val = terms.sum(axis=1) + tail + 2 * trw + single
        out[sel] = np.where(np.isfinite(val), val, np.inf)
    return np.maximum(out, np.linalg.eigvalsh(np.asarray(Sigma0, float))[-1])


def critical_distance(points_q, points_p, curve_q, curve_p):
    """Euclidean distance in the ``(p, q)`` plane from each grid point to a densely sampled curve.

    Parameters
    ----------
    points_q, points_p : array_like
        The grid points.
    curve_q, curve_p : array_like
        Samples of the critical curve (spacing well below the distances of interest).

    Returns
    -------
    ndarray
        Distances, shape of ``points_q``.
    """
    from scipy.spatial import cKDTree

    tree = cKDTree(np.column_stack([np.asarray(curve_q, float), np.asarray(curve_p, float)]))
    pts = np.column_stack([np.ravel(points_q), np.ravel(points_p)])
    d, _ = tree.query(pts)
    return d.reshape(np.shape(points_q))


def true_critical_curve(reference: str, lam: float, n_samples: int = 20001):
    """Samples ``(q, p)`` of the true critical curve of the examples in the ``(p, q)`` unit square.

    ``nondegenerate`` (Example I, [18]): ``E||P_k||`` is bounded iff ``|lambda|^2 (1-q) < 1``, so the
    curve is the segment ``q = 1 - 1/|lambda|^2``, ``0 <= p <= 1`` (certified on both sides by
    :func:`two_reception_bound` and :func:`loss_run_lower_bound`). ``parity`` (Example II): the graph
    of ``p = (1 - (|lambda|^2 (1-q))^2) / (|lambda|^4 q)`` over ``q >= 1 - 1/|lambda|^2``, ``p <= 1``
    (certified below by :func:`thm1_radius`, above by :func:`parity_lower_bound`).

    Parameters
    ----------
    reference : {"nondegenerate", "parity"}
        Which example's structure.
    lam : float
        ``|lambda_A|``.
    n_samples : int
        Number of samples.

    Returns
    -------
    (q, p) : ndarray
        Curve samples.

    Raises
    ------
    InputError
        For another ``reference``.
    """
    q_nec = 1.0 - 1.0 / lam ** 2
    if reference == "nondegenerate":
        return np.full(n_samples, q_nec), np.linspace(0.0, 1.0, n_samples)
    if reference == "parity":
        q = np.linspace(q_nec, 1.0, n_samples)
        p = (1.0 - (lam ** 2 * (1.0 - q)) ** 2) / (lam ** 4 * q)
        keep = p <= 1.0
        return q[keep], p[keep]
    raise InputError(f"no known critical curve for reference {reference!r}")


def certificate_grid(system: LinearSystem, Sigma0, P, Qg, n_gaps: int = 400):
    """Every certificate's number on a ``(p, q)`` grid (decided by :func:`decide_certified`).

    Parameters
    ----------
    system : LinearSystem
        The system (eqs. 1-2), ``l_o = 2``.
    Sigma0 : array_like
        ``P_1``.
    P, Qg : ndarray
        Grid of ``p`` and ``q`` (same shape).
    n_gaps : int
        Explicit gap terms of :func:`two_reception_bound`.

    Returns
    -------
    dict of ndarray (shape of ``P``)
        ``rho1`` (``min_K rho(H_1(K))`` found at that ``q``; ``nan`` where ``|lambda|^2 (1-q) >= 1``),
        ``upper`` (:func:`two_reception_bound`; ``inf`` where not applicable), ``loss_growth``,
        ``parity_growth`` (``nan`` without the parity structure).
    """
    A, C = system.A, system.C
    lam = spectral_abs(A)
    P, Qg = np.asarray(P, float), np.asarray(Qg, float)
    uq, inv = np.unique(Qg, return_inverse=True)
    ok = lam ** 2 * (1.0 - uq) < 1.0
    rho_q = np.full(len(uq), np.nan)
    if ok.any():
        rho_q[ok] = thm1_radius(A, C, uq[ok])[0]
    rho1 = rho_q[inv].reshape(P.shape)
    n, m = A.shape[0], C.shape[0]
    if n == 2 * m:
        upper = two_reception_bound(system, Sigma0, P, Qg, n_gaps)
    else:
        upper = np.full(P.shape, np.inf)
    st = parity_structure(A, C, system.Q)
    par = parity_growth(st["lam"], P, Qg) if st is not None else np.full(P.shape, np.nan)
    return {"rho1": rho1, "upper": upper, "loss_growth": loss_run_growth(A, Qg), "parity_growth": par}


def decide_certified(facts: dict, P, rho_margin: float, growth_margin: float):
    """Verdicts from the certificates of :func:`certificate_grid` alone.

    ``bounded`` if ``p rho_1 < 1 - rho_margin`` (Theorem 1) or the two-reception bound is finite;
    ``unbounded`` if the loss-run growth is ``>= growth_margin`` or the parity growth ``> growth_margin``;
    ``undecided`` otherwise.

    Parameters
    ----------
    facts : dict
        From :func:`certificate_grid`.
    P : ndarray
        The ``p`` grid.
    rho_margin, growth_margin : float
        Margins of the two comparisons (rounding of an eigenvalue and of a logarithm).

    Returns
    -------
    (verdict, method) : ndarray of str

    Raises
    ------
    ModelError
        If a point is certified both bounded and unbounded (a bug in a certificate).
    """
    from ...errors import ModelError

    with np.errstate(invalid="ignore"):
        b_thm1 = np.asarray(P) * facts["rho1"] < 1.0 - rho_margin
        b_two = np.isfinite(facts["upper"])
        u_loss = facts["loss_growth"] >= growth_margin
        u_par = facts["parity_growth"] > growth_margin
    bounded, unbounded = b_thm1 | b_two, u_loss | u_par
    if np.any(bounded & unbounded):
        raise ModelError(f"{int(np.sum(bounded & unbounded))} grid points certified both bounded and unbounded")
    verdict = np.where(bounded, "bounded", np.where(unbounded, "unbounded", "undecided"))
    method = np.where(b_thm1, "Theorem 1: rho(H(K)) < 1 for a computed K",
                      np.where(b_two, "two-reception estimator upper bound (finite)",
                               np.where(u_loss, "loss-run lower bound grows (|lambda|^2 (1-q) >= 1)",
                                        np.where(u_par, "parity lower bound grows (lambda^4 (pq + (1-q)^2) > 1)",
                                                 "undecided: no certificate"))))
    return verdict, method


def iid_instability_end(A, C, Q):
    """Arrival rate below which ``E||P_k||`` is certified unbounded on the i.i.d. line ``p + q = 1``.

    On the i.i.d. line (arrival rate ``lambda = q = 1 - p``) the parity growth factor
    ``|lambda_A|^4 (pq + (1-q)^2)`` of :func:`parity_growth` is ``|lambda_A|^4 (1 - lambda)``, so for a
    parity-locked system (:func:`parity_structure`, Example II) the lower bound grows for every
    ``lambda < 1 - |lambda_A|^-4``; otherwise the loss-run bound (:func:`loss_run_growth`) grows for
    ``lambda < 1 - |lambda_A|^-2`` (the necessary condition of [18]). Any LMI that implies mean-square
    stability (Sinopoli et al.'s, Theorem 2's) is therefore infeasible below this end.

    Parameters
    ----------
    A, C, Q : array_like
        System, output and process noise matrices.

    Returns
    -------
    (float, str)
        The end and the certificate that backs it.
    """
    lam = spectral_abs(A)
    if parity_structure(A, C, Q) is not None:
        return 1.0 - lam ** -4, "parity lower bound grows (|lambda|^4 (1 - lambda) > 1) below 1 - |lambda|^-4"
    return 1.0 - lam ** -2, "loss-run lower bound grows (|lambda|^2 (1 - lambda) >= 1) up to 1 - |lambda|^-2"
