"""Paper `intermittent`: S. Teerikoski, *Kalman Filtering with Measurement Losses* (2014).

After Sinopoli et al. (2004) and Liu & Goldsmith (2004). The report studies the
scalar system x_{k+1} = a x_k + v_k, y_k = x_k + w_k with i.i.d. packet losses
(arrival probability lambda) and the prediction-error variance recursion (6)

    p_{k+1} = a^2 p_k + R1 - gamma_k a^2 p_k^2 / (p_k + R2).

What this module computes
-------------------------
* the bounds s_k (eq. 10) and r_k (eq. 9) on E(p_k), the report's rough
  estimate of E(p_k) (with its algebra corrected), and the true E(p_k):
  exactly by enumerating all arrival sequences for short horizons, and over
  the full horizon by a *conditional* Monte Carlo estimator that averages only
  bounded quantities (the plain sample mean of p_k is heavy-tailed);
* the two-sensor stability region (Liu & Goldsmith): the lower bound
  lambda2c_lower(lambda1) and the LMI upper bound by bisection, with every
  feasible LMI answer certified by a spectral radius; a simulation check on
  both sides of the boundary;
* the claims table, the errata (printed vs corrected, with demonstrations),
  and the reconstructions.

Tables
------
``results/intermittent/exact_mean.csv``: ``lam, k, mean_exact``.
``results/intermittent/monte_carlo.csv``: ``lam, k, cond_mean, cond_lo, cond_hi, plain_mean, plain_lo,
plain_hi, plain_max, n_paths``.
``results/intermittent/scalar_bounds.csv``: ``lam, k, s, r, report_estimate, mean, mean_lo, mean_hi,
mean_method`` plus ``lam_label, report_estimate_printed, plain_mean, plain_lo, plain_hi``.
``results/intermittent/two_sensor_region.csv``: ``lambda1, lambda2c_lower, lambda2c_upper`` plus
``bracket_lower, n_solves, status_at_threshold, certified_radius, statuses_seen``.
``results/intermittent/two_sensor_simulation.csv``: ``lambda1, lambda2, side, k, mean, mean_lo, mean_hi,
predicted_growth``.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from ..claims import claim_row, claims_frame, errata_frame, reconstructions_frame
from ..config import ConfigError
from ..engines.channels import arrival_patterns, iid_arrivals
from ..engines.montecarlo import load_sums, merge_block_sums, run_blocks, run_monte_carlo, save_sums, shard_blocks
from ..engines.riccati import Sensor, covariance_paths
from ..io import read_table
from ..plotting import new_figure, save_figure

__all__ = [
    "critical_probability",
    "riccati_step",
    "lower_bound_sequence",
    "upper_bound_sequence",
    "report_estimate_sequence",
    "exact_mean_enumeration",
    "loss_propagation",
    "conditional_mean_weights",
    "conditional_mean_paths",
    "two_sensor_lower_bound",
    "two_sensor_modes",
    "two_sensor_upper_bound",
    "check_config",
    "PAPER",
]

PAPER = "intermittent"


# ----------------------------------------------------------------------------- scalar theory
def critical_probability(a) -> float:
    """lambda_c = 1 - 1/|a|^2 (section 4; for a matrix, |a| is the spectral radius)."""
    rho = np.max(np.abs(np.linalg.eigvals(np.atleast_2d(np.asarray(a, dtype=float)))))
    return float(1.0 - 1.0 / rho**2)


def riccati_step(p, gamma, a, R1, R2):
    """Eq. (6): p_{k+1} = a^2 p + R1 - gamma a^2 p^2 / (p + R2), elementwise."""
    p = np.asarray(p, dtype=float)
    return a * a * p + R1 - gamma * a * a * p * p / (p + R2)


def lower_bound_sequence(s0, a, R1, lam, n_steps) -> np.ndarray:
    """Eq. (10): s_{k+1} = (1 - lambda) a^2 s_k + R1, for k = 0..n_steps."""
    s = np.empty(n_steps + 1)
    s[0] = s0
    with np.errstate(over="ignore"):
        for k in range(n_steps):
            s[k + 1] = (1.0 - lam) * a * a * s[k] + R1
    return s


def upper_bound_sequence(r0, a, R1, R2, lam, n_steps) -> np.ndarray:
    """Eq. (9): r_{k+1} = a^2 r_k + R1 - lambda a^2 r_k^2 / (r_k + R2) (the modified Riccati iteration)."""
    r = np.empty(n_steps + 1)
    r[0] = r0
    with np.errstate(over="ignore"):
        for k in range(n_steps):
            # a diverged bound stays inf (inf/inf would give NaN)
            r[k + 1] = np.inf if np.isinf(r[k]) else a * a * r[k] + R1 - lam * a * a * r[k] ** 2 / (r[k] + R2)
    return r


def report_estimate_sequence(m0, s, r, a, R1, R2, lam, printed=False) -> np.ndarray:
    """The report's rough estimate of E(p_k) (section 4, after Fig. 1).

    With p^2/(p+R2) = p - R2 + R2^2/(p+R2), eq. (8) is exactly

        E(p_{k+1}) = a^2 E(p_k) + R1 - a^2 lambda (E(p_k) - R2 + R2^2 E[(p_k+R2)^{-1}]),

    and the report replaces E[(p_k+R2)^{-1}] by the average of (s_k+R2)^{-1}
    and (r_k+R2)^{-1}, with its own previous estimate for E(p_k).
    ``printed=True`` uses the formula as printed,
    ``+ a^2 lambda (E(p_k) - R2 - R2 E[(p_k+R2)^{-1}])`` (an erratum).
    """
    m = np.empty(len(s))
    m[0] = m0
    for k in range(len(s) - 1):
        inv = 0.5 * (1.0 / (s[k] + R2) + 1.0 / (r[k] + R2))
        if printed:
            m[k + 1] = a * a * m[k] + R1 + a * a * lam * (m[k] - R2 - R2 * inv)
        else:
            m[k + 1] = a * a * m[k] + R1 - a * a * lam * (m[k] - R2 + R2 * R2 * inv)
    return m


def exact_mean_enumeration(p0, a, R1, R2, lam, n_steps, return_distribution=False):
    """E(p_k) for k = 0..n_steps by enumerating all 2^k arrival sequences (eq. (6)).

    The support doubles each step (2^n_steps points at the end), so this is
    for short horizons only; it is the ground truth that validates the Monte
    Carlo estimators.
    """
    if n_steps > 24:
        raise ValueError(f"exact enumeration over 2^{n_steps} sequences is too large; use n_steps <= 24")
    values = np.array([float(p0)])
    weights = np.array([1.0])
    means = [float(p0)]
    for _ in range(n_steps):
        values = np.concatenate([riccati_step(values, 0.0, a, R1, R2), riccati_step(values, 1.0, a, R1, R2)])
        weights = np.concatenate([(1.0 - lam) * weights, lam * weights])
        means.append(float(weights @ values))
    means = np.array(means)
    return (means, values, weights) if return_distribution else means


def loss_propagation(x, m, a, R1):
    """L^m(x) = a^{2m} x + R1 (a^{2m} - 1)/(a^2 - 1): m steps of eq. (6) with gamma = 0."""
    a2m = (a * a) ** np.asarray(m, dtype=float)
    growth = m * 1.0 if np.isclose(a * a, 1.0) else (a2m - 1.0) / (a * a - 1.0)
    return a2m * x + R1 * growth


def conditional_mean_weights(horizon, a, pi_loss):
    """Weights W[j, k] = pi_loss^{k-1-j} a^{2(k-1-j)} for j < k (else 0), shape (horizon, horizon+1).

    Used by :func:`conditional_mean_paths`: the contribution to E(p_k) of
    the last arrival happening at time j.
    """
    j = np.arange(horizon)[:, None]
    k = np.arange(horizon + 1)[None, :]
    m = k - 1 - j
    with np.errstate(over="ignore"):
        w = np.where(m >= 0, (pi_loss * a * a) ** np.maximum(m, 0), 0.0)
    return w


def conditional_mean_paths(p_paths, p0, a, R1, sensor_vars, probs):
    """Per-path unbiased estimator of E(p_k) that averages only bounded quantities.

    Condition on the time j of the last step before k at which at least one
    packet arrived. The sequence after j is pure loss, with known probability
    pi_0^{k-1-j} (pi_0 = P(no packet)), and p_k = L^{k-1-j}(p_{j+1}) with L the
    loss propagation. Since p_j is independent of the arrivals at and after j,

    .. math::

        E(p_k) = \\sum_{j<k} \\pi_0^{k-1-j} E\\big[\\sum_{S \\ne \\emptyset} \\pi_S
                 L^{k-1-j}(\\varphi_S(p_j))\\big] + \\pi_0^k L^k(p_0),

    where phi_S(p) = a^2 (p^{-1} + sum_{i in S} 1/sigma_i^2)^{-1} + R1 is bounded
    by a^2 min_i sigma_i^2 + R1. The returned per-path quantity Y_k has
    E(Y_k) = E(p_k) and is bounded, so its sample mean obeys the CLT,
    unlike the sample mean of p_k (heavy-tailed; infinite variance when
    pi_0 a^4 >= 1).

    Parameters
    ----------
    p_paths : array (N, T+1)
        Sample paths p_0..p_T of the recursion (eq. (6) or (14)).
    sensor_vars : sequence of float
        Measurement noise variances of the (scalar, C = 1) sensors.
    probs : sequence of float
        Arrival probabilities of the sensors.

    Returns
    -------
    array (N, T+1) of Y_k.
    """
    p_paths = np.asarray(p_paths, dtype=float)
    N, T1 = p_paths.shape
    T = T1 - 1
    patterns, weights = arrival_patterns(probs)
    pi0 = float(weights[~patterns.any(axis=1)].sum())
    inv_vars = 1.0 / np.asarray(sensor_vars, dtype=float)
    p = p_paths[:, :T]
    mixed = np.zeros_like(p)  # sum over S != {} of pi_S phi_S(p_j)
    with np.errstate(divide="ignore"):
        for pattern, weight in zip(patterns, weights):
            if not pattern.any():
                continue
            post = 1.0 / (1.0 / p + inv_vars[pattern].sum())
            mixed += weight * (a * a * post + R1)
    W = conditional_mean_weights(T, a, pi0)  # (T, T+1)
    ks = np.arange(T + 1)
    # deterministic part: the R1 terms of L^m weighted by pi0^m, and the no-arrival-at-all path.
    # Written with (pi0 a^2)^m and pi0^m separately so that no 0 * inf can occur.
    with np.errstate(over="ignore", invalid="ignore"):
        grow = (pi0 * a * a) ** ks.astype(float)  # (pi0 a^2)^k
        shrink = pi0 ** ks.astype(float)  # pi0^k
        if np.isclose(a * a, 1.0):
            r1_terms = R1 * ks * shrink
        else:
            r1_terms = R1 * (grow - shrink) / (a * a - 1.0)  # pi0^m R1 (a^{2m} - 1)/(a^2 - 1)
        cumulative = np.concatenate([[0.0], np.cumsum(r1_terms[:-1])])  # sum over m = 0..k-1
        const = (1.0 - pi0) * cumulative + p0 * grow + r1_terms
        return mixed @ W + const[None, :]


# ----------------------------------------------------------------------------- two sensors
def two_sensor_lower_bound(lambda1, a) -> np.ndarray:
    """lambda2c_lower = max(1 - 1/(alpha^2 (1 - lambda1)), 0), alpha = |a| (Liu & Goldsmith)."""
    lambda1 = np.asarray(lambda1, dtype=float)
    with np.errstate(divide="ignore"):
        return np.maximum(1.0 - 1.0 / (a * a * (1.0 - lambda1)), 0.0)


def two_sensor_modes():
    """Output rows delivered in each arrival pattern, ordered as :func:`arrival_patterns` ([F,F],[F,T],[T,F],[T,T])."""
    return [None, np.array([[1.0]]), np.array([[1.0]]), np.array([[1.0], [1.0]])]


def two_sensor_upper_bound(lambda1_grid, a, tol=1e-5):
    """lambda2c_upper(lambda1) = inf{lambda2 : exists K, K1, K2, X > 0 with X > phi(K, K1, K2, X)} (eq. 16).

    Feasibility of eq. (16) is decided by the LMI of
    :class:`~netrepro.engines.lmi.MareStabilizabilityLMI` (one parametrised
    problem for the whole sweep) and certified by the spectral radius of the
    closed-loop second-moment operator; lambda2 is found by a bisection at each grid
    point bracketed from the closed-form lower bound of that point (so sharding the grid
    cannot change any answer, and a plain bisection would return the same lattice point).
    The noise terms of phi do not affect feasibility (the condition is
    homogeneous in X), so the bound depends on a and the C_i only.

    Returns a DataFrame with ``lambda1, lambda2c_upper, bracket_lower, n_solves,
    status_at_threshold, certified_radius, statuses_seen`` (every solver status met in the bisection).
    """
    from ..engines.lmi import MareStabilizabilityLMI, bisect_bracketed  # cvxpy: only the steps that solve LMIs

    lmi = MareStabilizabilityLMI([[a]], two_sensor_modes())
    grid = np.asarray(lambda1_grid, dtype=float)
    outcomes = {float(lam1): {} for lam1 in grid}

    def make_predicate(lam1):
        def feasible(lam2):
            _, weights = arrival_patterns([lam1, lam2])
            out = lmi.solve(weights)
            outcomes[float(lam1)][lam2] = out
            return out.certified

        return feasible

    # each point's bisection starts from its own closed-form lower bound (a guess only: the LMI still
    # decides both ends of the final bracket, and for a monotone predicate the answer is the plain
    # bisection's, engines.lmi.bisect_bracketed); nothing depends on the neighbours, so no shard
    # split can change an answer
    guesses = two_sensor_lower_bound(grid, a)
    results = [bisect_bracketed(make_predicate(lam1), 0.0, 1.0, guess, 0.0, tol=tol)  # one lattice cell each side
               for lam1, guess in zip(grid, guesses)]
    rows = []
    for lam1, res in zip(grid, results):
        seen_outcomes = outcomes[float(lam1)]
        at = seen_outcomes.get(res.threshold)
        seen = pd.Series([o.status for o in seen_outcomes.values()]).value_counts()
        if at is None:  # nothing certified: say what the solver said at the feasible end of the bracket
            end = seen_outcomes.get(1.0)
            status = f"not certified at lambda2 = 1 ({end.status if end else 'not solved'})"
        else:
            status = at.status
        rows.append({
            "lambda1": lam1,
            "lambda2c_upper": res.threshold,
            "bracket_lower": res.lower,
            "n_solves": res.n_evals,
            "status_at_threshold": status,
            "certified_radius": at.certificate_value if at else np.nan,
            "statuses_seen": "; ".join(f"{k}: {v}" for k, v in seen.items()),
        })
    return pd.DataFrame(rows)


# ----------------------------------------------------------------------------- config
def check_config(section: dict) -> None:
    """Checks beyond the schema: sizes that must agree."""
    scalar = section.get("scalar", {})
    if scalar and scalar.get("exact_horizon", 0) > scalar.get("horizon", 0):
        raise ConfigError(
            f"config key 'intermittent.scalar.exact_horizon' = {scalar['exact_horizon']} must not exceed "
            f"'intermittent.scalar.horizon' = {scalar['horizon']}")
    lam_c = critical_probability(scalar.get("a", 2.0)) if scalar else 0.5
    for off in scalar.get("lambda_offsets", []):
        if not 0.0 <= lam_c + off <= 1.0:
            raise ConfigError(
                f"config key 'intermittent.scalar.lambda_offsets' has {off}: lambda_c + offset = {lam_c + off:.3f} "
                "is not a probability in [0, 1]")


def _lambdas(cfg):
    lam_c = critical_probability(cfg["a"])
    return [(lam_c + off, f"lambda_c{off:+g}") for off in cfg["lambda_offsets"]]


# ----------------------------------------------------------------------------- steps
def exact_mean_step(params, inputs, outputs):
    """Step: exact E(p_k), k <= exact_horizon, for each lambda."""
    frames = []
    for lam, _ in _lambdas(params):
        means = exact_mean_enumeration(params["Ep0"], params["a"], params["R1"], params["R2"], lam,
                                       params["exact_horizon"])
        frames.append(pd.DataFrame({"lam": lam, "k": np.arange(len(means)), "mean_exact": means}))
    return {"table": pd.concat(frames, ignore_index=True)}


def _scalar_simulator(params, lam):
    a, R1, R2, p0, T = params["a"], params["R1"], params["R2"], params["Ep0"], params["horizon"]
    sensors = [Sensor([[1.0]], [[R2]])]

    def simulate(rng, n):
        arrivals = iid_arrivals(rng, n, T, lam)
        paths = covariance_paths(p0, [[a]], [[R1]], sensors, arrivals)
        cond = conditional_mean_paths(paths, p0, a, R1, [R2], [lam])
        return {"plain": paths, "cond": cond}

    return simulate


def monte_carlo_shard_step(params, inputs, outputs):
    """Step: block sums of one Monte Carlo shard (both lambdas); merged by :func:`monte_carlo_merge_step`."""
    blocks = shard_blocks(params["n_paths"], params["block_size"], params["n_shards"], params["shard"])
    named = {}
    for i, (lam, _) in enumerate(_lambdas(params)):
        named[f"lam{i}"] = run_blocks(_scalar_simulator(params, lam), params["n_paths"], params["block_size"],
                                      params["seed"] + i, blocks=blocks)
    save_sums(outputs["sums"], named)
    return {"provenance": {"blocks": [int(b) for b in blocks]}}


def monte_carlo_merge_step(params, inputs, outputs):
    """Step: merge the shards (in block order, so any shard count gives identical results) into the
    plain and conditional Monte Carlo estimates of E(p_k) with 95% bands."""
    shards = [load_sums(path) for path in inputs["shards"]]
    frames = []
    for i, (lam, _) in enumerate(_lambdas(params)):
        mc = merge_block_sums(shard[f"lam{i}"] for shard in shards)
        cm, clo, chi = mc.ci("cond")
        pm, plo, phi = mc.ci("plain")
        frames.append(pd.DataFrame({
            "lam": lam, "k": np.arange(params["horizon"] + 1), "cond_mean": cm, "cond_lo": clo, "cond_hi": chi,
            "plain_mean": pm, "plain_lo": plo, "plain_hi": phi, "plain_max": mc.maximum("plain"), "n_paths": mc.n,
        }))
    return {"table": pd.concat(frames, ignore_index=True)}


def scalar_bounds_step(params, inputs, outputs):
    """Step: the Figs 1-2 table (bounds, report estimate, true mean with its method)."""
    exact = read_table(inputs["exact"])
    mc = read_table(inputs["mc"])
    a, R1, R2, p0, T = params["a"], params["R1"], params["R2"], params["Ep0"], params["horizon"]
    frames = []
    for lam, label in _lambdas(params):
        s = lower_bound_sequence(p0, a, R1, lam, T)
        r = upper_bound_sequence(p0, a, R1, R2, lam, T)
        est = report_estimate_sequence(p0, s, r, a, R1, R2, lam)
        est_printed = report_estimate_sequence(p0, s, r, a, R1, R2, lam, printed=True)
        ex = exact[np.isclose(exact["lam"], lam)].set_index("k")["mean_exact"]
        m = mc[np.isclose(mc["lam"], lam)].set_index("k")
        k = np.arange(T + 1)
        use_exact = np.isin(k, ex.index)
        mean = np.where(use_exact, ex.reindex(k).to_numpy(), m["cond_mean"].reindex(k).to_numpy())
        lo = np.where(use_exact, mean, m["cond_lo"].reindex(k).to_numpy())
        hi = np.where(use_exact, mean, m["cond_hi"].reindex(k).to_numpy())
        frames.append(pd.DataFrame({
            "lam": lam, "k": k, "s": s, "r": r, "report_estimate": est, "mean": mean, "mean_lo": lo, "mean_hi": hi,
            "mean_method": np.where(use_exact, "exact enumeration", "conditional Monte Carlo"),
            "lam_label": label, "report_estimate_printed": est_printed,
            "plain_mean": m["plain_mean"].reindex(k).to_numpy(), "plain_lo": m["plain_lo"].reindex(k).to_numpy(),
            "plain_hi": m["plain_hi"].reindex(k).to_numpy(),
        }))
    return {"table": pd.concat(frames, ignore_index=True)}


def two_sensor_region_shard_step(params, inputs, outputs):
    """Step: lower bound (closed form) and LMI upper bound (bisection) on one shard of the lambda1 grid."""
    # every n-th grid point, so that shards near and far from lambda1 = 0 get balanced work
    grid = np.linspace(0.0, 1.0, params["lambda1_grid"])[params["shard"]::params["n_shards"]]
    upper = two_sensor_upper_bound(grid, params["a"], params["bisection_tol"])
    upper.insert(1, "lambda2c_lower", two_sensor_lower_bound(grid, params["a"]))
    return {"table": upper, "provenance": {"lmi_solves": int(upper["n_solves"].sum())}}


def two_sensor_region_merge_step(params, inputs, outputs):
    """Step: the Figs 4-5 table, concatenating the lambda1 shards."""
    table = pd.concat([read_table(p) for p in inputs["shards"]], ignore_index=True).sort_values("lambda1",
                                                                                                  kind="stable")
    expected = np.linspace(0.0, 1.0, params["lambda1_grid"])
    if len(table) != len(expected) or not np.allclose(table["lambda1"].to_numpy(), expected, rtol=0, atol=1e-12):
        raise ValueError(f"the {len(inputs['shards'])} lambda1 shards do not cover the grid of {len(expected)} points "
                         "exactly once; rebuild the shards (snakemake --forcerun intermittent_two_sensor_region_shard)")
    return {"table": table.reset_index(drop=True), "provenance": {"total_lmi_solves": int(table["n_solves"].sum())}}


def two_sensor_simulation_step(params, inputs, outputs):
    """Step: E(p_k) with the two-sensor recursion (14) on both sides of the boundary at lambda1 = check_lambda1."""
    a, R1 = params["a"], params["R1"]
    var1, var2 = params["sigma2"]
    lam1 = params["check_lambda1"]
    boundary = float(two_sensor_lower_bound(lam1, a))
    sensors = [Sensor([[1.0]], [[var1]]), Sensor([[1.0]], [[var2]])]
    T = params["check_horizon"]
    frames = []
    for i, (side, lam2) in enumerate((("stable", boundary + params["check_offset"]),
                                      ("unstable", boundary - params["check_offset"]))):
        lam2 = float(np.clip(lam2, 0.0, 1.0))

        def simulate(rng, n, lam2=lam2):
            arrivals = iid_arrivals(rng, n, T, [lam1, lam2])
            paths = covariance_paths(1.0, [[a]], [[R1]], sensors, arrivals)
            return {"cond": conditional_mean_paths(paths, 1.0, a, R1, [var1, var2], [lam1, lam2])}

        mc = run_monte_carlo(simulate, params["check_paths"], params["block_size"], params["seed"] + i)
        mean, lo, hi = mc.ci("cond")
        frames.append(pd.DataFrame({
            "lambda1": lam1, "lambda2": lam2, "side": side, "k": np.arange(T + 1), "mean": mean, "mean_lo": lo,
            "mean_hi": hi, "predicted_growth": (1 - lam1) * (1 - lam2) * a * a,
        }))
    return {"table": pd.concat(frames, ignore_index=True)}


# ----------------------------------------------------------------------------- errata
def _phi_scalar(K, p, lam, a, R1, R2):
    """Sinopoli's operator phi(K, p) for the scalar system (section 4)."""
    return (1 - lam) * (a * a * p + R1) + lam * ((a + K) ** 2 * p + R1 + K * R2 * K)


def errata_rows(cfg: dict) -> list[dict]:
    """Every equation the report prints wrong, with a numerical demonstration."""
    sc = cfg["scalar"]
    a, R1, R2, p0 = sc["a"], sc["R1"], sc["R2"], sc["Ep0"]
    lam_c = critical_probability(a)
    lam = lam_c + 0.1
    rows = []

    def add(eid, location, printed, corrected, demo, res_p, res_c):
        rows.append({"paper": PAPER, "erratum_id": eid, "location": location, "printed": printed,
                     "corrected": corrected, "demonstration": demo, "residual_printed": res_p,
                     "residual_corrected": res_c})

    # E1: Lemma 1 gain uses R1 instead of R2
    p = 1.0
    from scipy import optimize

    k_opt = optimize.minimize_scalar(lambda K: _phi_scalar(K, p, lam, a, R1, R2)).x
    add("E1", "Section 4, K~ (matrix and scalar forms)", "K~ = -A P C^T (C P C^T + R1)^-1; K~ = -a p/(p + R1)",
        "K~ = -A P C^T (C P C^T + R2)^-1; K~ = -a p/(p + R2)",
        f"numerical minimiser of phi(K, p=1) is K = {k_opt:.6f}; residual = |K~ - K_opt|",
        abs(-a * p / (p + R1) - k_opt), abs(-a * p / (p + R2) - k_opt))
    # E2: the condition p > phi(K~, p)
    phi_direct = _phi_scalar(-a * p / (p + R2), p, lam, a, R1, R2)
    printed_rhs = a * a * p + lam * a * a * p * p / (p + R2) ** 2 * (p - 2 + R2)
    corrected_rhs = a * a * p + R1 - lam * a * a * p * p / (p + R2)
    add("E2", "Section 4, condition before (11)", "p~ > a^2 p~ + lambda a^2 p~^2 (p~ + R2)^-2 (p~ - 2 + R2)",
        "p~ > phi(K~, p~) = a^2 p~ + R1 - lambda a^2 p~^2 / (p~ + R2)",
        f"phi(K~, p~=1) evaluated directly = {phi_direct:.6f} at lambda = lambda_c + 0.1; residual = |RHS - phi|",
        abs(printed_rhs - phi_direct), abs(corrected_rhs - phi_direct))
    # E3: condition (11)
    grid = np.logspace(-3, 4, 20001)
    printed_margin = np.max(lam * grid * (2 - R2 - grid) / (grid + R2) ** 2) - (1 - 1 / a**2)
    corrected_margin = np.max(lam * grid / (grid + R2) - R1 / (a * a * grid)) - (1 - 1 / a**2)
    r_end = upper_bound_sequence(p0, a, R1, R2, lam, 200)[-1]
    add("E3", "Eq. (11)", "1 - 1/a^2 < lambda p~ (2 - R2 - p~) / (p~ + R2)^2",
        "1 - 1/a^2 < lambda p~/(p~ + R2) - R1/(a^2 p~) for some p~ > 0 (hence lambda_c = 1 - 1/a^2 exactly)",
        f"at lambda = lambda_c + 0.1 the bound r_k converges (r_200 = {r_end:.4f}), so a p~ must exist; best margin "
        "over p~ in [1e-3, 1e4] (residual = max(0, -margin): positive means the condition wrongly fails)",
        max(0.0, -printed_margin), max(0.0, -corrected_margin))
    # E4: Jensen direction
    _, vals, w = exact_mean_enumeration(p0, a, R1, R2, lam, 8, return_distribution=True)
    e_f = float(w @ (vals**2 / (vals + R2)))
    ep = float(w @ vals)
    f_e = ep**2 / (ep + R2)
    add("E4", "Section 4, Jensen step before (9)", "E(p^2/(p+R2)) <= E(p)^2/(E(p)+R2)",
        "E(p^2/(p+R2)) >= E(p)^2/(E(p)+R2) (p^2/(p+R2) is convex), which is what makes (9) an upper bound",
        f"exact distribution of p_8 at lambda_c + 0.1: E(f(p)) = {e_f:.5f}, f(E p) = {f_e:.5f}; "
        "residual = amount by which the printed inequality is violated",
        max(0.0, e_f - f_e), max(0.0, f_e - e_f))
    # E5: indices in (9) and (10)
    r = upper_bound_sequence(p0, a, R1, R2, lam, 10)
    means = exact_mean_enumeration(p0, a, R1, R2, lam, 10)
    add("E5", "Eqs. (9) and (10), left-hand sides", "E(p_k) <= r_{k+1};  E(p_k) >= s_{k+1}",
        "E(p_{k+1}) <= r_{k+1};  E(p_{k+1}) >= s_{k+1}",
        "exact E(p_k), k <= 10, lambda_c + 0.1; residual = largest violation over k",
        float(np.max(np.maximum(means[:-1] - r[1:], 0))), float(np.max(np.maximum(means[1:] - r[1:], 0))))
    # E6: algebraic manipulation of (8)
    _, vals, w = exact_mean_enumeration(p0, a, R1, R2, lam, 6, return_distribution=True)
    ep, einv = float(w @ vals), float(w @ (1 / (vals + R2)))
    true_next = float(w @ riccati_step(vals, lam, a, R1, R2))
    printed = a * a * ep + R1 + a * a * lam * (ep - R2 - R2 * einv)
    corrected = a * a * ep + R1 - a * a * lam * (ep - R2 + R2 * R2 * einv)
    add("E6", "Section 4, rewriting of (8) before the rough estimate",
        "E(p_{k+1}) = a^2 E(p_k) + R1 + a^2 lambda (E(p_k) - R2 - R2 E((p_k+R2)^-1))",
        "E(p_{k+1}) = a^2 E(p_k) + R1 - a^2 lambda (E(p_k) - R2 + R2^2 E((p_k+R2)^-1))",
        f"exact distribution of p_6 at lambda_c + 0.1, true E(p_7) = {true_next:.6f}; residual = |formula - truth|",
        abs(printed - true_next), abs(corrected - true_next))
    # E7: the lambda_c argument uses r_k in the denominator
    r6 = upper_bound_sequence(p0, a, R1, R2, lam, 6)[-1]
    printed = a * a * ep + R1 - a * a * lam * float(w @ (vals**2 / (r6 + R2)))
    corrected = a * a * ep + R1 - a * a * lam * float(w @ (vals**2 / (vals + R2)))
    add("E7", "Section 4, existence argument for lambda_c", "E(p_{k+1}) = a^2 E(p_k) + R1 - a^2 lambda E(p_k^2 (r_k + R2)^-1)",
        "E(p_{k+1}) = a^2 E(p_k) + R1 - a^2 lambda E(p_k^2 (p_k + R2)^-1)",
        f"exact distribution of p_6, true E(p_7) = {true_next:.6f}; residual = |formula - truth|",
        abs(printed - true_next), abs(corrected - true_next))
    # E8: lambda >= lambda_c => bounded fails at equality
    s_c = lower_bound_sequence(p0, a, R1, lam_c, 100)
    add("E8", "Section 4, properties of lambda_c", "lambda >= lambda_c => lim E(p_k) < infinity",
        "lambda > lambda_c => lim E(p_k) < infinity (at lambda = lambda_c, (1-lambda)a^2 = 1 and E(p_k) >= s_k grows "
        "linearly)",
        f"lower bound at lambda = lambda_c: s_100 - s_0 = {s_c[-1] - s_c[0]:.4f} = 100 R1 (unbounded); residual = "
        "s_100 - s_0 under each reading's claim of boundedness (printed claims bounded)",
        float(s_c[-1] - s_c[0]), 0.0)
    # E9: sigma_1^2 duplicated
    add("E9", "Section 5, task statement", "sigma_1^2 = 0.2 and sigma_1^2 = 0.5", "sigma_1^2 = 0.2 and sigma_2^2 = 0.5",
        "textual: two values for one symbol; the second sensor's variance is otherwise never given", np.nan, np.nan)
    # E10: (15) misses R2 and the inverse
    X = 1.0
    sig = np.diag(cfg["two_sensor"]["sigma2"])
    l1, l2 = 0.5, 0.5
    ones = np.ones((2, 1))
    from ..engines.riccati import expected_riccati_map
    truth = float(expected_riccati_map([[X]], [[a]], [[R1]],
                                       [Sensor([[1.0]], [[sig[0, 0]]]), Sensor([[1.0]], [[sig[1, 1]]])], [l1, l2])[0, 0])
    common = a * a * X + R1 - l1 * (1 - l2) * a * a * X**2 / (X + sig[0, 0]) - (1 - l1) * l2 * a * a * X**2 / (X + sig[1, 1])
    printed = common - l1 * l2 * a * a * X**2 * (ones.T @ (ones * X @ ones.T) @ ones).item()
    corrected = common - l1 * l2 * a * a * X**2 * (ones.T @ np.linalg.inv(ones * X @ ones.T + sig) @ ones).item()
    add("E10", "Eq. (15), modified algebraic Riccati equation",
        "... - lambda1 lambda2 a^2 X^2 [1 1]([1;1] X [1 1])[1;1] ...",
        "... - lambda1 lambda2 a^2 X^2 [1 1]([1;1] X [1 1] + R2)^-1 [1;1] ...",
        "g(X=1) at lambda1 = lambda2 = 0.5 against the expected Riccati map of the engine (sum over arrival "
        "patterns); residual = |g - truth|", abs(printed - truth), abs(corrected - truth))
    # E11: stable for lambda_b = 0 twice
    add("E11", "Section 5, existence of lambda_2c", "unstable for lambda_b = 0 and stable for lambda_b = 0",
        "unstable for lambda_b = 0 and stable for lambda_b = 1", "textual: the two conditions contradict each other",
        np.nan, np.nan)
    # E12: precedence in the first lower-bound formula
    lam1 = 0.3
    lmi = float(two_sensor_upper_bound([lam1], a, 1e-6)["lambda2c_upper"].iloc[0])
    literal = max(1 - (1 - lam1) / a**2, 0.0)
    add("E12", "Section 5, first formula for lambda_2c_lower", "max(1 - 1/alpha^2(1 - lambda1), 0)",
        "max(1 - 1/(alpha^2 (1 - lambda1)), 0)",
        f"at lambda1 = 0.3 the LMI threshold is {lmi:.5f}; residual = |formula - LMI threshold|",
        abs(literal - lmi), abs(float(two_sensor_lower_bound(lam1, a)) - lmi))
    # E13: Sinopoli's Theorem 1 is about the MARE iteration, not E(P_k)
    r_inf = upper_bound_sequence(p0, a, R1, R2, lam, 400)[-1]
    add("E13", "Section 4, statement of Sinopoli et al. Theorem 1",
        "lim E(P_k) = P*, the unique fixed point of (4)",
        "the modified Riccati iteration V_{k+1} = g_lambda(V_k) (here r_k) converges to the unique fixed point of "
        "the MARE, which bounds lim sup E(P_k) from above; E(P_k) itself is generally smaller",
        f"fixed point r* = {r_inf:.4f} vs exact/conditional E(p_k) (see claims C8/C9); residual not applicable",
        np.nan, np.nan)
    # E14: lambda_2c_upper is an infimum, not an arg-infimum
    add("E14", "Section 5, definition of lambda_2c_upper", "arginf_{lambda2} (exists K, K1, K2, X | X > phi)",
        "inf { lambda2 : exists K, K1, K2, X > 0 with X > phi(K, K1, K2, X) }",
        "textual: the quantity is the threshold value of lambda2, not a minimising argument", np.nan, np.nan)
    return rows


def errata_step(params, inputs, outputs):
    """Step: the errata table."""
    return {"table": errata_frame(errata_rows(params))}


def reconstructions_step(params, inputs, outputs):
    """Step: parameters the report leaves unstated, with the values we chose."""
    sc, ts = params["scalar"], params["two_sensor"]
    rows = [
        ("scalar.Ep0", sc["Ep0"], "The report gives E(p0) = 10 only; we take p0 = 10 deterministically (then "
         "s_0 = r_0 = E(p0) = 10, the tightest initial bounds).", "Bounds and means forget p0 within ~15 steps in the "
         "stable case; the diverging case scales with p0."),
        ("scalar.horizon", sc["horizon"], "Figure range not stated; the text says values are reached around k = 25.",
         "None for the converged values."),
        ("scalar.report_estimate", "own previous estimate", "The rough estimate needs E(p_k) on the right-hand side; "
         "we use the estimate's previous value (the only computable reading).", "Using the true mean instead changes "
         "the estimate by < 5% in the stable case."),
        ("two_sensor.sigma2", ts["sigma2"], "Printed as sigma_1^2 = 0.2 and sigma_1^2 = 0.5 (erratum E9).",
         "The stability region does not depend on the noise variances (LMI feasibility is homogeneous)."),
        ("two_sensor.lambda1_grid", ts["lambda1_grid"], "Grid not stated; uniform on [0, 1].", "None."),
        ("two_sensor.R1", ts["R1"], "Stated R1 = 0.1; initial p0 = 1 for the simulation check is our choice.",
         "None for boundedness."),
    ]
    return {"table": reconstructions_frame(
        {"paper": PAPER, "key": k, "value": str(v), "reason": r, "sensitivity": s} for k, v, r, s in rows)}


# ----------------------------------------------------------------------------- claims
def _settle_step(x, rel=0.01):
    """First k after which x stays within rel of its final value."""
    x = np.asarray(x)
    off = np.abs(x - x[-1]) > rel * abs(x[-1])
    idx = np.nonzero(off)[0]
    return int(idx[-1] + 1) if len(idx) else 0


def _settle_note(x):
    steps = {rel: _settle_step(x, rel) for rel in (0.01, 0.02, 0.05)}
    return ("settling step depends on the criterion: " + ", ".join(f"{int(r * 100)}%: k = {k}" for r, k in steps.items())
            + "; the paper judged by eye")


def claims_step(params, inputs, outputs):
    """Step: every number the report states, checked against what we compute."""
    sc = params["scalar"]
    a = sc["a"]
    bounds = read_table(inputs["bounds"])
    region = read_table(inputs["region"])
    sim = read_table(inputs["simulation"])
    lam_c = critical_probability(a)
    stable = bounds[bounds["lam"] > lam_c].sort_values("k")
    unstable = bounds[bounds["lam"] < lam_c].sort_values("k")
    # converged values from long recursions (the table's horizon may be short in test configs)
    lam_s = float(stable["lam"].iloc[0])
    s_long = lower_bound_sequence(sc["Ep0"], a, sc["R1"], lam_s, 400)
    r_long = upper_bound_sequence(sc["Ep0"], a, sc["R1"], sc["R2"], lam_s, 400)
    rows = [
        claim_row(PAPER, "C1", "Critical arrival probability lambda_c = 1 - 1/a^2 for a = 1.5", 0.556, lam_c, 5e-4,
                  "paper rounds to 3 decimals"),
        claim_row(PAPER, "C2", "Fig 1: s_k converges to approximately 0.4 (lambda = lambda_c + 0.1)", 0.4, s_long[-1],
                  0.05, "'approximately' with one significant digit: half a unit of the last digit",
                  note="closed form s* = R1 / (1 - (1-lambda) a^2)"),
        claim_row(PAPER, "C3", "Fig 1: r_k converges to approximately 3.3", 3.3, r_long[-1], 0.05,
                  "one decimal given: half a unit of the last digit"),
        claim_row(PAPER, "C4", "Fig 1: s_k reaches its limit around k = 25", 25, _settle_step(s_long[:200]), 5,
                  "'around': +-5 steps; settling = within 1% of the limit",
                  note=_settle_note(s_long[:200])),
        claim_row(PAPER, "C5", "Fig 1: r_k reaches its limit around k = 25", 25, _settle_step(r_long[:200]), 5,
                  "'around': +-5 steps; settling = within 1% of the limit",
                  note=_settle_note(r_long[:200])),
        claim_row(PAPER, "C6", "Fig 2: both bounds diverge to infinity at lambda = lambda_c - 0.1", True,
                  bool(unstable["s"].iloc[-1] > unstable["s"].iloc[0] and
                       np.all(np.diff(unstable["s"].to_numpy()[-10:]) > 0) and
                       np.all(np.diff(unstable["r"].to_numpy()[-10:]) > 0)), 0,
                  "qualitative: s_k ends above s_0 and both sequences strictly increase over the last 10 steps",
                  note=f"growth factor of s_k: (1-lambda)a^2 = {(1 - unstable['lam'].iloc[0]) * a * a:.4f} > 1"),
        claim_row(PAPER, "C7", "The report's estimate of E(p_k) stays within its bounds in Figs 1 and 2", True,
                  bool(np.all((bounds["report_estimate"] >= bounds["s"] - 1e-9) &
                              (bounds["report_estimate"] <= bounds["r"] + 1e-9))), 0,
                  "qualitative, checked at every k of both figures"),
        claim_row(PAPER, "C8", "Eq. (7): s_k <= E(p_k) <= r_k (true mean, both lambdas, every k)", True,
                  bool(np.all((bounds["mean_hi"] >= bounds["s"] - 1e-9) & (bounds["mean_lo"] <= bounds["r"] + 1e-9))),
                  0, "qualitative; with Monte Carlo steps judged on the 95% band"),
        claim_row(PAPER, "C9", "Stable case: the rough estimate 'lies close to its real curve' (relative error at the "
                  "last k below 10%)", True,
                  bool(abs(stable["report_estimate"].iloc[-1] / stable["mean"].iloc[-1] - 1) < 0.10), 0,
                  "qualitative claim made quantitative as 10% relative error",
                  note=f"estimate {stable['report_estimate'].iloc[-1]:.4f} vs true E(p_k) {stable['mean'].iloc[-1]:.4f}"),
        claim_row(PAPER, "C10", "lambda >= lambda_c => lim E(p_k) finite; lambda < lambda_c => infinite: the true "
                  "mean is bounded at lambda_c + 0.1 and grows at lambda_c - 0.1", True,
                  bool(stable["mean_hi"].iloc[-1] < 2 * stable["mean_lo"].iloc[-6] and
                       unstable["mean_lo"].iloc[-1] > 1.5 * unstable["mean_hi"].iloc[-6]), 0,
                  "qualitative: E(p_k) flat over the last 5 steps vs growing by > 50%"),
        claim_row(PAPER, "C11", "Two sensors (C1 = C2 = 1 invertible): lambda2c_lower = lambda2c_upper for every "
                  "lambda1 (max difference)", 0.0,
                  float(np.max(np.abs(region["lambda2c_upper"] - region["lambda2c_lower"]))),
                  2 * params["two_sensor"]["bisection_tol"] + 1e-4,
                  "bisection tolerance plus the LMI margin threshold (strict feasibility near the boundary)"),
        claim_row(PAPER, "C12", "Region above the curve is stable: E(p_k) bounded at lambda2 = boundary + offset",
                  True, bool(_is_bounded(sim[sim["side"] == "stable"])), 0,
                  "qualitative, conditional Monte Carlo with 95% band"),
        claim_row(PAPER, "C13", "Below the curve E(p_k) diverges: lambda2 = boundary - offset", True,
                  bool(not _is_bounded(sim[sim["side"] == "unstable"])), 0,
                  "qualitative, conditional Monte Carlo with 95% band",
                  note=f"predicted growth factor {sim[sim['side'] == 'unstable']['predicted_growth'].iloc[0]:.4f}"),
    ]
    return {"table": claims_frame(rows)}


def _is_bounded(frame):
    frame = frame.sort_values("k")
    last, earlier = frame.iloc[-1], frame.iloc[-1 - max(5, len(frame) // 4)]
    return last["mean_lo"] < 1.5 * earlier["mean_hi"]


# ----------------------------------------------------------------------------- figures
def figure_bounds(params, inputs, outputs):
    """Figs 1 and 2: s_k, r_k, the report's estimate and the true E(p_k) with its 95% band."""
    table = read_table(inputs["bounds"])
    stable = params["which"] == "stable"
    lam_c = table["lam"].min() + (table["lam"].max() - table["lam"].min()) / 2
    data = table[(table["lam"] > lam_c) == stable].sort_values("k")
    fig, ax = new_figure()
    k = data["k"]
    ax.plot(k, data["r"], "-", color="C3", label="upper bound $r_k$ (9)")
    ax.plot(k, data["s"], "-", color="C0", label="lower bound $s_k$ (10)")
    ax.plot(k, data["report_estimate"], "--", color="C2", label="report's estimate (corrected)")
    ax.fill_between(k, data["mean_lo"], data["mean_hi"], color="k", alpha=0.2, lw=0)
    ax.plot(k, data["mean"], ":", color="k", label="true $E(p_k)$ (exact / conditional MC, 95% band)")
    ax.set_xlabel("k")
    ax.set_ylabel("prediction error variance")
    lam = data["lam"].iloc[0]
    ax.set_title(f"$\\lambda = {lam:.4f}$ ({'stable' if stable else 'diverging'} case)")
    if not stable:
        ax.set_yscale("log")
    ax.legend(fontsize=8)
    save_figure(fig, outputs["figure"])


def figure_region(params, inputs, outputs):
    """Figs 4 and 5: lower bound and LMI upper bound of lambda_2c against lambda_1 (plus simulation checks)."""
    region = read_table(inputs["region"])
    fig, ax = new_figure(figsize=(5.0, 4.2))
    ax.plot(region["lambda1"], region["lambda2c_lower"], "-", color="C0", label="lower bound $\\lambda_{2c}^{lower}$")
    if params["show_upper"]:
        ax.plot(region["lambda1"], region["lambda2c_upper"], "o", mfc="none", color="C3", ms=4,
                label="LMI upper bound $\\lambda_{2c}^{upper}$ (bisection)")
        sim = read_table(inputs["simulation"])
        for side, marker, color in (("stable", "^", "C2"), ("unstable", "v", "C1")):
            pt = sim[sim["side"] == side].iloc[0]
            ax.plot(pt["lambda1"], pt["lambda2"], marker, color=color, ms=8, label=f"simulation check: {side}")
    ax.set_xlabel("$\\lambda_1$")
    ax.set_ylabel("$\\lambda_2$")
    ax.set_xlim(0, 1)
    ax.set_ylim(0, 1)
    ax.legend(fontsize=8)
    save_figure(fig, outputs["figure"])


def figure_estimators(params, inputs, outputs):
    """Fig S1 (ours): the plain sample mean of p_k against the conditional estimator and the exact mean."""
    mc = read_table(inputs["mc"])
    exact = read_table(inputs["exact"])
    lams = sorted(mc["lam"].unique())
    fig, axes = new_figure(1, len(lams), figsize=(10, 4))
    for ax, lam in zip(np.atleast_1d(axes), lams):
        d = mc[np.isclose(mc["lam"], lam)].sort_values("k")
        e = exact[np.isclose(exact["lam"], lam)]
        ax.fill_between(d["k"], d["cond_lo"], d["cond_hi"], color="C0", alpha=0.3, lw=0)
        ax.plot(d["k"], d["cond_mean"], "-", color="C0", label="conditional estimator (95% band)")
        ax.fill_between(d["k"], d["plain_lo"], d["plain_hi"], color="C3", alpha=0.2, lw=0)
        ax.plot(d["k"], d["plain_mean"], "--", color="C3", label="plain sample mean (95% band)")
        ax.plot(e["k"], e["mean_exact"], "k.", ms=4, label="exact (enumeration)")
        ax.set_yscale("log")
        ax.set_xlabel("k")
        ax.set_title(f"$\\lambda = {lam:.4f}$, {int(d['n_paths'].iloc[0])} paths")
    np.atleast_1d(axes)[0].set_ylabel("$E(p_k)$")
    np.atleast_1d(axes)[0].legend(fontsize=8)
    save_figure(fig, outputs["figure"])
