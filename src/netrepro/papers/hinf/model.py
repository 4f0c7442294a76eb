"""The multi-agent system of Section VI of the `hinf` paper: scenarios and their Monte Carlo simulation.

A target (random walk, stationary or evasive) is measured by ``N`` agents through the noise
model (2)-(4); each agent runs the local, decentralized (PI consensus (5) + eq (9)) and
centralized (eq (6)) H-infinity filters and their Kalman counterparts (gamma = infinity);
mobile agents follow the gradient law (12). Everything is vectorised over runs and agents.

Scenarios (``config['hinf']['scenarios']``): ``fig2`` / ``fig3``: ten stationary agents,
random-walk target, W = 0.01 I / 0.001 I (Figs 2-3); ``static_fixed`` / ``static_mobile``:
stationary target, stationary / mobile agents (Figs 4-5); ``evasive_hinf`` / ``evasive_kalman``:
four mobile agents, evasive target, driven by decentralized H-infinity / Kalman filters (Fig 6).
"""

from __future__ import annotations

import math

import numpy as np

from ...errors import InputError, ModelError
from .algebra import I2, min_eig2, sym2
from .consensus import (CONSENSUS_DESIGNS, adjacency, complete_laplacian, component_membership, component_sums,
                        laplacian, pi_consensus_step, topology_changed)
from .evader import SOLVERS, evader_move
from .filters import FilterDoesNotExist, congruence, hinf_update_batch, minimum_attenuation
from .motion import control_law, sigma_gradient
from .noise import NoiseModel, geometry, noise_information, plane_norm, sample_noise

__all__ = ["FILTER_KINDS", "SCENARIOS", "KINDS", "layout_positions", "resolve_scenario", "simulate",
           "FilterDoesNotExist", "attenuation_levels", "window_means", "paired_z", "run_paired", "bonferroni_z", "tag_z",
           "settle_step", "advantage", "gaussian_factor", "gaussian_draws"]

KINDS = ("local", "decentralized", "centralized")

FILTER_KINDS = {
    "local": ("local", False), "decentralized": ("decentralized", False), "centralized": ("centralized", False),
    "kalman_local": ("local", True), "kalman_decentralized": ("decentralized", True),
    "kalman_centralized": ("centralized", True),
}
SCENARIOS = ("fig2", "fig3", "static_fixed", "static_mobile", "evasive_hinf", "evasive_kalman")


def layout_positions(spec: dict) -> np.ndarray:
    """Agent positions on an arc around the origin.

    Parameters
    ----------
    spec : dict
        ``n`` agents, arc ``radius``, angular ``spacing_deg`` and ``start_deg`` (degrees).

    Returns
    -------
    ndarray, shape ``(n, 2)``
    """
    ang = np.deg2rad(spec["start_deg"] + spec["spacing_deg"] * np.arange(spec["n"]))
    return np.stack([spec["radius"] * np.cos(ang), spec["radius"] * np.sin(ang)], -1)


def resolve_scenario(cfg: dict, name: str, **overrides) -> dict:
    """The dict :func:`simulate` takes, from the config section and a scenario name.

    Parameters
    ----------
    cfg : dict
        The ``hinf`` configuration section.
    name : str
        A key of ``cfg['scenarios']``.
    **overrides
        Scenario keys (``runs``, ``horizon``, ``seed``, ...) and the sub-dicts ``filter``,
        ``consensus``, ``control`` whose entries replace the configured ones.

    Returns
    -------
    dict
        The resolved scenario (arrays, :class:`NoiseModel`, gains); see :func:`simulate`.
    """
    sc = dict(cfg["scenarios"][name])
    sc.update({k: v for k, v in overrides.items() if k in sc or k in ("runs", "horizon", "seed")})
    f = dict(cfg["filter"])
    f.update(overrides.get("filter", {}))
    cons = dict(cfg["consensus"])
    cons.update(overrides.get("consensus", {}))
    ctrl = dict(cfg["control"])
    ctrl.update(overrides.get("control", {}))
    L = np.asarray(f["L"], dtype=float)
    W = float(sc["W"])
    return {
        "agents0": layout_positions(cfg["layouts"][sc["layout"]]), "target0": np.zeros(2), "target": sc["target"],
        "W_true": W * np.eye(2), "W_filter": float(sc["W_filter"]) * np.eye(2), "A": np.asarray(f["A"], dtype=float),
        "gamma": float(f["gamma"]), "Lbar": L.T @ np.asarray(f["Q"], dtype=float) @ L, "P0": float(f["P0"]),
        "psd_floor": float(f["psd_floor"]), "model": NoiseModel.from_config(cfg["noise"]),
        "radius": float(cfg["comm_radius"]), "consensus": cons, "control": ctrl, "mobile": bool(sc["mobile"]),
        "driver": sc.get("driver", "decentralized"),
        "evader": {"n_headings": cfg["evader"]["n_headings"], "n_iter": cfg["evader"]["n_iter"],
                   "solver": cfg["evader"].get("solver", "mirror"),
                   "step": cfg["evader"]["step_scale"] * math.sqrt(2 * W)},
        "filters": list(sc["filters"]), "horizon": int(sc["horizon"]), "runs": int(sc["runs"]), "seed": int(sc["seed"]),
    }


def _psd_floor(C, floor):
    """Shift 2x2 symmetric matrices up so their smallest eigenvalue is at least ``floor``; count the shifts."""
    C = sym2(C)
    low = min_eig2(C)
    shift = np.maximum(floor - low, 0.0)
    return C + shift[..., None, None] * I2, int(np.count_nonzero(shift))


def gaussian_factor(cov):
    """The factor ``F = u sqrt(s)`` (``cov = u diag(s) v^T``, SVD) with which numpy's
    ``Generator.multivariate_normal`` (its default ``method="svd"``) maps standard normals to ``N(0, cov)``.

    Parameters
    ----------
    cov : ndarray, shape ``(d, d)``
        Symmetric positive semi-definite covariance.

    Returns
    -------
    ndarray, shape ``(d, d)``
    """
    u, s, _ = np.linalg.svd(np.asarray(cov, dtype=float))
    return u * np.sqrt(s)


def gaussian_draws(rng: np.random.Generator, factor, size: int):
    """``rng.multivariate_normal(0, cov, size)`` from its :func:`gaussian_factor`, the same draws and numbers.

    numpy draws ``x = rng.standard_normal((size, d))`` and returns ``mean + x @ F^T``; with ``F`` computed once,
    a simulation does not repeat the SVD and the positive semi-definiteness check of ``cov`` at every step.

    Parameters
    ----------
    rng : numpy.random.Generator
        The generator the draws come from (it advances as ``multivariate_normal`` would advance it).
    factor : ndarray, shape ``(d, d)``
        :func:`gaussian_factor` of the covariance.
    size : int
        Number of draws.

    Returns
    -------
    ndarray, shape ``(size, d)``
    """
    x = rng.standard_normal((int(size), factor.shape[0]))
    return np.zeros(factor.shape[0]) + x @ factor.T


def _connected(adj):
    # agent 0 reaches every agent (boolean squaring; the same answer as lambda_2(laplacian) > 1e-9, ~4x faster)
    return component_membership(adj)[..., 0, :].min(-1) > 0


def simulate(sc: dict) -> dict:
    """Monte Carlo simulation of one scenario of Section VI, vectorised over runs and agents.

    Parameters
    ----------
    sc : dict
        Resolved scenario: ``agents0 (N, 2)``, ``target0 (2,)``, ``target`` in
        {``random``, ``stationary``, ``evasive``, ``evasive_noise``, ``drift``, ``replay``} (``evasive_noise``: the
        evader's move plus white noise ``W_true``; ``drift``: a non-reactive target moving by the evader's step
        length in a heading fixed per run, drawn uniformly; ``replay``: the path ``target_path (R, K+1, 2)``),
        ``W_true``, ``W_filter``, ``A`` (2x2),
        ``gamma``, ``Lbar`` (= L^T Q L), ``P0``, ``model`` (:class:`NoiseModel`), ``radius``,
        ``consensus`` (``gamma_c, h, K_p, K_i, iters``, optional ``design`` of
        :data:`~netrepro.papers.hinf.consensus.CONSENSUS_DESIGNS`, default ``pi``), ``mobile``, ``driver``, ``control``
        (``Gamma, v_max, recursion``), ``evader`` (``n_headings, n_iter, step``, optional ``solver``), ``filters``,
        ``horizon``, ``runs``, ``seed``, ``psd_floor``. Optional: ``filter_base`` (label -> filter
        name, to run several copies of one filter), ``filter_gamma`` (label -> its own gamma),
        ``filter_W_factor`` (label -> its design process noise as a multiple of ``W_filter``),
        ``consensus_variants`` (label -> consensus entries replaced: a decentralized filter of that label on its
        own consensus), ``record_information``. Every filter sees the same target, agents and measurements; the
        agents are moved by ``driver`` alone (a paired design).

    Returns
    -------
    dict
        ``errors[name]``: ``(runs, n, horizon + 1)`` position-error norms ``|xhat - x|``
        (``n = N`` for local/decentralized, 1 for centralized); ``target (runs, K+1, 2)``;
        ``agents (runs, K+1, N, 2)``; ``connected (K+1,)`` fraction of runs with a connected
        graph; ``max_degree``; ``fused_trace (runs, K+1)`` (min over lambda of tr Q_fused, eq (22));
        ``trace_sigma[name] (runs, K+1)`` mean over agents of ``tr Sigma``; ``n_psd_fix``;
        ``connected_runs (runs, K+1)`` whether each run's graph is connected; ``information``: with
        ``record_information``, ``{"local": C^T M_k^{-1} C, "decentralized": N C~_k}`` of shape
        ``(K, runs, N, 2, 2)`` (the S sequences of eqs (6) and (9), for gamma_0), else None;
        ``topology_changes (runs,)`` number of steps at which the graph (25) changed.

    Raises
    ------
    FilterDoesNotExist
        If an H-infinity filter does not exist (gamma below gamma_0) at some step.
    InputError
        If a filter name, the driver or the target mode is unknown.
    """
    R, K = int(sc["runs"]), int(sc["horizon"])
    P = np.broadcast_to(np.asarray(sc["agents0"], dtype=float), (R,) + np.shape(sc["agents0"])).copy()
    N = P.shape[1]
    A = np.asarray(sc["A"], dtype=float)
    BWB = np.asarray(sc["W_filter"], dtype=float)
    Wt = np.asarray(sc["W_true"], dtype=float)
    Wt_factor = gaussian_factor(Wt)  # the target's noise N(0, W_true): rng.multivariate_normal's factor, once
    Lbar = np.asarray(sc["Lbar"], dtype=float)
    g2 = float(sc["gamma"]) ** -2.0
    model = sc["model"]
    cons = sc["consensus"]
    ctrl = sc.get("control", {})
    ev = sc.get("evader", {})
    if sc["target"] in ("evasive", "evasive_noise") and ev.get("solver", "mirror") == "exact":
        # numba: the certified evader (evader_move with a state) and the filters then run compiled (bit-identical);
        # its load (~0.5 s) pays for itself in any evasive loop of a step (fig6_paths: 2.47 s -> 1.52 s of CPU)
        from . import evader_kernels  # noqa: F401
    names = list(sc["filters"])
    base = sc.get("filter_base", {})  # label -> filter name of FILTER_KINDS (extra copies of a filter)
    for name in names:
        if base.get(name, name) not in FILTER_KINDS:
            raise InputError(f"unknown filter {name!r}; expected one of {sorted(FILTER_KINDS)}")
    kind_of = {n: FILTER_KINDS[base.get(n, n)] for n in names}
    own_gamma = sc.get("filter_gamma", {})  # label -> its own H-infinity gamma (default sc['gamma'])
    gi_of = {n: 0.0 if kind_of[n][1] else (float(own_gamma[n]) ** -2.0 if n in own_gamma else g2) for n in names}
    own_W = sc.get("filter_W_factor", {})  # label -> its own design W as a multiple of W_filter
    bwb_of = {n: float(own_W[n]) * BWB if n in own_W else BWB for n in names}
    # label -> consensus entries replaced: one more decentralized filter (eq (9), gamma and W_filter of the scenario)
    # fed by its own consensus (5) on the same measurements
    cvars = {None: cons}
    for lab, over in sc.get("consensus_variants", {}).items():
        if lab in names:
            raise InputError(f"consensus variant {lab!r} has the name of a filter")
        cvars[lab] = {**cons, **dict(over)}
        names.append(lab)
        kind_of[lab], gi_of[lab], bwb_of[lab] = FILTER_KINDS["decentralized"], g2, BWB
    for c in cvars.values():
        if c.get("design", "pi") not in CONSENSUS_DESIGNS:
            raise InputError(f"unknown consensus design {c.get('design')!r}; expected one of {CONSENSUS_DESIGNS}")
    record = bool(sc.get("record_information", False))
    mobile = bool(sc.get("mobile", False))
    driver = sc.get("driver", "decentralized")
    if mobile and driver not in names:
        raise InputError(f"driver filter {driver!r} must be among the filters {names}")
    ss = np.random.SeedSequence(int(sc["seed"]))
    rng0, rng_t, rng_m = (np.random.default_rng(s) for s in ss.spawn(3))
    if sc["target"] == "drift":
        heading = rng_t.uniform(0.0, 2 * np.pi, size=R)
        drift = float(ev["step"]) * np.stack([np.cos(heading), np.sin(heading)], -1)

    x = np.broadcast_to(np.asarray(sc["target0"], dtype=float), (R, 2)).copy()
    x0hat = x + np.sqrt(float(sc["P0"])) * rng0.standard_normal((R, 2))
    Sig0 = float(sc["P0"]) * I2
    # the filters of one kind are fed the same measurements: updated together, stacked on a leading axis
    groups, g_cons = {}, {}  # group -> its filters' labels; a decentralized group -> its consensus (None: cons)
    for name in names:
        key = name if name in cvars else kind_of[name][0]
        groups.setdefault(key, []).append(name)
        g_cons[key] = name if name in cvars else None
    g_kind = {key: kind_of[labs[0]][0] for key, labs in groups.items()}
    slot = {n: (kind, i) for kind, labs in groups.items() for i, n in enumerate(labs)}
    est, cov, delta, err_g, tr_g, bwb_g, gi_g = {}, {}, {}, {}, {}, {}, {}
    for kind, labs in groups.items():  # kind: the group's key
        shape = (len(labs), R) if g_kind[kind] == "centralized" else (len(labs), R, N)
        est[kind] = np.broadcast_to(x0hat[:, None, :] if g_kind[kind] != "centralized" else x0hat, shape + (2,)).copy()
        cov[kind] = np.broadcast_to(Sig0, shape + (2, 2)).copy()
        err_g[kind] = np.empty((len(labs), R, 1 if g_kind[kind] == "centralized" else N, K + 1))
        tr_g[kind] = np.empty((len(labs), R, K + 1))
        bwb_g[kind] = np.stack([bwb_of[n] for n in labs])
        gi_g[kind] = np.array([gi_of[n] for n in labs])
        e = plane_norm(est[kind] - (x if g_kind[kind] == "centralized" else x[:, None, :]))
        err_g[kind][..., 0] = e if e.ndim == 3 else e[..., None]
        tr_g[kind][:, :, 0] = 2 * float(sc["P0"])
    errors = {n: err_g[slot[n][0]][slot[n][1]] for n in names}
    trace_sigma = {n: tr_g[slot[n][0]][slot[n][1]] for n in names}
    tgt = np.empty((R, K + 1, 2))
    tgt[:, 0] = x
    ags = np.empty((R, K + 1, N, 2))
    ags[:, 0] = P
    fused = np.full((R, K + 1), np.nan)
    connected = np.empty(K + 1)
    conn_runs = np.empty((R, K + 1), dtype=bool)
    adj = adjacency(P, sc["radius"])
    lap = laplacian(adj)
    conn_runs[:, 0] = _connected(adj)
    connected[0] = conn_runs[:, 0].mean()
    info_hist = {"local": np.empty((K, R, N, 2, 2)), "decentralized": np.empty((K, R, N, 2, 2))} if record else None
    max_degree = int(adj.sum(-1).max())
    changes = np.zeros(R, dtype=int)
    reset = np.zeros(R, dtype=bool)
    lap_complete = (np.broadcast_to(complete_laplacian(N), (R, N, N))
                    if any(c.get("design", "pi") == "complete" for c in cvars.values()) else None)
    cons_ids = [cid for cid in cvars if cid in g_cons.values()]  # the consensus runs some filter reads
    v, w, Ct, yt = {}, {}, {}, {}
    dsig = np.zeros((2, R, N, 2, 2))  # local copies of Sigma^r_i, Sigma^theta_i (eq (14))
    n_psd_fix = 0
    ev_state = {}  # the evader's weights from move to move: it solves only the candidates that can win
    for k in range(1, K + 1):
        # 1. target motion
        if sc["target"] == "random":
            x = x @ A.T + gaussian_draws(rng_t, Wt_factor, R) if np.any(Wt) else x @ A.T
        elif sc["target"] == "evasive":
            x, fz = evader_move(x, P, model, float(ev["step"]), int(ev["n_headings"]), int(ev["n_iter"]),
                                ev.get("solver", "mirror"), state=ev_state)
            fused[:, k] = fz
        elif sc["target"] == "evasive_noise":
            x, fz = evader_move(x, P, model, float(ev["step"]), int(ev["n_headings"]), int(ev["n_iter"]),
                                ev.get("solver", "mirror"), state=ev_state)
            fused[:, k] = fz
            x = x + gaussian_draws(rng_t, Wt_factor, R)
        elif sc["target"] == "drift":
            x = x + drift
        elif sc["target"] == "replay":  # a recorded path (the other streams of random numbers are unaffected)
            x = np.asarray(sc["target_path"], dtype=float)[:, k]
        elif sc["target"] != "stationary":
            raise InputError(f"unknown target mode {sc['target']!r}")
        # 2. measurements (2)-(4) from the true geometry
        r, th = geometry(x, P)
        Minv = noise_information(r, th, model)
        y = x[:, None, :] + sample_noise(rng_m, r, th, model)
        yinfo = (Minv @ y[..., None])[..., 0]
        # 3. PI consensus (5) on u_i = (C_i^T M_i^-1 C_i, C_i^T M_i^-1 y_i), eqs (7)-(8)
        if cons_ids:
            u = np.concatenate([Minv.reshape(R, N, 4), yinfo], -1)
        for cid in cons_ids:
            c = cvars[cid]
            design = c.get("design", "pi")
            if design == "exact_component":  # exact sums over each agent's connected piece, divided by N for (9)
                v[cid] = component_sums(u, adj) / N
            else:
                if cid not in v:
                    v[cid], w[cid] = u.copy(), np.zeros_like(u)
                if design == "pi_reset" and reset.any():
                    w[cid][reset] = 0.0
                lap_c = lap_complete if design == "complete" else lap
                for _ in range(int(c["iters"])):
                    v[cid], w[cid] = pi_consensus_step(v[cid], w[cid], u, lap_c, c["gamma_c"], c["h"], c["K_p"],
                                                       c["K_i"])
            Ct[cid], nfix = _psd_floor(v[cid][..., :4].reshape(R, N, 2, 2), float(sc.get("psd_floor", 1e-9)))
            yt[cid] = v[cid][..., 4:]
            if cid is None:
                n_psd_fix += nfix
                if record:
                    info_hist["decentralized"][k - 1] = N * Ct[cid]
        if record:
            info_hist["local"][k - 1] = Minv
        # 4. filters (6), (9) and their Kalman counterparts
        for kind in groups:  # kind: the group's key
            if g_kind[kind] == "local":
                y_k, S_k = yinfo, Minv
            elif g_kind[kind] == "centralized":
                y_k, S_k = yinfo.sum(1), Minv.sum(1)
            else:  # eq (9) is eq (6) with S = N C~, y_info = N y~ (decentralized_update)
                y_k, S_k = N * yt[g_cons[kind]], N * Ct[g_cons[kind]]
            est[kind], cov[kind], delta[kind], _ = hinf_update_batch(est[kind], cov[kind], y_k, S_k, A, bwb_g[kind],
                                                                     gi_g[kind], Lbar)
            if g_kind[kind] == "centralized":
                err_g[kind][:, :, 0, k] = plane_norm(est[kind] - x)
                tr_g[kind][:, :, k] = cov[kind][..., 0, 0] + cov[kind][..., 1, 1]
            else:
                err_g[kind][:, :, :, k] = plane_norm(est[kind] - x[:, None, :])
                tr_g[kind][:, :, k] = (cov[kind][..., 0, 0] + cov[kind][..., 1, 1]).mean(2)
        # 5. decentralized gradient motion control (12)-(18), each agent with its own estimate
        if mobile:
            gi = gi_of[driver]
            # each agent steers by its own estimate; ``steer_on_truth`` (a cause test) by the true position
            xh = est[slot[driver][0]][slot[driver][1]]  # (R, N, 2)
            xh = np.broadcast_to(x[:, None, :], xh.shape) if ctrl.get("steer_on_truth") else xh
            d = xh - P
            rh, thh = np.hypot(d[..., 0], d[..., 1]), np.arctan2(d[..., 1], d[..., 0])
            rh = np.maximum(rh, 1e-6)
            _, dMr, dMt = noise_information(rh, thh, model, derivatives=True)
            Delta = delta[slot[driver][0]][slot[driver][1]]
            S_hat = N * Ct[None] if kind_of[driver][0] == "decentralized" else Minv
            grads = []
            for z, dM in enumerate((dMr, dMt)):
                dDelta = congruence(A, dsig[z]) if ctrl.get("recursion", True) else np.zeros_like(Delta)
                _, dS = sigma_gradient(Delta, dDelta, S_hat, dM, gi, Lbar)
                dsig[z] = dS
                grads.append(dS[..., 0, 0] + dS[..., 1, 1])
            P = P + control_law(grads[0], grads[1], rh, thh, float(ctrl["Gamma"]), float(ctrl["v_max"]))
            adj_new = adjacency(P, sc["radius"])
            reset = topology_changed(adj, adj_new)
            changes += reset
            adj = adj_new
            lap = laplacian(adj)
            max_degree = max(max_degree, int(adj.sum(-1).max()))
        conn_runs[:, k] = _connected(adj) if mobile else conn_runs[:, 0]
        connected[k] = conn_runs[:, k].mean() if mobile else connected[0]
        tgt[:, k] = x
        ags[:, k] = P
    if sc["target"] == "evasive" or sc.get("fused_all", True):
        r, th = geometry(tgt[:, 0], ags[:, 0])
        solver = ev.get("solver", "mirror")
        inner = SOLVERS[solver]  # the evader's own inner solver of (24)
        # a single call: the exact solver's numpy form (compiling its kernel would cost more than it saves)
        kw = {"kernel": "numpy"} if solver == "exact" else {}
        fused[:, 0] = inner(noise_information(r, th, model), int(ev.get("n_iter", 40)), **kw)[0]
    return {"errors": errors, "target": tgt, "agents": ags, "connected": connected, "max_degree": max_degree,
            "fused_trace": fused, "trace_sigma": trace_sigma, "n_psd_fix": n_psd_fix, "connected_runs": conn_runs,
            "information": info_hist, "topology_changes": changes}


def attenuation_levels(information, P0: float, A, BWB, Lbar) -> dict:
    """Minimum attenuation level gamma_0 of each H-infinity filter kind along recorded informations.

    gamma_0 is the smallest gamma for which ``Sigma_k^{-1} > 0`` at every step of every run and
    agent (eq (6) for ``local`` and ``centralized``, eq (9) for ``decentralized``); the
    covariance recursion does not depend on the measurements, only on the sequence ``S_k``.

    Parameters
    ----------
    information : dict
        ``simulate(...)["information"]``: ``local`` ``(K, R, N, 2, 2)`` the agents' ``M_k^{-1}``,
        ``decentralized`` ``(K, R, N, 2, 2)`` their ``N C~_k``.
    P0 : float
        ``Sigma_0 = P0 I``.
    A, BWB, Lbar : ndarray, shape ``(2, 2)``
        Target dynamics ``A``, the filters' ``B W B^T`` and ``Lbar = L^T Q L``.

    Returns
    -------
    dict
        ``{kind: gamma_0}`` for ``local`` (worst agent), ``decentralized`` (worst agent), ``centralized``.
    """
    Sig0 = float(P0) * I2
    loc = information["local"]
    return {
        "local": minimum_attenuation(loc, Sig0, A, BWB, Lbar),
        "decentralized": minimum_attenuation(information["decentralized"], Sig0, A, BWB, Lbar),
        "centralized": minimum_attenuation(loc.sum(2), Sig0, A, BWB, Lbar),
    }


def window_means(errors, start: int, stop: int | None = None):
    """Mean error of each run over the steps ``start <= k <= stop`` (the claims' window) and the agents.

    Parameters
    ----------
    errors : ndarray, shape ``(R, n, K + 1)``
        Position-error norms ``|xhat - x|`` of ``R`` runs, ``n`` agents (1 for the centralized filter)
        and steps ``0..K`` (``simulate(...)["errors"][name]``).
    start : int
        First step included.
    stop : int, optional
        Last step included (default ``K``).

    Returns
    -------
    ndarray, shape ``(R,)``
        Each run's mean error over the window and the agents.
    """
    stop = errors.shape[-1] - 1 if stop is None else int(stop)
    return errors[..., int(start):stop + 1].mean(axis=(1, 2))


def paired_z(a, b):
    """Paired comparison of per-run values: mean of ``a - b``, its standard error and ``z = mean / se``.

    Parameters
    ----------
    a, b : ndarray, shape ``(R,)``
        Values of the two arms on the same runs (common random numbers).

    Returns
    -------
    mean, se, z : float
        ``se`` is the sample standard deviation of the differences over ``sqrt(R)``.
    """
    d = np.asarray(a, dtype=float) - np.asarray(b, dtype=float)
    se = d.std(ddof=1) / math.sqrt(len(d)) if len(d) > 1 else np.nan
    return float(d.mean()), float(se), float(d.mean() / se) if se > 0 else np.nan


def run_paired(sc: dict, factors, w_factors=()) -> dict:
    """Every filter on the same target, agents and measurements, with gamma swept relative to each gamma_0.

    Pass 1 runs the driver alone (it alone moves the agents) and records the informations; gamma_0 of
    each kind follows from them (:func:`attenuation_levels`). Pass 2 repeats the same seed with the
    driver, the six filters of ``FILTER_KINDS`` and one extra H-infinity copy of each kind per factor
    ``c`` at ``gamma = c gamma_0(kind)`` (labels ``"<kind>@<c>"``), replaying the target's path of pass 1.
    Since only the driver moves the agents and the measurement noise has its own random stream, both
    passes have identical target and agent trajectories and measurements; this is checked (the
    driver's errors must agree to the bit).

    Parameters
    ----------
    sc : dict
        Resolved scenario (see :func:`simulate`); ``driver`` must be one of the six filter names.
    factors : sequence of float
        Multiples of gamma_0 (each > 1).
    w_factors : sequence of float, optional
        Design process noises of extra Kalman copies of each kind, as multiples of ``W_filter``
        (labels ``"kalman_<kind>@W<f>"``; a factor 1 is the plain Kalman filter and adds no copy).

    Returns
    -------
    dict
        ``gamma0 {kind: float}``, ``gammas {label: gamma or inf}``, ``base {label: filter name}``,
        ``w_factor {label: design-W factor}`` of the extra Kalman copies,
        ``out``: the pass-2 output of :func:`simulate`.

    Raises
    ------
    ModelError
        If the two passes do not share their trajectories.
    """
    first = simulate({**sc, "filters": [sc["driver"]], "record_information": True})
    gamma0 = attenuation_levels(first["information"], sc["P0"], np.asarray(sc["A"], float),
                                np.asarray(sc["W_filter"], float), np.asarray(sc["Lbar"], float))
    names = list(FILTER_KINDS)
    base = {n: n for n in names}
    gammas = {n: (np.inf if FILTER_KINDS[n][1] else float(sc["gamma"])) for n in names}
    for kind in KINDS:
        for c in factors:
            label = f"{kind}@{c:g}"
            base[label], gammas[label] = kind, float(c) * gamma0[kind]
            names.append(label)
    wf = {}
    for kind in KINDS:
        for f in w_factors:
            if float(f) == 1.0:
                continue
            label = f"kalman_{kind}@W{float(f):g}"
            base[label], gammas[label], wf[label] = "kalman_" + kind, np.inf, float(f)
            names.append(label)
    own = {n: g for n, g in gammas.items() if np.isfinite(g)}
    # the target's path is replayed (the evader's moves depend only on the target and the agents, which the
    # driver alone moves); the measurement noise has its own stream of random numbers
    out = simulate({**sc, "filters": names, "filter_base": base, "filter_gamma": own, "filter_W_factor": wf,
                    "target": "replay",
                    "target_path": first["target"]})
    same = (np.array_equal(out["target"], first["target"]) and np.array_equal(out["agents"], first["agents"])
            and np.array_equal(out["errors"][sc["driver"]], first["errors"][sc["driver"]]))
    if not same:
        raise ModelError("paired design broken: trajectories or measurements depend on the set of filters")
    out["fused_trace"] = first["fused_trace"]
    out["topology_changes"] = first["topology_changes"]
    return {"gamma0": gamma0, "gammas": gammas, "base": base, "w_factor": wf, "out": out}


def bonferroni_z(alpha: float, m: int) -> float:
    """Two-sided critical |z| of one of ``m`` comparisons at family-wise level ``alpha`` (Bonferroni).

    Each comparison is two-sided at level ``alpha / m``, so the probability that any of the ``m``
    rejects a true null is at most ``alpha`` (union bound), whatever their dependence.

    Parameters
    ----------
    alpha : float
        Family-wise significance level, ``0 < alpha < 1``.
    m : int
        Number of comparisons in the family (>= 1).

    Returns
    -------
    float
        ``Phi^-1(1 - alpha / (2 m))``.

    Raises
    ------
    InputError
        If ``alpha`` or ``m`` is out of range.
    """
    from scipy.special import ndtri  # scipy.stats.norm.ppf is ndtri (same numbers); scipy.stats costs ~0.5 s of import

    if not 0.0 < float(alpha) < 1.0 or int(m) < 1:
        raise InputError(f"need 0 < alpha < 1 and m >= 1, got alpha={alpha!r}, m={m!r}")
    return float(ndtri(1.0 - float(alpha) / (2 * int(m))))


def tag_z(z: float, z_crit: float) -> str:
    """``holds`` (z < -z_crit: arm a significantly smaller), ``reversed`` (z > z_crit) or ``not significant``.

    Parameters
    ----------
    z : float
        Paired z of ``a - b``.
    z_crit : float
        Critical |z| (e.g. :func:`bonferroni_z`).

    Returns
    -------
    str
    """
    if not np.isfinite(z):
        return "not significant"
    return "holds" if z < -z_crit else ("reversed" if z > z_crit else "not significant")


def settle_step(error_mean, threshold: float) -> int:
    """First step after which the series stays below ``threshold`` (``-1``: never).

    Parameters
    ----------
    error_mean : array_like
        A (Monte Carlo mean) error series over ``k = 0..K``.
    threshold : float
        The level the series must stay below.

    Returns
    -------
    int
        The smallest ``k`` with ``error_mean[j] < threshold`` for every ``j >= k``; 0 if the whole series
        is below, -1 if the last value is not.
    """
    e = np.asarray(error_mean, dtype=float)
    above = np.flatnonzero(e >= threshold)
    if len(above) == 0:
        return 0
    k = int(above[-1]) + 1
    return k if k < len(e) else -1


def advantage(local, decentralized):
    """The decentralized filter's advantage: local / decentralized late error (> 1: decentralized better).

    Parameters
    ----------
    local, decentralized : array_like
        Late-window errors of the two filters.

    Returns
    -------
    ndarray
    """
    return np.asarray(local, dtype=float) / np.asarray(decentralized, dtype=float)
