"""The evader's certified choice (eq (19)): only the candidates that can win are solved exactly, bit for bit as all.

``evader_move(..., state=...)`` brackets every candidate from the previous move's support
(:func:`_support_bracket_numpy` / ``support_bracket_kernel``) and runs :func:`min_fused_trace_exact` on the
contenders only. It must return the same move and value bits as the reference (every candidate solved), which
rests on two facts tested here: the exact solver's result for an instance does not depend on the batch it is
solved in, and the bracket contains the true minimum (checked against SLSQP and a dense grid).
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import minimize

from netrepro.papers.hinf import evader as E
from netrepro.papers.hinf.evader_kernels import support_bracket_kernel
from netrepro.papers.hinf.noise import NoiseModel, geometry, noise_information

MODEL = NoiseModel(0.3528, 15.625, 0.0008, 5.0)


def _positions(x, step=0.14, H=16):
    phi = 2 * np.pi * np.arange(H) / H
    offs = np.concatenate([np.zeros((1, 2)), step * np.stack([np.cos(phi), np.sin(phi)], -1)])
    return x[:, None, :] + offs[None]


def _candidates(x, agents, step=0.14, H=16):
    r, th = geometry(_positions(x, step, H), agents[:, None, :, :])
    return noise_information(r, th, MODEL, kernel="numpy")


def _hard_cases(seed=0):
    """``(x, agents)`` of hard cases: model geometry, near-duplicate and identical agents, mirror ties, a
    candidate on an agent."""
    rng = np.random.default_rng(seed)
    out = []
    for N in (3, 4, 10):
        out.append((rng.normal(scale=3, size=(25, 2)), rng.normal(scale=20, size=(25, N, 2))))
    ag = rng.normal(scale=20, size=(25, 4, 2))
    ag[:, 2] = ag[:, 0] + 1e-7 * rng.standard_normal((25, 2))   # nearly coincident agents (Newton polish)
    ag[:, 3] = ag[:, 1]                                          # identical agents (singular faces)
    x = rng.normal(scale=3, size=(25, 2))
    ag[:4, 1] = x[:4]                                            # an agent on the target (range 0)
    ag[4:8, 1] = _positions(x)[4:8, 5]                           # an agent on a candidate
    out.append((x, ag))
    # mirror-symmetric agents about the x axis, target on the axis: headings phi and -phi tie (up to rounding)
    a = rng.normal(scale=20, size=(25, 2, 2))
    sym = np.concatenate([a, a * [1.0, -1.0]], 1)
    out.append((np.stack([rng.normal(scale=3, size=25), np.zeros(25)], -1), sym))
    return out


def _hard_instances(seed=0):
    """``(R, C, N, 2, 2)`` candidate informations of :func:`_hard_cases`."""
    return [_candidates(x, ag) for x, ag in _hard_cases(seed)]


def _slsqp_min(S):
    """Independent minimum of ``tr (sum lam_j S_j)^{-1}`` on the simplex: SLSQP from several starts."""
    n = len(S)

    def f(x):
        return np.trace(np.linalg.inv(np.einsum("j,jab->ab", x, S)))

    starts = [np.full(n, 1.0 / n)] + list(np.eye(n)) + list(np.random.default_rng(1).dirichlet(np.ones(n), 4))
    best = np.inf
    for x0 in starts:
        res = minimize(f, x0, method="SLSQP", bounds=[(0, 1)] * n, options={"ftol": 1e-15, "maxiter": 500},
                       constraints=[{"type": "eq", "fun": lambda x: x.sum() - 1}])
        x = np.clip(res.x, 0, None)
        best = min(best, f(x / x.sum()))
    return best


@pytest.mark.parametrize("case", range(5))
def test_exact_solver_result_does_not_depend_on_its_batch(case):
    """Each instance solved alone, in random subsets and in the whole batch, by either form: the same bits."""
    M = _hard_instances()[case]
    n = M.shape[-3]
    Mf = M.reshape(-1, n, 2, 2)
    ref_v, ref_l = E.min_fused_trace_exact(Mf, kernel="compiled")
    rng = np.random.default_rng(case)
    subsets = [np.arange(len(Mf))[::-1], rng.choice(len(Mf), 300, replace=False), rng.choice(len(Mf), 7, replace=False)]
    subsets += [np.array([i]) for i in rng.choice(len(Mf), 12, replace=False)]
    for sub in subsets:
        for kernel in ("numpy", "compiled", "auto"):
            v, lam = E.min_fused_trace_exact(Mf[sub], kernel=kernel)
            assert v.tobytes() == ref_v[sub].tobytes() and lam.tobytes() == ref_l[sub].tobytes(), (sub[:3], kernel)


def _hints(M, rng):
    """Hints of every kind: the optimum's weights, another candidate's, random supports of 1-3 agents, all agents."""
    R, C, n = M.shape[:3]
    _, lam = E.min_fused_trace_exact(M)
    hints = [lam[:, 0], lam[:, C // 2], np.full((R, n), 1.0 / n)]
    for k in (1, 2, 3):
        h = np.zeros((R, n))
        for r in range(R):
            J = rng.choice(n, min(k, n), replace=False)
            h[r, J] = rng.dirichlet(np.ones(len(J)))
        hints.append(h)
    return hints


def test_support_bracket_contains_the_minimum_and_is_tight_on_the_right_support():
    rng = np.random.default_rng(2)
    for M in _hard_instances(3)[:4]:
        M = M[:4, ::4]                                   # (4, 5, N, 2, 2): 20 instances per hint
        R, C, n = M.shape[:3]
        Mf = M.reshape(-1, n, 2, 2)
        # the best of SLSQP (independent) and the exact solver (SLSQP can stall on singular faces): an upper bound
        # of the minimum within 1e-12 of it
        true = np.minimum([_slsqp_min(S) for S in Mf], E.min_fused_trace_exact(Mf)[0])
        for hint in _hints(M, rng):
            rep = np.repeat(hint, C, 0)
            for rounds in (0, 1, 3):
                value, lower, scale = E._support_bracket_numpy(Mf, rep, rounds)
                assert np.all(lower <= true * (1 + 1e-12)) and np.all(true <= value * (1 + 1e-12))
                assert np.all(scale >= 1.0)
        # the optimum's own support: the bracket is as tight as the exact solver's certificate
        _, lam = E.min_fused_trace_exact(Mf)
        value, lower, _ = E._support_bracket_numpy(Mf, lam)
        assert np.all(value - lower <= 1e-10 * value)
        np.testing.assert_allclose(value, true, rtol=1e-8)


def test_support_bracket_on_a_dense_grid_of_three_agents():
    """Against a dense grid of the simplex (independent of any solver): the bracket's lower bound is below it."""
    rng = np.random.default_rng(4)
    G = rng.standard_normal((6, 3, 2, 2))
    S = G @ np.swapaxes(G, -1, -2) + 0.2 * np.eye(2)
    t = np.linspace(0, 1, 301)
    a, b = np.meshgrid(t, t, indexing="ij")
    keep = a + b <= 1
    grid = np.stack([a[keep], b[keep], 1 - a[keep] - b[keep]], -1)
    brute = np.array([np.min(np.trace(np.linalg.inv(np.einsum("gn,nij->gij", grid, s)), axis1=-2, axis2=-1))
                      for s in S])
    for hint in (np.eye(3)[[0, 1, 2, 0, 1, 2]], np.full((6, 3), 1 / 3), np.array([[0.5, 0.5, 0.0]] * 6)):
        value, lower, _ = E._support_bracket_numpy(S, hint)
        assert np.all(lower <= brute + 1e-12)
        assert np.all(value >= brute - 1e-3 * brute)  # an upper bound of the minimum (grid spacing 1/300)


@pytest.mark.parametrize("rounds", [0, 1, 3])
@pytest.mark.parametrize("case", range(5))
def test_support_bracket_kernel_matches_numpy_form(case, rounds):
    """Same mathematics (not necessarily the same rounding): equal to 1e-12 relative, same fallbacks."""
    M = _hard_instances(5)[case]
    R, C, n = M.shape[:3]
    Mf = np.ascontiguousarray(M.reshape(-1, n, 2, 2))
    for hint in _hints(M, np.random.default_rng(case)):
        rep = np.ascontiguousarray(np.repeat(hint, C, 0))
        a = E._support_bracket_numpy(Mf, rep, rounds)
        b = tuple(np.empty(len(Mf)) for _ in range(3))
        support_bracket_kernel(Mf, rep, rounds, *b)
        for u, v in zip(a, b):
            np.testing.assert_allclose(v, u, rtol=1e-12 * max(1.0, float(np.max(a[2]))), atol=0)


def _reference_choice(M):
    v, _ = E.min_fused_trace_exact(M)
    best = v.argmax(1)
    return best, v[np.arange(len(v)), best]


def test_approximate_information_is_the_model_information_to_a_few_ulps():
    rng = np.random.default_rng(12)
    x, ag = rng.normal(scale=3, size=(30, 2)), rng.normal(scale=20, size=(30, 4, 2))
    approx = E._approx_information(_positions(x), ag, MODEL)
    np.testing.assert_allclose(approx, _candidates(x, ag), rtol=1e-13, atol=1e-15)
    # by hand: an agent due west of the target at range r sees diag(1/f_r, 1/(alpha f_r))
    fr = MODEL.a2 * (7.0 - MODEL.a1) ** 2 + MODEL.a0
    S = E._approx_information(np.array([[[7.0, 0.0]]]), np.zeros((1, 1, 2)), MODEL)[0, 0, 0]
    np.testing.assert_allclose(S, np.diag([1 / fr, 1 / (MODEL.alpha * fr)]), rtol=1e-15)


@pytest.mark.parametrize("case", range(5))
def test_candidate_bracket_compiled_matches_numpy_form_and_contains_the_exact_value(case):
    x, ag = _hard_cases(13)[case]
    cand = _positions(x)
    M = _candidates(x, ag)
    exact, _ = E.min_fused_trace_exact(M)
    for hint in _hints(M, np.random.default_rng(case)):
        a = E._candidate_bracket(cand, ag, MODEL, hint, compiled=False)
        b = E._candidate_bracket(cand, ag, MODEL, hint, compiled=True)
        fin = np.isfinite(a[2]) & (a[2] < 1e8)
        for u, v in zip(a, b):
            assert np.array_equal(np.isfinite(u), np.isfinite(v))
            np.testing.assert_allclose(v[fin], u[fin], rtol=1e-12 * max(1.0, float(np.max(a[2][fin]))), atol=0)
        ok = np.isfinite(a[0]) & np.isfinite(a[1])
        assert np.all(a[1][ok] <= exact[ok] * (1 + 1e-11)) and np.all(exact[ok] <= a[0][ok] * (1 + 1e-11))
        assert np.all(a[2] >= MODEL.alpha)
        # a candidate on an agent (range 0): no bracket, so never excluded
        if case == 3:
            assert not np.isfinite(a[0][4:8, 5]).any()


@pytest.mark.parametrize("kernel", ["numpy", "compiled"])
@pytest.mark.parametrize("case", range(5))
def test_certified_values_give_the_reference_choice_bitwise(case, kernel):
    x, ag = _hard_cases(6)[case]
    M = _candidates(x, ag)
    ref_best, ref_val = _reference_choice(M)
    R = len(M)
    _, lam = E.min_fused_trace_exact(M)
    excluded = 0
    for hint in (lam[:, 0], lam[:, 5], np.full((R, M.shape[2]), 1.0 / M.shape[2])):
        tr, lam_c = E._certified_exact_values(_positions(x), ag, MODEL, hint, kernel=kernel)
        best = tr.argmax(1)
        assert np.array_equal(best, ref_best)
        assert tr[np.arange(R), best].tobytes() == ref_val.tobytes()
        assert lam_c[np.arange(R), best].tobytes() == lam[np.arange(R), best].tobytes()
        excluded += np.isneginf(tr).sum()
    assert excluded > 0  # the fast path is taken


def test_certified_fallbacks_solve_every_candidate(monkeypatch):
    x, ag = _hard_cases(7)[1]
    M = _candidates(x, ag)
    ref_v, ref_l = E.min_fused_trace_exact(M)
    cand = _positions(x)
    # no hint, an infinite margin, or no trusted bracket (scale limit 0): every candidate solved, as the reference
    for tr, lam_c in (E._certified_exact_values(cand, ag, MODEL, None),
                      E._certified_exact_values(cand, ag, MODEL, ref_l[:, 0], margin=np.inf)):
        assert tr.tobytes() == ref_v.tobytes() and lam_c.tobytes() == ref_l.tobytes()
    monkeypatch.setattr(E, "CERTIFY_SCALE_MAX", 0.0)
    tr, _ = E._certified_exact_values(cand, ag, MODEL, ref_l[:, 0])
    assert tr.tobytes() == ref_v.tobytes()


def test_candidate_informations_of_a_subset_are_those_of_the_whole_batch():
    """The contenders' informations are recomputed on their own: element-wise, so the same bits (either form)."""
    for x, ag in _hard_cases(14):
        cand = _positions(x)
        r, th = geometry(cand, ag[:, None, :, :])
        full = noise_information(r, th, MODEL)
        rng = np.random.default_rng(0)
        for size in (1, 5, 60, 300):
            ri, ci = rng.integers(0, len(x), size), rng.integers(0, cand.shape[1], size)
            r2, th2 = geometry(cand[ri, ci], ag[ri])
            for kernel in ("numpy", "compiled", "auto"):
                assert noise_information(r2, th2, MODEL, kernel=kernel).tobytes() == full[ri, ci].tobytes()


def test_evader_move_with_state_follows_the_reference_path_bitwise():
    """Moves in sequence (the state carries the weights), agents wandering, hard geometries: the same bits."""
    rng = np.random.default_rng(8)
    for M0 in range(3):
        N = (3, 4, 10)[M0]
        x = rng.normal(scale=3, size=(30, 2))
        agents = rng.normal(scale=20, size=(30, N, 2))
        if N == 4:
            agents[:, 3] = agents[:, 1]
        state, xs = {}, x.copy()
        agents[:3, 0] = x[:3]  # an agent on the target
        for _ in range(15):
            a = E.evader_move(x, agents, MODEL, 0.14, 16, 0, "exact")
            b = E.evader_move(xs, agents, MODEL, 0.14, 16, 0, "exact", state=state)
            assert a[0].tobytes() == b[0].tobytes() and a[1].tobytes() == b[1].tobytes()
            assert state["lam"].shape == (30, N)
            x, xs = a[0], b[0]
            agents = agents + 0.3 * rng.standard_normal(agents.shape)
    # a state from another simulation (other shape): every candidate solved
    c = E.evader_move(x[:5], agents[:5], MODEL, 0.14, 16, 0, "exact", state=state)
    d = E.evader_move(x[:5], agents[:5], MODEL, 0.14, 16, 0, "exact")
    assert c[1].tobytes() == d[1].tobytes() and state["lam"].shape == (5, agents.shape[1])


def test_simulate_evasive_matches_the_reference_evader(monkeypatch):
    """A short evasive closed loop with the certified evader and with the reference (state dropped): same bits."""
    from pathlib import Path

    import yaml

    from netrepro.papers.hinf import model as Mo
    from netrepro.papers.hinf import simulation as Si

    cfg = yaml.safe_load((Path(__file__).resolve().parents[3] / "config" / "config.yaml").read_text())["hinf"]
    sc = Mo.resolve_scenario(cfg, "evasive_hinf", runs=6, horizon=40, seed=3)
    outs = []
    for target in ("evasive", "evasive_noise"):
        sc["target"] = target
        outs.append(Mo.simulate(sc))
    orig = Si.evader_move  # the target's move phase calls it
    monkeypatch.setattr(Si, "evader_move", lambda *a, state=None: orig(*a))
    for target, fast in zip(("evasive", "evasive_noise"), outs):
        sc["target"] = target
        ref = Mo.simulate(sc)
        for key in ("target", "agents", "fused_trace"):
            assert ref[key].tobytes() == fast[key].tobytes(), (target, key)


def test_support_corrections_tighten_brackets_from_a_wrong_support():
    """Hints from another candidate or a random support: the active-set corrections make more brackets tight."""
    M = _hard_instances(10)[1]
    R, C, n = M.shape[:3]
    Mf = M.reshape(-1, n, 2, 2)
    tight = {}
    for rounds in (0, 3):
        count = 0
        for hint in _hints(M, np.random.default_rng(3))[1:]:
            value, lower, _ = E._support_bracket_numpy(Mf, np.repeat(hint, C, 0), rounds)
            count += np.sum(value - lower <= 1e-12 * value)
        tight[rounds] = count
    assert tight[3] > tight[0]
