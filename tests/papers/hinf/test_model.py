"""Tests of the `hinf` mathematics (netrepro.papers.hinf math modules): each equation against an independent computation."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import minimize

from netrepro.papers.hinf.algebra import inv2, min_eig2, rotation
from netrepro.papers.hinf.consensus import (
    adjacency, consensus_h_max, laplacian, pi_consensus_modes, pi_consensus_spectral_radius, pi_consensus_step,
    run_pi_consensus,
)
from netrepro.papers.hinf.evader import evader_move, fused_trace, min_fused_trace, overbounding_ellipse
from netrepro.papers.hinf.filters import (
    FilterDoesNotExist, decentralized_update, hinf_update, kalman_update, minimum_attenuation,
)
from netrepro.papers.hinf.model import layout_positions, simulate
from netrepro.papers.hinf.motion import control_law, printed_control_law, printed_sigma_gradient, sigma_gradient
from netrepro.papers.hinf.noise import (
    NoiseModel, geometry, noise_covariance, noise_information, printed_dinfo_dtheta, sample_noise,
)

MODEL = NoiseModel(0.3528, 15.625, 0.0008, 5.0)
I2 = np.eye(2)


def _agents(n=10, radius=40.0, spacing=20.0, start=-90.0):
    return layout_positions({"n": n, "radius": radius, "spacing_deg": spacing, "start_deg": start})


def _scenario(**kw):
    sc = {
        "agents0": _agents(), "target0": np.zeros(2), "target": "random", "W_true": 0.01 * I2, "W_filter": 0.01 * I2,
        "A": I2, "gamma": 3.0, "Lbar": I2, "P0": 4.0, "psd_floor": 1e-9, "model": MODEL, "radius": 20.0,
        "consensus": {"gamma_c": 0.5, "h": 0.5, "K_p": 0.4, "K_i": 0.2, "iters": 1},
        "control": {"Gamma": 20000.0, "v_max": 0.5, "recursion": True},
        "evader": {"n_headings": 8, "n_iter": 20, "step": 0.14}, "mobile": False, "driver": "decentralized",
        "filters": ["local", "decentralized", "centralized"], "horizon": 30, "runs": 6, "seed": 3,
    }
    sc.update(kw)
    return sc


# ----------------------------------------------------------------------------------- algebra, noise model
def test_inv2_and_min_eig_match_numpy():
    rng = np.random.default_rng(0)
    a = rng.normal(size=(5, 3, 2, 2))
    np.testing.assert_allclose(inv2(a), np.linalg.inv(a), rtol=1e-10, atol=1e-12)
    s = a + np.swapaxes(a, -1, -2)
    np.testing.assert_allclose(min_eig2(s), np.linalg.eigvalsh(s)[..., 0], atol=1e-12)


def test_noise_covariance_eq3_4_by_sampling():
    rng = np.random.default_rng(1)
    r, th = 30.0, 0.4
    m = sample_noise(rng, np.full(200_000, r), np.full(200_000, th), MODEL)
    M = noise_covariance(r, th, MODEL)
    np.testing.assert_allclose(np.cov(m.T), M, rtol=0.02, atol=0.01)
    fr = MODEL.a2 * (r - MODEL.a1) ** 2 + MODEL.a0
    np.testing.assert_allclose(np.linalg.eigvalsh(M), [fr, MODEL.alpha * fr])
    # the range axis is the line of sight
    los = rotation(th)[:, 0]
    np.testing.assert_allclose(los @ M @ los, fr)


def test_noise_sweet_spot_is_a1():
    r = np.linspace(0, 50, 50001)
    tr = np.trace(noise_covariance(r, np.zeros_like(r), MODEL), axis1=-2, axis2=-1)
    assert abs(r[np.argmin(tr)] - MODEL.a1) < 1e-3
    assert np.isclose(tr.min(), MODEL.a0 * (1 + MODEL.alpha))


@pytest.mark.parametrize("r,th", [(5.0, 0.3), (15.625, 2.0), (40.0, -1.2)])
def test_information_derivatives_eq17_against_finite_differences(r, th):
    eps = 1e-6
    _, dr, dt = noise_information(r, th, MODEL, derivatives=True)
    fd_r = (noise_information(r + eps, th, MODEL) - noise_information(r - eps, th, MODEL)) / (2 * eps)
    fd_t = (noise_information(r, th + eps, MODEL) - noise_information(r, th - eps, MODEL)) / (2 * eps)
    np.testing.assert_allclose(dr, fd_r, atol=1e-8)
    np.testing.assert_allclose(dt, fd_t, atol=1e-7)
    np.testing.assert_allclose(noise_information(r, th, MODEL), np.linalg.inv(noise_covariance(r, th, MODEL)))


def test_printed_bearing_derivative_is_wrong():
    r, th = 45.0, 0.9
    eps = 1e-6
    fd_t = (noise_information(r, th + eps, MODEL) - noise_information(r, th - eps, MODEL)) / (2 * eps)
    assert np.linalg.norm(printed_dinfo_dtheta(r, th, MODEL) - fd_t) > 0.5 * np.linalg.norm(fd_t)


def test_geometry_and_adjacency():
    r, th = geometry(np.array([3.0, 4.0]), np.zeros((1, 2)))
    assert np.isclose(r[0], 5.0) and np.isclose(th[0], np.arctan2(4, 3))
    adj = adjacency(_agents(), 20.0)
    assert adj.sum(1).max() == 2 and np.all(adj.sum(1) >= 1)
    lam = np.linalg.eigvalsh(laplacian(adj))
    assert lam[1] > 1e-6  # connected path


# ----------------------------------------------------------------------------------- PI consensus (5)
def _random_connected_graph(rng, n=8):
    while True:
        p = rng.uniform(0, 40, size=(n, 2))
        adj = adjacency(p, 20.0)
        lap = laplacian(adj)
        if np.linalg.eigvalsh(lap)[1] > 1e-6:
            return lap


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_pi_consensus_tracks_average_with_zero_steady_state_error(seed):
    rng = np.random.default_rng(seed)
    lap = _random_connected_graph(rng)
    u = rng.normal(size=(lap.shape[0], 3))
    gc, kp, ki = 1.0, 0.3, 0.3
    h = 0.5 * consensus_h_max(lap, gc, kp, ki)
    # step-by-step iteration (the definition) agrees with the exact matrix-power iteration
    v, w = u.copy(), np.zeros_like(u)
    for _ in range(50):
        v, w = pi_consensus_step(v, w, u, lap, gc, h, kp, ki)
    np.testing.assert_allclose(run_pi_consensus(u, lap, gc, h, kp, ki, 50), v, atol=1e-12)
    v_inf = run_pi_consensus(u, lap, gc, h, kp, ki, 10**7)
    np.testing.assert_allclose(v_inf, np.broadcast_to(u.mean(0), u.shape), atol=1e-9)


def test_pi_consensus_unstable_above_h_max_and_jury():
    lap = laplacian(adjacency(_agents(), 20.0))
    gc, kp, ki = 0.5, 0.4, 0.2
    hmax = consensus_h_max(lap, gc, kp, ki)
    assert pi_consensus_spectral_radius(lap, gc, 0.99 * hmax, kp, ki) < 1
    assert pi_consensus_spectral_radius(lap, gc, 1.01 * hmax, kp, ki) > 1
    u = np.random.default_rng(0).normal(size=(10, 2))
    v = run_pi_consensus(u, lap, gc, 1.05 * hmax, kp, ki, 20000)
    assert not np.all(np.isfinite(v)) or np.abs(v).max() > 1e6
    # Jury conditions on each Laplacian eigenvalue: a = gamma + K_p lam, b = K_i^2 lam^2
    lam = np.linalg.eigvalsh(lap)[1:]
    for h in np.linspace(0.05, 2.0, 40):
        a, b = gc + kp * lam, (ki * lam) ** 2
        jury = np.all(h * b < a) and np.all(4 - 2 * h * a + h * h * b > 0) and abs(1 - gc * h) < 1
        assert jury == (pi_consensus_modes(np.r_[0.0, lam], gc, h, kp, ki).max() < 1)


# ----------------------------------------------------------------------------------- H-infinity filters (6), (9)
def _measurements(rng, x, agents):
    r, th = geometry(x, agents)
    Mi = noise_information(r, th, MODEL)
    M = noise_covariance(r, th, MODEL)
    y = x[..., None, :] + sample_noise(rng, r, th, MODEL)
    return Mi, M, y, (Mi @ y[..., None])[..., 0]


def test_hinf_with_gamma_to_infinity_is_kalman():
    rng = np.random.default_rng(4)
    ag = np.broadcast_to(_agents(), (5, 10, 2))
    x = np.zeros((5, 2))
    xh = x + rng.normal(size=x.shape)
    P = np.broadcast_to(4 * I2, (5, 2, 2)).copy()
    xk, Pk = xh.copy(), P.copy()
    W = 0.01 * I2
    for _ in range(30):
        x = x + rng.normal(scale=0.1, size=x.shape)
        Mi, M, y, yi = _measurements(rng, x, ag)
        xh, P, _, _ = hinf_update(xh, P, yi.sum(1), Mi.sum(1), I2, W, 1e-14, I2)
        xk, Pk = kalman_update(xk, Pk, y, M, I2, W)
    np.testing.assert_allclose(xh, xk, atol=1e-9)
    np.testing.assert_allclose(P, Pk, atol=1e-11)


def test_hinf_gamma_shrinks_toward_kalman_monotonically():
    Mi = noise_information(*geometry(np.zeros(2), _agents()), MODEL).sum(0)
    traces = []
    for g in (1.0, 3.0, 10.0, 1e6):
        Sig = 4 * I2
        for _ in range(50):
            _, Sig, _, _ = hinf_update(np.zeros(2), Sig, np.zeros(2), Mi, I2, 0.01 * I2, g ** -2, I2)
        traces.append(np.trace(Sig))
    assert np.all(np.diff(traces) < 0)  # the H-infinity bound is larger than the Kalman covariance


def test_decentralized_with_exact_consensus_equals_centralized():
    rng = np.random.default_rng(5)
    ag = np.broadcast_to(_agents(), (4, 10, 2))
    x = np.zeros((4, 2))
    xc = xd = x + rng.normal(size=x.shape)
    Sc = Sd = np.broadcast_to(4 * I2, (4, 2, 2)).copy()
    for _ in range(25):
        x = x + rng.normal(scale=0.1, size=x.shape)
        Mi, _, _, yi = _measurements(rng, x, ag)
        xc, Sc, _, _ = hinf_update(xc, Sc, yi.sum(1), Mi.sum(1), I2, 0.01 * I2, 3.0 ** -2, I2)
        xd, Sd, _, _ = decentralized_update(xd, Sd, yi.mean(1), Mi.mean(1), 10, I2, 0.01 * I2, 3.0 ** -2, I2)
    np.testing.assert_allclose(xd, xc, atol=1e-12)
    np.testing.assert_allclose(Sd, Sc, atol=1e-12)


def test_hinf_gain_form_of_eq6():
    """The information-form update equals K_k (y - C A x) with K_k of eq (6) on the stacked measurement."""
    rng = np.random.default_rng(6)
    ag = _agents(4)
    x = np.array([1.0, -2.0])
    Mi, M, y, yi = _measurements(rng, x, ag)
    Sig, xprev = np.array([[0.5, 0.1], [0.1, 0.3]]), np.array([0.5, -1.0])
    W, g2 = 0.01 * I2, 0.05
    xn, Sn, Delta, _ = hinf_update(xprev, Sig, yi.sum(0), Mi.sum(0), I2, W, g2, I2)
    C = np.tile(I2, (4, 1))
    Minv = np.zeros((8, 8))
    for i in range(4):
        Minv[2 * i:2 * i + 2, 2 * i:2 * i + 2] = Mi[i]
    K = Delta @ np.linalg.inv(I2 + C.T @ Minv @ C @ Delta) @ C.T @ Minv
    np.testing.assert_allclose(xn, xprev + K @ (y.ravel() - C @ xprev), atol=1e-12)
    np.testing.assert_allclose(Sn, Delta @ np.linalg.inv(I2 - g2 * Delta + C.T @ Minv @ C @ Delta), atol=1e-12)


def test_below_gamma0_filter_reported_as_not_existing():
    ag = _agents()
    Mi = noise_information(*geometry(np.zeros(2), ag), MODEL)
    K = 60
    g0 = minimum_attenuation(np.broadcast_to(Mi, (K,) + Mi.shape), 4 * I2, I2, 0.01 * I2, I2)
    assert 1.5 < g0 < 2.5  # set by the worst cross-range information 1/f_b(40)
    with pytest.raises(FilterDoesNotExist, match="gamma below gamma_0"):
        simulate(_scenario(gamma=0.9 * g0, horizon=K, filters=["local"]))
    out = simulate(_scenario(gamma=1.2 * g0, horizon=K, filters=["local"]))
    assert np.all(np.isfinite(out["errors"]["local"]))


# ----------------------------------------------------------------------------------- motion control (12)-(18)
def _sigma_of_positions(Delta, agents, x, g2):
    r, th = geometry(x, agents)
    S = noise_information(r, th, MODEL).sum(0)
    return Delta @ np.linalg.inv(I2 + S @ Delta - g2 * Delta)


@pytest.mark.parametrize("i", [0, 2])
def test_gradient_of_trace_sigma_one_step_against_finite_differences(i):
    rng = np.random.default_rng(7)
    ag = rng.uniform(-30, 30, size=(4, 2))
    x = np.array([2.0, -1.0])
    Delta = np.array([[0.4, 0.05], [0.05, 0.25]])
    g2 = 0.1
    r, th = geometry(x, ag)
    Mi, dMr, dMt = noise_information(r, th, MODEL, derivatives=True)
    S = Mi.sum(0)
    eps = 1e-6
    for z, dM in ((0, dMr[i]), (1, dMt[i])):
        def sig(delta):
            rr, tt = r.copy(), th.copy()
            (rr if z == 0 else tt)[i] += delta
            Sz = noise_information(rr, tt, MODEL).sum(0)
            return Delta @ np.linalg.inv(I2 + Sz @ Delta - g2 * Delta)

        fd = (sig(eps) - sig(-eps)) / (2 * eps)
        _, dS = sigma_gradient(Delta, np.zeros((2, 2)), S, dM, g2, I2)
        np.testing.assert_allclose(dS, fd, atol=1e-8)
        np.testing.assert_allclose(np.trace(dS), np.trace(fd), atol=1e-9)  # eq (13)
        assert np.linalg.norm(printed_sigma_gradient(Delta, np.zeros((2, 2)), S, dM, g2, I2) - fd) > 1e-3 * np.linalg.norm(fd)


def test_gradient_recursion_eq14_against_finite_differences():
    """Sigma^z carried by (14) is the derivative of Sigma_K w.r.t. a shift of r_i held over all steps."""
    ag = _agents(4, 30.0, 30.0)
    x = np.array([1.0, 0.5])
    r, th = geometry(x, ag)
    W, g2, K = 0.01 * I2, 3.0 ** -2, 15

    def run(dr):
        rr = r.copy()
        rr[1] += dr
        Mi, dMr, _ = noise_information(rr, th, MODEL, derivatives=True)
        S = Mi.sum(0)
        Sig, dSig = 4 * I2, np.zeros((2, 2))
        for _ in range(K):
            Delta = Sig + W
            Sig, dSig = sigma_gradient(Delta, dSig, S, dMr[1], g2, I2)
        return Sig, dSig

    eps = 1e-6
    fd = (run(eps)[0] - run(-eps)[0]) / (2 * eps)
    np.testing.assert_allclose(run(0.0)[1], fd, atol=1e-9)


def test_control_law_is_steepest_descent():
    rng = np.random.default_rng(8)
    ag = rng.uniform(-30, 30, size=(4, 2))
    x = np.array([0.0, 0.0])
    Delta = np.array([[0.3, 0.0], [0.0, 0.3]])
    g2 = 0.1
    r, th = geometry(x, ag)
    Mi, dMr, dMt = noise_information(r, th, MODEL, derivatives=True)
    S = Mi.sum(0)
    i = 1
    Jr = np.trace(sigma_gradient(Delta, np.zeros((2, 2)), S, dMr[i], g2, I2)[1])
    Jt = np.trace(sigma_gradient(Delta, np.zeros((2, 2)), S, dMt[i], g2, I2)[1])
    u = control_law(Jr, Jt, r[i], th[i], 1.0)

    def J(p):
        a = ag.copy()
        a[i] = p
        return np.trace(_sigma_of_positions(Delta, a, x, g2))

    eps = 1e-6
    grad = np.array([(J(ag[i] + eps * e) - J(ag[i] - eps * e)) / (2 * eps) for e in I2])
    np.testing.assert_allclose(u, -grad, rtol=1e-5, atol=1e-12)
    u_printed = printed_control_law(Jr, Jt, r[i], th[i], 1.0)
    assert not np.allclose(u_printed, -grad, rtol=1e-2)
    # the speed limit only rescales
    u_lim = control_law(Jr, Jt, r[i], th[i], 1e9, v_max=0.5)
    assert np.isclose(np.linalg.norm(u_lim), 0.5) and np.isclose(u_lim @ u / np.linalg.norm(u), 0.5)


# ----------------------------------------------------------------------------------- evasive target (19)-(24)
def test_overbounding_map_eq23_describes_the_same_set():
    rng = np.random.default_rng(9)
    B = rng.normal(size=(2, 2))
    A = B @ B.T + I2
    b = rng.normal(size=2)
    rho = -1.0
    q, Q = overbounding_ellipse(A, b, rho)
    pts = rng.normal(scale=3, size=(1000, 2))
    lhs = np.einsum("ni,ij,nj->n", pts, A, pts) - 2 * pts @ b + rho <= 1
    d = pts - q
    rhs = np.einsum("ni,ij,nj->n", d, np.linalg.inv(Q), d) <= 1
    assert np.array_equal(lhs, rhs)


def test_fused_ellipse_eq24_contains_intersection_and_min_trace():
    rng = np.random.default_rng(10)
    ag = rng.uniform(-30, 30, size=(4, 2))
    x = np.array([1.0, 2.0])
    Mi = noise_information(*geometry(x, ag), MODEL)
    lam = np.full(4, 0.25)
    tr = fused_trace(Mi, lam, x)
    np.testing.assert_allclose(tr, np.trace(np.linalg.inv(np.einsum("n,nij->ij", lam, Mi))))
    best, lam_opt = min_fused_trace(Mi, n_iter=200)

    def f(z):
        w = np.exp(z) / np.exp(z).sum()
        return np.trace(np.linalg.inv(np.einsum("n,nij->ij", w, Mi)))

    ref = minimize(f, np.zeros(4), method="Nelder-Mead", options={"xatol": 1e-10, "fatol": 1e-12, "maxiter": 20000}).fun
    assert best <= ref * (1 + 1e-4)
    assert best >= ref * (1 - 1e-6) - 1e-12
    best20, _ = min_fused_trace(Mi, n_iter=20)  # the iteration count used in the simulations
    assert best20 <= ref * 1.02
    # the fused ellipse contains the intersection of the sensor ellipses
    pts = x + rng.uniform(-3, 3, size=(20000, 2))
    d = pts - x
    inside_all = np.all(np.einsum("ni,mij,nj->nm", d, Mi, d) <= 1, axis=1)
    Q = np.linalg.inv(np.einsum("n,nij->ij", lam_opt, Mi))
    assert np.all(np.einsum("ni,ij,nj->n", d[inside_all], np.linalg.inv(Q), d[inside_all]) <= 1 + 1e-9)


def test_evader_picks_the_best_candidate():
    ag = np.broadcast_to(_agents(4, 30.0, 30.0), (2, 4, 2))
    x = np.zeros((2, 2))
    nxt, val = evader_move(x, ag, MODEL, 0.5, 8, n_iter=100)
    phi = 2 * np.pi * np.arange(8) / 8
    cands = np.vstack([np.zeros(2), 0.5 * np.stack([np.cos(phi), np.sin(phi)], -1)])
    vals = [min_fused_trace(noise_information(*geometry(c, ag[0]), MODEL), 100)[0] for c in cands]
    np.testing.assert_allclose(nxt[0], cands[int(np.argmax(vals))])
    np.testing.assert_allclose(val[0], max(vals))


# ----------------------------------------------------------------------------------- simulation, config
def test_simulate_is_seeded_and_vectorised_shapes():
    a = simulate(_scenario())
    b = simulate(_scenario())
    for k in a["errors"]:
        np.testing.assert_array_equal(a["errors"][k], b["errors"][k])
    assert a["errors"]["local"].shape == (6, 10, 31)
    assert a["errors"]["centralized"].shape == (6, 1, 31)
    c = simulate(_scenario(seed=4))
    assert not np.array_equal(a["errors"]["local"], c["errors"]["local"])


def test_simulate_mobile_and_evasive_run():
    out = simulate(_scenario(target="stationary", W_true=0 * I2, W_filter=0.001 * I2, mobile=True, horizon=40))
    r0, _ = geometry(out["target"][:, 0], out["agents"][:, 0])
    r1, _ = geometry(out["target"][:, -1], out["agents"][:, -1])
    assert np.abs(r1 - MODEL.a1).mean() < np.abs(r0 - MODEL.a1).mean()  # agents approach the sweet spot
    steps = np.linalg.norm(np.diff(out["agents"], axis=1), axis=-1)
    assert steps.max() <= 0.5 + 1e-9
    ev = simulate(_scenario(agents0=_agents(4, 30.0, 30.0), target="evasive", mobile=True, horizon=10, runs=3))
    tsteps = np.linalg.norm(np.diff(ev["target"], axis=1), axis=-1)
    assert np.all((np.isclose(tsteps, 0.14)) | (tsteps < 1e-12))



def test_noise_model_rejects_bad_parameters_by_name():
    from netrepro.errors import InputError
    with pytest.raises(InputError, match="alpha"):
        NoiseModel(0.3, 15.0, 0.001, 0.0)


def test_fit_noise_model_recovers_exact_parameters():
    from netrepro.papers.hinf.noise import fit_noise_model
    r = np.linspace(0.0, 50.0, 9)
    a0, a1, a2, alpha = 0.3528, 15.625, 0.0008, 5.0
    vr = a2 * (r - a1) ** 2 + a0  # eq (4) written out, not via noise_variances
    fit = fit_noise_model(r, vr, alpha * vr)
    np.testing.assert_allclose([fit["a0"], fit["a1"], fit["a2"], fit["alpha"]], [a0, a1, a2, alpha], rtol=1e-9)


MATH_MODULES = ["algebra", "noise", "consensus", "filters", "motion", "evader", "simulation", "model"]


@pytest.mark.parametrize("name", MATH_MODULES)
def test_math_modules_public_api_has_numpydoc_sections(name):
    import importlib
    import inspect
    mod = importlib.import_module(f"netrepro.papers.hinf.{name}")
    for attr in mod.__all__:
        obj = getattr(mod, attr)
        if not (inspect.isfunction(obj) or inspect.isclass(obj)) or obj.__module__ != mod.__name__:
            continue
        doc = inspect.getdoc(obj) or ""
        if inspect.isclass(obj) and issubclass(obj, Exception):
            assert doc, attr
            continue
        assert "Parameters\n----------" in doc, f"{name}.{attr}: no Parameters section"
        if inspect.isfunction(obj):
            assert "Returns\n-------" in doc, f"{name}.{attr}: no Returns section"


def test_connected_matches_the_laplacian_spectrum():
    """simulation._connected (reachability) against the algebraic connectivity lambda_2 > 1e-9 it replaced."""
    from itertools import product

    from netrepro.papers.hinf.consensus import laplacian
    from netrepro.papers.hinf.simulation import _connected

    def by_spectrum(adj):
        return np.linalg.eigvalsh(laplacian(adj))[..., 1] > 1e-9

    pairs = [(i, j) for i in range(4) for j in range(i + 1, 4)]
    every4 = np.zeros((2 ** len(pairs), 4, 4))  # all 64 graphs on 4 agents
    for g, bits in enumerate(product((0.0, 1.0), repeat=len(pairs))):
        for (i, j), b in zip(pairs, bits):
            every4[g, i, j] = every4[g, j, i] = b
    assert np.array_equal(_connected(every4), by_spectrum(every4))
    rng = np.random.default_rng(3)
    for n, p in ((10, 0.15), (10, 0.3), (7, 0.4), (2, 0.5)):
        a = np.triu((rng.random((500, n, n)) < p).astype(float), 1)
        a = a + np.swapaxes(a, -1, -2)
        got = _connected(a)
        assert np.array_equal(got, by_spectrum(a)) and 0 < got.sum() < len(a)


@pytest.mark.parametrize("mobile", [False, True])
def test_consensus_variants_equal_their_own_simulations(mobile):
    """A decentralized filter on a consensus variant gives the numbers of the simulation with that consensus alone
    (stationary agents; mobile agents move by the driver on the configured consensus, unchanged by the variants)."""
    variants = {"ki0": {"K_i": 0.0}, "gc2": {"gamma_c": 2.0}, "reset": {"design": "pi_reset"},
                "exact": {"design": "exact_component"}, "complete": {"design": "complete", "iters": 2}}
    sc = _scenario(agents0=_agents(4, 30.0, 30.0, -135.0), mobile=mobile, filters=["local", "decentralized"])
    out = simulate({**sc, "consensus_variants": variants})
    alone = simulate(sc)
    for name in ("local", "decentralized"):
        assert np.array_equal(out["errors"][name], alone["errors"][name])
    assert np.array_equal(out["agents"], alone["agents"]) and out["n_psd_fix"] == alone["n_psd_fix"]
    assert list(out["errors"]) == ["local", "decentralized"] + list(variants)
    for lab, over in variants.items():
        if not mobile:
            one = simulate({**sc, "consensus": {**sc["consensus"], **over}})
            assert np.array_equal(out["errors"][lab], one["errors"]["decentralized"]), lab
        if lab != "reset" or alone["topology_changes"].any():  # no topology change: nothing to reset
            assert not np.array_equal(out["errors"][lab], alone["errors"]["decentralized"]), lab


def test_plane_norm_is_numpy_norm_bitwise():
    """The simulations' plane norms (errors, separations, velocities) equal np.linalg.norm(axis=-1) bit for bit."""
    from netrepro.papers.hinf.noise import plane_norm as _error_norm

    rng = np.random.default_rng(31)
    d = rng.standard_normal((3, 50, 4, 2)) * 10.0 ** rng.integers(-200, 200, size=(3, 50, 4, 2))
    d[0, :5, 0] = [[np.inf, 1.0], [np.nan, 0.0], [-0.0, 0.0], [1e308, 1e308], [5e-324, -5e-324]]
    with np.errstate(over="ignore", under="ignore", invalid="ignore"):
        ours = _error_norm(d)
        ref = np.linalg.norm(d, axis=-1)
        assert ours.tobytes() == ref.tobytes()
        # on a strided slice, as simulate passes it
        assert _error_norm(d[:, ::3]).tobytes() == np.linalg.norm(d[:, ::3], axis=-1).tobytes()
    np.testing.assert_allclose(_error_norm(np.array([3.0, 4.0])), 5.0)  # independent: the 3-4-5 triangle
