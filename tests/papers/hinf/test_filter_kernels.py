"""The compiled filter, gradient and noise kernels reproduce their numpy reference forms bit for bit (speed).

Tolerance 0: :mod:`netrepro.papers.hinf.filter_kernels` replays numpy's BLAS rounding (``fma``) matrix by matrix.
"""

import numpy as np
import pytest

from netrepro.papers.hinf import filters as F
from netrepro.papers.hinf.motion import sigma_gradient
from netrepro.papers.hinf.noise import NoiseModel, geometry, noise_information, sample_noise

MODEL = NoiseModel(a0=0.3528, a1=15.625, a2=0.0008, alpha=5.0)
A_ROT = np.array([[1.0, 0.1], [-0.05, 0.98]])


def _information(lead, seed):
    rng = np.random.default_rng(seed)
    x = rng.normal(scale=5.0, size=lead + (2,))
    P = rng.normal(scale=30.0, size=lead + (2,))
    r, th = geometry(x, P[..., None, :])
    return r[..., 0], th[..., 0]


def _same(a, b):
    return all(np.shape(u) == np.shape(v) and np.array_equal(u, v) for u, v in zip(a, b))


@pytest.mark.parametrize("lead", [(40, 10), (60,), (1,), (9, 1), (1, 4), ()])
@pytest.mark.parametrize("gamma_inv2", [0.0, 1 / 9, 0.3])
@pytest.mark.parametrize("A", [np.eye(2), A_ROT])
def test_hinf_update_kernel_matches_numpy(lead, gamma_inv2, A):
    rng = np.random.default_rng(1)
    r, th = _information(lead, 2)
    S = noise_information(r, th, MODEL, kernel="numpy")
    Sig = np.broadcast_to(4.0 * np.eye(2), lead + (2, 2)).copy()
    xh, BWB, L = rng.normal(size=lead + (2,)), 0.01 * np.eye(2), np.eye(2)
    for _ in range(25):
        y = rng.normal(size=lead + (2,))
        a = F.hinf_update(xh, Sig, y, S, A, BWB, gamma_inv2, L, check=False, kernel="numpy")
        b = F.hinf_update(xh, Sig, y, S, A, BWB, gamma_inv2, L, check=False, kernel="compiled")
        assert _same(a, b)
        xh, Sig = a[0], a[1]


@pytest.mark.parametrize("A", [np.eye(2), A_ROT])
def test_minimum_attenuation_kernel_matches_numpy(A):
    r, th = _information((30, 5, 4), 3)
    S_seq = noise_information(r, th, MODEL, kernel="numpy")  # (K, runs, N, 2, 2)
    args = (4.0 * np.eye(2), A, 0.01 * np.eye(2), np.eye(2))
    for seq in (S_seq, S_seq.sum(2), np.broadcast_to(S_seq[0, 0], (30, 4, 2, 2))):
        assert F.minimum_attenuation(seq, *args, kernel="numpy") == F.minimum_attenuation(seq, *args, kernel="compiled")


@pytest.mark.parametrize("lead", [(30, 4), (7,), ()])
@pytest.mark.parametrize("gamma_inv2", [0.0, 1 / 9])
def test_sigma_gradient_kernel_matches_numpy(lead, gamma_inv2):
    r, th = _information(lead, 4)
    S, dMr, dMt = noise_information(r, th, MODEL, derivatives=True, kernel="numpy")
    rng = np.random.default_rng(5)
    Delta = np.broadcast_to(np.array([[2.0, 0.3], [0.3, 1.5]]), lead + (2, 2)) + 0.1 * rng.random(lead + (2, 2))
    dDelta = rng.normal(size=lead + (2, 2))
    for dS in (dMr, dMt):
        for dD in (dDelta, np.zeros((2, 2))):
            a = sigma_gradient(Delta, dD, S, dS, gamma_inv2, np.eye(2), kernel="numpy")
            b = sigma_gradient(Delta, dD, S, dS, gamma_inv2, np.eye(2), kernel="compiled")
            assert _same(a, b)


@pytest.mark.parametrize("lead", [(50, 16, 4), (3,), ()])
def test_noise_information_kernel_matches_numpy(lead):
    r, th = _information(lead, 6)
    for deriv in (False, True):
        a = noise_information(r, th, MODEL, derivatives=deriv, kernel="numpy")
        b = noise_information(r, th, MODEL, derivatives=deriv, kernel="compiled")
        assert _same(a, b) if deriv else _same([a], [b])
    # broadcast range against bearings
    a = noise_information(15.0, th, MODEL, derivatives=True, kernel="numpy")
    b = noise_information(15.0, th, MODEL, derivatives=True, kernel="compiled")
    assert _same(a, b)


@pytest.mark.parametrize("lead", [(100, 10), (50, 16, 4), (3,), ()])
def test_sample_noise_rotation_kernel_matches_numpy(lead):
    # the same draws (same generator state) rotated by the kernel and by numpy's matmul: tolerance 0
    rng = np.random.default_rng(8)
    r, th = rng.uniform(0.0, 60.0, lead), rng.uniform(-np.pi, np.pi, lead)
    for theta in (th, np.asfortranarray(th) if th.ndim > 1 else th):
        a = sample_noise(np.random.default_rng(3), r, theta, MODEL, kernel="numpy")
        b = sample_noise(np.random.default_rng(3), r, theta, MODEL, kernel="compiled")
        assert a.shape == lead + (2,) and a.tobytes() == b.tobytes()


@pytest.mark.parametrize("lead", [(40, 10), (60,), (1,), (9, 1), ()])
@pytest.mark.parametrize("kernel", ["numpy", "compiled"])
def test_hinf_update_batch_matches_each_filter(lead, kernel):
    """The stacked update of filters with their own gamma and design W equals hinf_update filter by filter."""
    rng = np.random.default_rng(7)
    r, th = _information(lead, 8)
    S = noise_information(r, th, MODEL, kernel="numpy")
    gi = np.array([0.0, 1 / 9, 0.3, 0.0])  # Kalman, gamma = 3, gamma ~ 1.8, Kalman at another W
    BWB = np.stack([w * np.eye(2) for w in (0.01, 0.01, 0.02, 0.05)])
    xh = rng.normal(size=(4,) + lead + (2,))
    Sig = np.broadcast_to(4.0 * np.eye(2), (4,) + lead + (2, 2)).copy()
    for _ in range(20):
        y = rng.normal(size=lead + (2,))
        got = F.hinf_update_batch(xh, Sig, y, S, A_ROT, BWB, gi, np.eye(2), check=False, kernel=kernel)
        for f in range(4):
            ref = F.hinf_update(xh[f], Sig[f], y, S, A_ROT, BWB[f], gi[f], np.eye(2), check=False, kernel="numpy")
            assert _same(ref, [g[f] for g in got])
        xh, Sig = got[0], got[1]


def test_hinf_update_batch_raises_if_any_filter_does_not_exist():
    r, th = _information((5, 3), 9)
    S = noise_information(r, th, MODEL, kernel="numpy")
    xh, Sig = np.zeros((2, 5, 3, 2)), np.broadcast_to(4.0 * np.eye(2), (2, 5, 3, 2, 2)).copy()
    args = (xh, Sig, np.zeros((5, 3, 2)), S, np.eye(2), np.stack([0.01 * np.eye(2)] * 2))
    for kernel in ("numpy", "compiled"):
        F.hinf_update_batch(*args, np.array([0.0, 1 / 9]), np.eye(2), kernel=kernel)
        with pytest.raises(F.FilterDoesNotExist):
            F.hinf_update_batch(*args, np.array([0.0, 100.0]), np.eye(2), kernel=kernel)


def _steady_state_prior_all_iterations(S, W, gamma_inv2, Lbar, n_iter):
    """Reference: every one of the ``n_iter`` fixed-point iterations of filters.steady_state_prior."""
    S = np.asarray(S, dtype=float)
    eye = np.broadcast_to(np.eye(2), S.shape)
    Delta = W * eye.copy()
    for _ in range(n_iter):
        Sigma = Delta @ np.linalg.inv(eye - gamma_inv2 * Lbar @ Delta + S @ Delta)
        Delta = 0.5 * (Sigma + np.swapaxes(Sigma, -1, -2)) + W * eye
    return Delta


@pytest.mark.parametrize("n_iter", [1, 2, 7, 300, 3000, 3001])
@pytest.mark.parametrize("gamma_inv2", [0.0, 1 / 9, 0.3])
def test_steady_state_prior_stops_early_on_the_same_bits(n_iter, gamma_inv2):
    """Stopping once the iterates repeat (period 1 or 2) gives the last of the n_iter iterates, bit for bit."""
    r, th = _information((3, 10), 21)
    S = noise_information(r, th, MODEL, kernel="numpy")
    for s in (S, S.sum(1), S[0, 0]):
        got = F.steady_state_prior(s, 0.001, gamma_inv2, np.eye(2), n_iter=n_iter)
        assert got.tobytes() == _steady_state_prior_all_iterations(s, 0.001, gamma_inv2, np.eye(2), n_iter).tobytes()


@pytest.mark.parametrize("lead", [(30, 4), (7,), (1,), ()])
@pytest.mark.parametrize("A", [np.eye(2), A_ROT, -A_ROT])
def test_congruence_kernel_matches_numpy(lead, A):
    rng = np.random.default_rng(22)
    X = rng.normal(size=lead + (2, 2))
    X.reshape(-1, 4)[::3] = [-0.0, 0.0, -0.0, -0.0]  # signed zeros: numpy's dgemm returns +0.0
    a = F.congruence(A, X, kernel="numpy")
    b = F.congruence(A, X, kernel="compiled")
    assert a.shape == b.shape and a.tobytes() == b.tobytes()


@pytest.mark.parametrize("lead", [(30, 4), (7,), ()])
def test_control_law_kernel_matches_numpy(lead):
    from netrepro.papers.hinf.motion import control_law

    r, th = _information(lead, 23)
    rng = np.random.default_rng(24)
    dr, dt = rng.normal(size=lead), rng.normal(size=lead)
    for v_max in (np.inf, 0.5):
        a = control_law(dr, dt, r, th, 2e4, v_max, kernel="numpy")
        b = control_law(dr, dt, r, th, 2e4, v_max, kernel="compiled")
        assert a.shape == b.shape and a.tobytes() == b.tobytes()
