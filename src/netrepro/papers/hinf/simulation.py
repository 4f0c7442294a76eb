"""The resolved scenario of Section VI and the named phases of one step of its Monte Carlo simulation.

:func:`~netrepro.papers.hinf.model.simulate` runs these phases in this order at every step ``k``:
:func:`move_target` (the random walk (1), the evader (19)-(24)), :func:`measure` (the noise model
(2)-(4)), :func:`consensus_round` (the PI consensus (5) on the inputs (7)-(8)), :func:`update_filters`
(eqs (6) and (9) and their Kalman limits), :func:`move_agents` (the gradient law (12)-(18)) and
:func:`record_step`. :class:`Scenario` is the frozen, typed form of the dict :func:`.model.resolve_scenario`
returns; :func:`plan_filters` and :func:`initial_state` set the loop up, :func:`initial_fused_trace`
fills the fused trace (22) at ``k = 0``.

Three random streams are spawned from the scenario's seed: the initial estimate, the target and the
measurements; each phase draws from its own stream only, in the order the loop calls it, so the draws
(and every table built from them) do not depend on how the loop is cut into phases.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType

import numpy as np

from ...errors import InputError
from .algebra import I2, min_eig2, sym2
from .consensus import (CONSENSUS_DESIGNS, adjacency, component_membership, component_sums, laplacian,
                        pi_consensus_step, topology_changed)
from .evader import SOLVERS, evader_move
from .filters import congruence, hinf_update_batch
from .motion import control_law, sigma_gradient
from .noise import NoiseModel, geometry, noise_information, plane_norm, sample_noise

__all__ = ["FILTER_KINDS", "TARGET_MODES", "Scenario", "FilterPlan", "LoopState", "Record", "gaussian_factor",
           "gaussian_draws", "plan_filters", "initial_state", "new_record", "move_target", "measure", "consensus_round",
           "update_filters", "move_agents", "record_step", "initial_fused_trace"]

FILTER_KINDS = {
    "local": ("local", False), "decentralized": ("decentralized", False), "centralized": ("centralized", False),
    "kalman_local": ("local", True), "kalman_decentralized": ("decentralized", True),
    "kalman_centralized": ("centralized", True),
}
TARGET_MODES = ("random", "stationary", "evasive", "evasive_noise", "drift", "replay")

_EMPTY = MappingProxyType({})


def _frozen(mapping) -> Mapping:
    """A read-only copy of ``mapping`` (``None``: empty)."""
    return MappingProxyType(dict(mapping or {}))


@dataclass(frozen=True, eq=False)
class Scenario:
    """One resolved scenario of Section VI, typed and read-only (the input of :func:`.model.simulate`).

    Parameters
    ----------
    agents0 : ndarray, shape ``(N, 2)``
        Initial agent positions.
    target0 : ndarray, shape ``(2,)``
        Initial target position.
    target : str
        Target mode, one of :data:`TARGET_MODES` (``evasive_noise``: the evader's move plus white noise
        ``W_true``; ``drift``: a fixed heading per run, drawn uniformly, at the evader's step length;
        ``replay``: the path ``target_path``).
    W_true, W_filter : ndarray, shape ``(2, 2)``
        The target's process noise and the filters' design ``B W B^T``.
    A : ndarray, shape ``(2, 2)``
        Target dynamics.
    gamma : float
        The H-infinity attenuation level of eqs (6) and (9).
    Lbar : ndarray, shape ``(2, 2)``
        ``L^T Q L``.
    P0 : float
        ``Sigma_0 = P0 I`` and the initial estimate's spread.
    model : NoiseModel
        The noise model (2)-(4).
    radius : float
        Communication radius of the graph (25).
    consensus : Mapping
        ``gamma_c, h, K_p, K_i, iters``, optional ``design`` of :data:`.consensus.CONSENSUS_DESIGNS`.
    control : Mapping
        ``Gamma, v_max``, optional ``recursion`` (default True) and ``steer_on_truth``.
    evader : Mapping
        ``n_headings, n_iter, step``, optional ``solver`` (default ``mirror``).
    mobile : bool
        Whether the agents move by (12).
    driver : str
        The filter whose estimates steer the agents.
    filters : tuple of str
        Filter labels (names of :data:`FILTER_KINDS`, or labels of ``filter_base``).
    horizon, runs, seed : int
        Steps ``K``, Monte Carlo runs ``R``, seed of the three random streams.
    psd_floor : float
        Smallest eigenvalue kept in the consensus estimate ``C~`` of eq (9).
    filter_base, filter_gamma, filter_W_factor : Mapping
        label -> filter name (copies of a filter), its own gamma, its design W as a multiple of ``W_filter``.
    consensus_variants : Mapping
        label -> consensus entries replaced: one more decentralized filter on its own consensus.
    record_information : bool
        Keep the information sequences of eqs (6) and (9) (for gamma_0).
    target_path : ndarray, shape ``(R, K+1, 2)``, optional
        The recorded path of ``target="replay"``.
    fused_all : bool
        Fill the fused trace (22) at ``k = 0`` for every target (not only the evader).
    """

    agents0: np.ndarray
    target0: np.ndarray
    target: str
    W_true: np.ndarray
    W_filter: np.ndarray
    A: np.ndarray
    gamma: float
    Lbar: np.ndarray
    P0: float
    model: NoiseModel
    radius: float
    consensus: Mapping
    filters: tuple
    horizon: int
    runs: int
    seed: int
    mobile: bool = False
    control: Mapping = field(default_factory=lambda: _EMPTY)
    evader: Mapping = field(default_factory=lambda: _EMPTY)
    driver: str = "decentralized"
    psd_floor: float = 1e-9
    filter_base: Mapping = field(default_factory=lambda: _EMPTY)
    filter_gamma: Mapping = field(default_factory=lambda: _EMPTY)
    filter_W_factor: Mapping = field(default_factory=lambda: _EMPTY)
    consensus_variants: Mapping = field(default_factory=lambda: _EMPTY)
    record_information: bool = False
    target_path: np.ndarray | None = None
    fused_all: bool = True

    @classmethod
    def from_mapping(cls, sc) -> "Scenario":
        """The scenario of a dict of :func:`.model.resolve_scenario` (or a :class:`Scenario`, returned as is).

        Parameters
        ----------
        sc : Mapping or Scenario
            The keys of the attributes; the optional ones may be left out. Unknown keys are ignored.

        Returns
        -------
        Scenario

        Raises
        ------
        InputError
            If the target mode is unknown or a required key is missing.
        """
        if isinstance(sc, Scenario):
            return sc
        missing = [k for k in _REQUIRED if k not in sc]
        if missing:
            raise InputError(f"scenario lacks {missing}")
        if sc["target"] not in TARGET_MODES:
            raise InputError(f"unknown target mode {sc['target']!r}")
        path = sc.get("target_path")
        variants = sc.get("consensus_variants") or {}
        return cls(
            agents0=np.asarray(sc["agents0"], dtype=float), target0=np.asarray(sc["target0"], dtype=float),
            target=str(sc["target"]), W_true=np.asarray(sc["W_true"], dtype=float),
            W_filter=np.asarray(sc["W_filter"], dtype=float), A=np.asarray(sc["A"], dtype=float),
            gamma=float(sc["gamma"]), Lbar=np.asarray(sc["Lbar"], dtype=float), P0=float(sc["P0"]),
            model=sc["model"], radius=sc["radius"], consensus=_frozen(sc["consensus"]),
            mobile=bool(sc.get("mobile", False)), filters=tuple(sc["filters"]), horizon=int(sc["horizon"]),
            runs=int(sc["runs"]), seed=int(sc["seed"]), control=_frozen(sc.get("control")),
            evader=_frozen(sc.get("evader")), driver=sc.get("driver", "decentralized"),
            psd_floor=float(sc.get("psd_floor", 1e-9)), filter_base=_frozen(sc.get("filter_base")),
            filter_gamma=_frozen(sc.get("filter_gamma")), filter_W_factor=_frozen(sc.get("filter_W_factor")),
            consensus_variants=MappingProxyType({k: _frozen(v) for k, v in variants.items()}),
            record_information=bool(sc.get("record_information", False)),
            target_path=None if path is None else np.asarray(path, dtype=float),
            fused_all=bool(sc.get("fused_all", True)),
        )

    @property
    def n_agents(self) -> int:
        """``N``, the number of agents."""
        return int(self.agents0.shape[0])

    @property
    def solver(self) -> str:
        """The evader's inner solver of (24)."""
        return self.evader.get("solver", "mirror")


# the keys a scenario cannot leave out
_REQUIRED = ("agents0", "target0", "target", "W_true", "W_filter", "A", "gamma", "Lbar", "P0", "model", "radius",
             "consensus", "filters", "horizon", "runs", "seed")


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


@dataclass(frozen=True, eq=False)
class FilterPlan:
    """Which filters run, and how they are grouped: the filters of one group see the same measurements.

    Parameters
    ----------
    names : tuple of str
        Every filter label, the scenario's filters then its consensus variants.
    kind_of : Mapping
        label -> ``(kind, is_kalman)`` with kind in {``local``, ``decentralized``, ``centralized``}.
    gi_of : Mapping
        label -> ``gamma^{-2}`` of its eq (6)/(9) (0 for a Kalman filter).
    bwb_of : Mapping
        label -> its design ``B W B^T``.
    cvars : Mapping
        consensus id -> its consensus entries; ``None`` is the scenario's own consensus (5).
    groups : Mapping
        group key -> its labels (stacked on a leading axis and updated together).
    g_kind, g_cons : Mapping
        group key -> its kind; -> the consensus id it reads.
    bwb_g, gi_g : Mapping
        group key -> its filters' ``B W B^T`` stacked ``(F, 2, 2)``; their ``gamma^{-2}`` ``(F,)``.
    slot : Mapping
        label -> ``(group key, index in the group)``.
    cons_ids : tuple
        The consensus runs some filter reads, in the order of ``cvars``.
    """

    names: tuple
    kind_of: Mapping
    gi_of: Mapping
    bwb_of: Mapping
    cvars: Mapping
    groups: Mapping
    g_kind: Mapping
    g_cons: Mapping
    bwb_g: Mapping
    gi_g: Mapping
    slot: Mapping
    cons_ids: tuple


def plan_filters(sc: Scenario) -> FilterPlan:
    """Resolve the scenario's filters: their kinds, attenuation levels, design noises, consensus and groups.

    Every filter is an eq (6) filter (``local`` on its own measurements, ``centralized`` on all of them) or an
    eq (9) filter (``decentralized``, on the consensus (5) estimates ``N C~``, ``N y~``); a Kalman filter is
    the same recursion with ``gamma^{-2} = 0``.

    Parameters
    ----------
    sc : Scenario
        The resolved scenario.

    Returns
    -------
    FilterPlan

    Raises
    ------
    InputError
        If a filter name, a consensus design or the driver is unknown, or a consensus variant has the name of
        a filter.
    """
    names = list(sc.filters)
    base = sc.filter_base
    for name in names:
        if base.get(name, name) not in FILTER_KINDS:
            raise InputError(f"unknown filter {name!r}; expected one of {sorted(FILTER_KINDS)}")
    g2 = sc.gamma ** -2.0
    BWB = sc.W_filter
    kind_of = {n: FILTER_KINDS[base.get(n, n)] for n in names}
    own_gamma, own_W = sc.filter_gamma, sc.filter_W_factor
    gi_of = {n: 0.0 if kind_of[n][1] else (float(own_gamma[n]) ** -2.0 if n in own_gamma else g2) for n in names}
    bwb_of = {n: float(own_W[n]) * BWB if n in own_W else BWB for n in names}
    cvars = {None: sc.consensus}
    for lab, over in sc.consensus_variants.items():
        if lab in names:
            raise InputError(f"consensus variant {lab!r} has the name of a filter")
        cvars[lab] = {**sc.consensus, **dict(over)}
        names.append(lab)
        kind_of[lab], gi_of[lab], bwb_of[lab] = FILTER_KINDS["decentralized"], g2, BWB
    for c in cvars.values():
        if c.get("design", "pi") not in CONSENSUS_DESIGNS:
            raise InputError(f"unknown consensus design {c.get('design')!r}; expected one of {CONSENSUS_DESIGNS}")
    if sc.mobile and sc.driver not in names:
        raise InputError(f"driver filter {sc.driver!r} must be among the filters {names}")
    groups, g_cons = {}, {}
    for name in names:
        key = name if name in cvars else kind_of[name][0]
        groups.setdefault(key, []).append(name)
        g_cons[key] = name if name in cvars else None
    return FilterPlan(
        names=tuple(names), kind_of=kind_of, gi_of=gi_of, bwb_of=bwb_of, cvars=cvars, groups=groups,
        g_kind={key: kind_of[labs[0]][0] for key, labs in groups.items()}, g_cons=g_cons,
        bwb_g={key: np.stack([bwb_of[n] for n in labs]) for key, labs in groups.items()},
        gi_g={key: np.array([gi_of[n] for n in labs]) for key, labs in groups.items()},
        slot={n: (kind, i) for kind, labs in groups.items() for i, n in enumerate(labs)},
        cons_ids=tuple(cid for cid in cvars if cid in g_cons.values()))


def _connected(adj):
    """Whether each run's graph is connected: agent 0 reaches every agent (boolean squaring; the same answer as
    ``lambda_2(laplacian) > 1e-9``, about four times faster)."""
    return component_membership(adj)[..., 0, :].min(-1) > 0


@dataclass(eq=False)
class LoopState:
    """What the simulation carries from step to step (mutable; the phases return its new values).

    Parameters
    ----------
    x : ndarray, shape ``(R, 2)``
        Target positions.
    P : ndarray, shape ``(R, N, 2)``
        Agent positions.
    est, cov, delta : dict
        group key -> the stacked estimates ``xhat``, covariances ``Sigma`` and priors ``Delta`` of eq (6).
    v, w : dict
        consensus id -> the PI estimator's states of eq (5) (created at the first round).
    Ct, yt : dict
        consensus id -> the consensus estimates ``C~`` (floored) and ``y~`` of eq (9).
    dsig : ndarray, shape ``(2, R, N, 2, 2)``
        The agents' copies of ``d Sigma / d r`` and ``d Sigma / d theta`` (eq (14)).
    adj, lap : ndarray
        The graph (25) and its Laplacian.
    reset : ndarray of bool, shape ``(R,)``
        Runs whose graph changed at the last move (the ``pi_reset`` consensus zeroes their ``w``).
    changes : ndarray of int, shape ``(R,)``
        Number of topology changes so far.
    max_degree : int
        Largest degree seen.
    n_psd_fix : int
        Number of floored ``C~`` matrices of the scenario's own consensus.
    ev_state : dict
        The evader's weights from move to move.
    drift : ndarray or None
        The ``drift`` target's step per run.
    """

    x: np.ndarray
    P: np.ndarray
    est: dict
    cov: dict
    adj: np.ndarray
    lap: np.ndarray
    dsig: np.ndarray
    reset: np.ndarray
    changes: np.ndarray
    max_degree: int
    drift: np.ndarray | None = None
    delta: dict = field(default_factory=dict)
    v: dict = field(default_factory=dict)
    w: dict = field(default_factory=dict)
    Ct: dict = field(default_factory=dict)
    yt: dict = field(default_factory=dict)
    n_psd_fix: int = 0
    ev_state: dict = field(default_factory=dict)


def initial_state(sc: Scenario, plan: FilterPlan, rng0: np.random.Generator, rng_t: np.random.Generator):
    """The state at ``k = 0``: target, agents, the filters' ``xhat_0 ~ N(x_0, P0 I)``, ``Sigma_0 = P0 I``, graph.

    Draws, in this order: ``R`` headings from ``rng_t`` (``drift`` target only), then ``R x 2`` standard
    normals from ``rng0`` (the initial estimate, shared by every filter).

    Parameters
    ----------
    sc : Scenario
        The resolved scenario.
    plan : FilterPlan
        The filters of :func:`plan_filters`.
    rng0, rng_t : numpy.random.Generator
        The initial estimate's and the target's streams.

    Returns
    -------
    LoopState
    """
    R, N = sc.runs, sc.n_agents
    P = np.broadcast_to(sc.agents0, (R,) + sc.agents0.shape).copy()
    drift = None
    if sc.target == "drift":
        heading = rng_t.uniform(0.0, 2 * np.pi, size=R)
        drift = float(sc.evader["step"]) * np.stack([np.cos(heading), np.sin(heading)], -1)
    x = np.broadcast_to(sc.target0, (R, 2)).copy()
    x0hat = x + np.sqrt(sc.P0) * rng0.standard_normal((R, 2))
    Sig0 = sc.P0 * I2
    est, cov = {}, {}
    for kind, labs in plan.groups.items():
        central = plan.g_kind[kind] == "centralized"
        shape = (len(labs), R) if central else (len(labs), R, N)
        est[kind] = np.broadcast_to(x0hat if central else x0hat[:, None, :], shape + (2,)).copy()
        cov[kind] = np.broadcast_to(Sig0, shape + (2, 2)).copy()
    adj = adjacency(P, sc.radius)
    return LoopState(x=x, P=P, est=est, cov=cov, adj=adj, lap=laplacian(adj), dsig=np.zeros((2, R, N, 2, 2)),
                     reset=np.zeros(R, dtype=bool), changes=np.zeros(R, dtype=int), max_degree=int(adj.sum(-1).max()),
                     drift=drift)


def move_target(sc: Scenario, k: int, x, P, rng_t: np.random.Generator, Wt_factor, drift=None, ev_state=None):
    """The target's move to step ``k``.

    ``random``: the random walk ``x_k = A x_{k-1} + w_{k-1}``, ``w ~ N(0, W_true)`` (eq (1); no draw if
    ``W_true = 0``); ``evasive``: the evader's move (19)-(24) against the agents at ``P``; ``evasive_noise``:
    that move plus ``w``; ``drift``: ``x + drift``; ``replay``: ``target_path[:, k]``; ``stationary``: ``x``.

    Parameters
    ----------
    sc : Scenario
        The resolved scenario.
    k : int
        The step (1 to ``K``).
    x : ndarray, shape ``(R, 2)``
        Target positions at ``k - 1``.
    P : ndarray, shape ``(R, N, 2)``
        Agent positions at ``k - 1`` (the evader's input).
    rng_t : numpy.random.Generator
        The target's stream (``R x 2`` standard normals drawn for ``random`` with ``W_true != 0`` and
        ``evasive_noise``).
    Wt_factor : ndarray, shape ``(2, 2)``
        :func:`gaussian_factor` of ``W_true``.
    drift : ndarray, shape ``(R, 2)``, optional
        The ``drift`` target's step.
    ev_state : dict, optional
        The evader's weights, updated in place.

    Returns
    -------
    x : ndarray, shape ``(R, 2)``
        Target positions at ``k``.
    fused : ndarray, shape ``(R,)``, or None
        The evader's fused trace (22) at its chosen move (evasive targets), else None.
    """
    target, fz = sc.target, None
    if target == "random":
        x = x @ sc.A.T + gaussian_draws(rng_t, Wt_factor, sc.runs) if np.any(sc.W_true) else x @ sc.A.T
    elif target in ("evasive", "evasive_noise"):
        ev = sc.evader
        x, fz = evader_move(x, P, sc.model, float(ev["step"]), int(ev["n_headings"]), int(ev["n_iter"]), sc.solver,
                            state=ev_state)
        if target == "evasive_noise":
            x = x + gaussian_draws(rng_t, Wt_factor, sc.runs)
    elif target == "drift":
        x = x + drift
    elif target == "replay":  # a recorded path (the other streams of random numbers are unaffected)
        x = sc.target_path[:, k]
    return x, fz


def measure(x, P, model: NoiseModel, rng_m: np.random.Generator):
    """Every agent's measurement of the target, eqs (2)-(4), in information form.

    ``y_i = x + m_i``, ``m_i ~ N(0, M_i)`` with ``M_i`` of eq (3) from the true range and bearing.

    Parameters
    ----------
    x : ndarray, shape ``(R, 2)``
        Target positions.
    P : ndarray, shape ``(R, N, 2)``
        Agent positions.
    model : NoiseModel
        The noise model (2)-(4).
    rng_m : numpy.random.Generator
        The measurements' stream (``sample_noise``'s draws, ``R x N x 2`` normals).

    Returns
    -------
    Minv : ndarray, shape ``(R, N, 2, 2)``
        ``C_i^T M_i^{-1} C_i`` (``C_i = I``).
    yinfo : ndarray, shape ``(R, N, 2)``
        ``C_i^T M_i^{-1} y_i``.
    """
    r, th = geometry(x, P)
    Minv = noise_information(r, th, model)
    y = x[:, None, :] + sample_noise(rng_m, r, th, model)
    return Minv, (Minv @ y[..., None])[..., 0]


def consensus_round(plan: FilterPlan, st: LoopState, Minv, yinfo, psd_floor: float, lap_complete=None):
    """One round of every consensus some filter reads: the PI estimator (5) on ``u_i`` of eqs (7)-(8).

    ``u_i = (C_i^T M_i^{-1} C_i, C_i^T M_i^{-1} y_i)``; ``iters`` steps of eq (5) (``design`` ``pi``; ``pi_reset``
    zeroes ``w`` in the runs whose graph just changed; ``complete`` runs on the complete graph) or the exact sums
    over each agent's connected piece divided by ``N`` (``exact_component``). The estimate ``C~`` is floored at
    ``psd_floor`` (the eq (9) filter needs it positive semi-definite).

    Parameters
    ----------
    plan : FilterPlan
        The filters of :func:`plan_filters`.
    st : LoopState
        Its ``v``, ``w`` (advanced), ``Ct``, ``yt`` (set) and ``n_psd_fix`` (counted, own consensus only) change;
        ``adj``, ``lap``, ``reset`` are read.
    Minv, yinfo : ndarray
        :func:`measure`'s output.
    psd_floor : float
        Smallest eigenvalue kept in ``C~``.
    lap_complete : ndarray, shape ``(R, N, N)``, optional
        The complete graph's Laplacian (a ``complete`` design only).

    Returns
    -------
    LoopState
        ``st``.
    """
    if not plan.cons_ids:
        return st
    R, N = Minv.shape[:2]
    u = np.concatenate([Minv.reshape(R, N, 4), yinfo], -1)
    for cid in plan.cons_ids:
        c = plan.cvars[cid]
        design = c.get("design", "pi")
        if design == "exact_component":  # exact sums over each agent's connected piece, divided by N for (9)
            st.v[cid] = component_sums(u, st.adj) / N
        else:
            if cid not in st.v:
                st.v[cid], st.w[cid] = u.copy(), np.zeros_like(u)
            if design == "pi_reset" and st.reset.any():
                st.w[cid][st.reset] = 0.0
            lap_c = lap_complete if design == "complete" else st.lap
            for _ in range(int(c["iters"])):
                st.v[cid], st.w[cid] = pi_consensus_step(st.v[cid], st.w[cid], u, lap_c, c["gamma_c"], c["h"],
                                                         c["K_p"], c["K_i"])
        st.Ct[cid], nfix = _psd_floor(st.v[cid][..., :4].reshape(R, N, 2, 2), psd_floor)
        st.yt[cid] = st.v[cid][..., 4:]
        if cid is None:
            st.n_psd_fix += nfix
    return st


def _psd_floor(C, floor):
    """Shift 2x2 symmetric matrices up so their smallest eigenvalue is at least ``floor``; count the shifts."""
    C = sym2(C)
    low = min_eig2(C)
    shift = np.maximum(floor - low, 0.0)
    return C + shift[..., None, None] * I2, int(np.count_nonzero(shift))


def update_filters(sc: Scenario, plan: FilterPlan, st: LoopState, Minv, yinfo):
    """Every filter's step: eq (6) (``local``: each agent's own information; ``centralized``: their sums) and
    eq (9) (``decentralized``: eq (6) with ``S = N C~``, ``y_info = N y~`` of its consensus), Kalman if
    ``gamma^{-2} = 0``.

    Parameters
    ----------
    sc : Scenario
        The resolved scenario.
    plan : FilterPlan
        The filters of :func:`plan_filters`.
    st : LoopState
        Its ``est``, ``cov`` and ``delta`` are replaced; ``Ct``, ``yt`` read.
    Minv, yinfo : ndarray
        :func:`measure`'s output.

    Returns
    -------
    LoopState
        ``st``.

    Raises
    ------
    FilterDoesNotExist
        If an H-infinity filter does not exist (gamma below gamma_0) at this step.
    """
    N = Minv.shape[1]
    for kind in plan.groups:  # kind: the group's key
        g_kind = plan.g_kind[kind]
        if g_kind == "local":
            y_k, S_k = yinfo, Minv
        elif g_kind == "centralized":
            y_k, S_k = yinfo.sum(1), Minv.sum(1)
        else:  # eq (9) is eq (6) with S = N C~, y_info = N y~ (decentralized_update)
            y_k, S_k = N * st.yt[plan.g_cons[kind]], N * st.Ct[plan.g_cons[kind]]
        st.est[kind], st.cov[kind], st.delta[kind], _ = hinf_update_batch(st.est[kind], st.cov[kind], y_k, S_k, sc.A,
                                                                          plan.bwb_g[kind], plan.gi_g[kind], sc.Lbar)
    return st


def move_agents(sc: Scenario, plan: FilterPlan, st: LoopState, Minv):
    """The agents' decentralized gradient move, eqs (12)-(18), each agent steering by its own estimate.

    Each agent ``i`` differentiates ``tr Sigma_i`` of the driver filter with respect to its range and bearing
    to its estimated target (eqs (13)-(16), with the recursion (14) of ``d Sigma`` unless
    ``control["recursion"]`` is false) and moves by the saturated law (12) (:func:`.motion.control_law`);
    then the graph (25) is rebuilt and its changes counted.

    Parameters
    ----------
    sc : Scenario
        A mobile scenario.
    plan : FilterPlan
        The filters of :func:`plan_filters`.
    st : LoopState
        Its ``P``, ``dsig``, ``adj``, ``lap``, ``reset``, ``changes`` and ``max_degree`` change; the driver's
        ``est``, ``delta`` and the own consensus's ``Ct`` are read.
    Minv : ndarray, shape ``(R, N, 2, 2)``
        This step's information (the ``S`` of a local driver).

    Returns
    -------
    LoopState
        ``st``.
    """
    ctrl, driver, model = sc.control, sc.driver, sc.model
    N = st.P.shape[1]
    group, i = plan.slot[driver]
    xh = st.est[group][i]  # (R, N, 2); ``steer_on_truth`` (a cause test) steers by the true position
    xh = np.broadcast_to(st.x[:, None, :], xh.shape) if ctrl.get("steer_on_truth") else xh
    d = xh - st.P
    rh, thh = np.hypot(d[..., 0], d[..., 1]), np.arctan2(d[..., 1], d[..., 0])
    rh = np.maximum(rh, 1e-6)
    _, dMr, dMt = noise_information(rh, thh, model, derivatives=True)
    Delta = st.delta[group][i]
    S_hat = N * st.Ct[None] if plan.kind_of[driver][0] == "decentralized" else Minv
    grads = []
    for z, dM in enumerate((dMr, dMt)):
        dDelta = congruence(sc.A, st.dsig[z]) if ctrl.get("recursion", True) else np.zeros_like(Delta)
        _, dS = sigma_gradient(Delta, dDelta, S_hat, dM, plan.gi_of[driver], sc.Lbar)
        st.dsig[z] = dS
        grads.append(dS[..., 0, 0] + dS[..., 1, 1])
    st.P = st.P + control_law(grads[0], grads[1], rh, thh, float(ctrl["Gamma"]), float(ctrl["v_max"]))
    adj_new = adjacency(st.P, sc.radius)
    st.reset = topology_changed(st.adj, adj_new)
    st.changes += st.reset
    st.adj = adj_new
    st.lap = laplacian(adj_new)
    st.max_degree = max(st.max_degree, int(adj_new.sum(-1).max()))
    return st


@dataclass(eq=False)
class Record:
    """The simulation's outputs, filled step by step (see :func:`.model.simulate` for their meaning).

    Parameters
    ----------
    err_g, tr_g : dict
        group key -> its filters' errors ``(F, R, n, K+1)`` and mean ``tr Sigma`` ``(F, R, K+1)``.
    tgt, ags : ndarray
        Target ``(R, K+1, 2)`` and agent ``(R, K+1, N, 2)`` positions.
    fused : ndarray, shape ``(R, K+1)``
        The fused trace (22) (NaN where not computed).
    connected, conn_runs : ndarray
        Fraction of runs with a connected graph ``(K+1,)``; per run ``(R, K+1)``.
    info_hist : dict or None
        The S sequences of eqs (6) and (9) (``record_information``).
    """

    err_g: dict
    tr_g: dict
    tgt: np.ndarray
    ags: np.ndarray
    fused: np.ndarray
    connected: np.ndarray
    conn_runs: np.ndarray
    info_hist: dict | None


def new_record(sc: Scenario, plan: FilterPlan, st: LoopState) -> Record:
    """The output arrays with step 0 filled: errors ``|xhat_0 - x_0|``, ``tr Sigma_0 = 2 P0``, positions, graph.

    Parameters
    ----------
    sc : Scenario
        The resolved scenario.
    plan : FilterPlan
        The filters of :func:`plan_filters`.
    st : LoopState
        The state of :func:`initial_state`.

    Returns
    -------
    Record
    """
    R, K, N = sc.runs, sc.horizon, sc.n_agents
    err_g, tr_g = {}, {}
    for kind, labs in plan.groups.items():
        central = plan.g_kind[kind] == "centralized"
        err_g[kind] = np.empty((len(labs), R, 1 if central else N, K + 1))
        tr_g[kind] = np.empty((len(labs), R, K + 1))
        e = plane_norm(st.est[kind] - (st.x if central else st.x[:, None, :]))
        err_g[kind][..., 0] = e if e.ndim == 3 else e[..., None]
        tr_g[kind][:, :, 0] = 2 * sc.P0
    tgt = np.empty((R, K + 1, 2))
    tgt[:, 0] = st.x
    ags = np.empty((R, K + 1, N, 2))
    ags[:, 0] = st.P
    conn_runs = np.empty((R, K + 1), dtype=bool)
    conn_runs[:, 0] = _connected(st.adj)
    connected = np.empty(K + 1)
    connected[0] = conn_runs[:, 0].mean()
    info = ({"local": np.empty((K, R, N, 2, 2)), "decentralized": np.empty((K, R, N, 2, 2))}
            if sc.record_information else None)
    return Record(err_g=err_g, tr_g=tr_g, tgt=tgt, ags=ags, fused=np.full((R, K + 1), np.nan), connected=connected,
                  conn_runs=conn_runs, info_hist=info)


def record_step(sc: Scenario, plan: FilterPlan, st: LoopState, rec: Record, k: int, Minv) -> Record:
    """Write step ``k``: each filter's errors ``|xhat - x|`` and mean ``tr Sigma``, positions, connectivity,
    and (``record_information``) the S sequences of eqs (6) and (9).

    Parameters
    ----------
    sc : Scenario
        The resolved scenario.
    plan : FilterPlan
        The filters of :func:`plan_filters`.
    st : LoopState
        The loop's state after the step's phases.
    rec : Record
        Filled in place.
    k : int
        The step (1 to ``K``).
    Minv : ndarray, shape ``(R, N, 2, 2)``
        This step's information ``C_i^T M_i^{-1} C_i`` (:func:`measure`).

    Returns
    -------
    Record
        ``rec``.
    """
    for kind in plan.groups:
        est, cov = st.est[kind], st.cov[kind]
        if plan.g_kind[kind] == "centralized":
            rec.err_g[kind][:, :, 0, k] = plane_norm(est - st.x)
            rec.tr_g[kind][:, :, k] = cov[..., 0, 0] + cov[..., 1, 1]
        else:
            rec.err_g[kind][:, :, :, k] = plane_norm(est - st.x[:, None, :])
            rec.tr_g[kind][:, :, k] = (cov[..., 0, 0] + cov[..., 1, 1]).mean(2)
    if rec.info_hist is not None:
        if None in plan.cons_ids:
            rec.info_hist["decentralized"][k - 1] = Minv.shape[1] * st.Ct[None]
        rec.info_hist["local"][k - 1] = Minv
    rec.conn_runs[:, k] = _connected(st.adj) if sc.mobile else rec.conn_runs[:, 0]
    rec.connected[k] = rec.conn_runs[:, k].mean() if sc.mobile else rec.connected[0]
    rec.tgt[:, k] = st.x
    rec.ags[:, k] = st.P
    return rec


def initial_fused_trace(sc: Scenario, x0, P0):
    """The fused trace (22) at ``k = 0``: ``min over lambda of tr Q_fused`` of the agents' informations at the
    initial geometry, by the evader's own inner solver of (24).

    Parameters
    ----------
    sc : Scenario
        The resolved scenario.
    x0 : ndarray, shape ``(R, 2)``
        Target positions at ``k = 0``.
    P0 : ndarray, shape ``(R, N, 2)``
        Agent positions at ``k = 0``.

    Returns
    -------
    ndarray, shape ``(R,)``
    """
    r, th = geometry(x0, P0)
    solver = sc.solver
    # a single call: the exact solver's numpy form (compiling its kernel would cost more than it saves)
    kw = {"kernel": "numpy"} if solver == "exact" else {}
    return SOLVERS[solver](noise_information(r, th, sc.model), int(sc.evader.get("n_iter", 40)), **kw)[0]

