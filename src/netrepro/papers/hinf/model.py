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
from .algebra import I2
from .consensus import complete_laplacian
from .filters import FilterDoesNotExist, minimum_attenuation
from .noise import NoiseModel
from .simulation import (FILTER_KINDS, Scenario, consensus_round, gaussian_draws, gaussian_factor, initial_fused_trace,
                         initial_state, measure, move_agents, move_target, new_record, plan_filters, record_step,
                         update_filters)

__all__ = ["FILTER_KINDS", "SCENARIOS", "KINDS", "layout_positions", "resolve_scenario", "simulate", "Scenario",
           "FilterDoesNotExist", "attenuation_levels", "window_means", "paired_z", "run_paired", "bonferroni_z", "tag_z",
           "settle_step", "advantage", "gaussian_factor", "gaussian_draws"]

KINDS = ("local", "decentralized", "centralized")

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


def simulate(sc) -> dict:
    """Monte Carlo simulation of one scenario of Section VI, vectorised over runs and agents.

    Parameters
    ----------
    sc : Mapping or Scenario
        Resolved scenario (a dict of :func:`resolve_scenario`, read by
        :meth:`~netrepro.papers.hinf.simulation.Scenario.from_mapping`): ``agents0 (N, 2)``, ``target0 (2,)``, ``target`` in
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

    Notes
    -----
    Each step runs the named phases of :mod:`~netrepro.papers.hinf.simulation`: move the target, measure,
    consensus round, update the filters, move the agents (mobile scenarios), record.
    """
    sc = Scenario.from_mapping(sc)
    if sc.target in ("evasive", "evasive_noise") and sc.solver == "exact":
        # numba: the certified evader (evader_move with a state) and the filters then run compiled (bit-identical);
        # its load (~0.5 s) pays for itself in any evasive loop of a step (fig6_paths: 2.47 s -> 1.52 s of CPU)
        from . import evader_kernels  # noqa: F401
    plan = plan_filters(sc)
    rng0, rng_t, rng_m = (np.random.default_rng(s) for s in np.random.SeedSequence(sc.seed).spawn(3))
    st = initial_state(sc, plan, rng0, rng_t)
    rec = new_record(sc, plan, st)
    Wt_factor = gaussian_factor(sc.W_true)  # the target's noise N(0, W_true): rng.multivariate_normal's factor, once
    lap_complete = (np.broadcast_to(complete_laplacian(sc.n_agents), (sc.runs, sc.n_agents, sc.n_agents))
                    if any(c.get("design", "pi") == "complete" for c in plan.cvars.values()) else None)
    for k in range(1, sc.horizon + 1):
        st.x, fz = move_target(sc, k, st.x, st.P, rng_t, Wt_factor, st.drift, st.ev_state)
        if fz is not None:
            rec.fused[:, k] = fz
        Minv, yinfo = measure(st.x, st.P, sc.model, rng_m)
        consensus_round(plan, st, Minv, yinfo, sc.psd_floor, lap_complete)
        update_filters(sc, plan, st, Minv, yinfo)
        if sc.mobile:
            move_agents(sc, plan, st, Minv)
        record_step(sc, plan, st, rec, k, Minv)
    if sc.target == "evasive" or sc.fused_all:
        rec.fused[:, 0] = initial_fused_trace(sc, rec.tgt[:, 0], rec.ags[:, 0])
    slot = plan.slot
    return {"errors": {n: rec.err_g[slot[n][0]][slot[n][1]] for n in plan.names}, "target": rec.tgt,
            "agents": rec.ags, "connected": rec.connected, "max_degree": st.max_degree, "fused_trace": rec.fused,
            "trace_sigma": {n: rec.tr_g[slot[n][0]][slot[n][1]] for n in plan.names}, "n_psd_fix": st.n_psd_fix,
            "connected_runs": rec.conn_runs, "information": rec.info_hist, "topology_changes": st.changes}


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
