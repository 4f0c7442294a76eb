"""Estimator verdicts of the stability map (a cross-check; the map is decided by :mod:`.certificates`):
extrapolated growth of the exact ``E||P_k||`` and the long-horizon conditional estimator for points
the exact horizon leaves undecided. Both depend on thresholds; ``map_sensitivity.csv`` shows how much.
"""

from __future__ import annotations

import numpy as np

from .estimators import rb_trace_grid

__all__ = ["classify_growth", "refine_long_horizon", "decide_estimator", "single_transition"]


def classify_growth(means: np.ndarray, bounded_tol: float, unbounded_tol: float):
    """Asymptotic growth rate of exact means ``E||P_k||`` and a three-way verdict.

    Two-step log increments ``d_k = (log m_k - log m_{k-2}) / 2`` (two steps, because Example II
    alternates with period 2) are extrapolated to ``k -> infinity`` by Aitken's delta-squared on
    the last three even-spaced increments. Verdict: ``bounded`` if the extrapolated rate is below
    ``bounded_tol``, the increments are decreasing and the last one is below ``unbounded_tol``;
    ``unbounded`` if both the extrapolated
    and the last raw rate exceed ``unbounded_tol``, ``undecided`` otherwise. Vectorised over
    leading axes of ``means`` (last axis = k).

    Parameters
    ----------
    means : ndarray
        ``(..., K)`` exact ``E||P_k||``, ``k = 1..K`` (``K >= 11``).
    bounded_tol, unbounded_tol : float
        Growth-rate thresholds (per step).

    Returns
    -------
    (rate, last, verdict)
        Extrapolated rate, last raw two-step rate, and ``"bounded" / "unbounded" / "undecided"``.
    """
    with np.errstate(divide="ignore", invalid="ignore"):
        lm = np.log(means)
        d = (lm[..., 2:] - lm[..., :-2]) / 2.0
        x0, x1, x2 = d[..., -5], d[..., -3], d[..., -1]
        den = x2 - 2 * x1 + x0
        ait = np.where(np.abs(den) > 1e-12, x2 - (x2 - x1) ** 2 / den, x2)
        ratio = (x2 - x1) / (x1 - x0)
    converging = (ratio > 0) & (ratio < 1)
    # a converging sequence of increments has its limit between 0 (E||P_k|| settles) and the last one
    rate = np.where(converging, np.clip(ait, 0.0, np.maximum(x2, 0.0)), x2)
    verdict = np.where((rate < bounded_tol) & (x2 <= x1) & (x2 < unbounded_tol), "bounded",
                       np.where((rate > unbounded_tol) & (x2 > unbounded_tol), "unbounded", "undecided"))
    return rate, x2, verdict


def refine_long_horizon(system, Sigma0, ps, qs, opts, rng, z: float):
    """Long-horizon verdicts from the conditional trace estimator (:func:`~.estimators.rb_trace_grid`).

    The growth rate is ``log(m_T / m_{T/2}) / (T/2)``. The estimator integrates the trailing loss
    run exactly but samples everything before it, so it is trusted only where its batch-means
    95% half-width stays below ``rel_tol`` of the mean over ``k >= T/2`` (a heavy tail that is not
    a trailing loss run, e.g. Example II's parity-locked receptions, shows up as a wide interval);
    elsewhere the verdict stays ``undecided``. A short pilot run screens out points whose interval
    is already wider than ``pilot_factor`` times ``rel_tol``.

    Parameters
    ----------
    system : LinearSystem
        The system (eqs. 1-2).
    Sigma0 : array_like
        ``P_1``.
    ps, qs : array_like
        The points.
    opts : dict
        Estimator settings (``config.yaml``: ``markov.map.refine``).
    rng : numpy.random.Generator
        Random source.
    z : float
        Normal quantile of the batch-means interval (``markov.estimator.interval_z``).

    Returns
    -------
    (rate, rel_halfwidth, verdict) arrays over the points.
    """
    def run(idx, n_paths, T):
        rates, rels = [], []
        for start in range(0, len(idx), opts["chunk"]):
            sel = idx[start:start + opts["chunk"]]
            m, h = rb_trace_grid(system, Sigma0, ps[sel], qs[sel], n_paths, T, rng, opts["n_batches"], z)
            with np.errstate(divide="ignore", invalid="ignore"):
                rates.append(np.log(m[:, -1] / m[:, T // 2]) / (T - T // 2))
                rels.append(np.max(h[:, T // 2:] / m[:, T // 2:], axis=1))
        return (np.concatenate(rates), np.concatenate(rels)) if rates else (np.array([]), np.array([]))

    ps, qs = np.asarray(ps, float), np.asarray(qs, float)
    rate, rel = np.full(len(ps), np.nan), np.full(len(ps), np.inf)
    # pilot: a short, cheap run; points whose interval is already wide are not worth the long run
    _, rel_pilot = run(np.arange(len(ps)), opts["pilot_paths"], opts["pilot_horizon"])
    keep = np.flatnonzero(np.isfinite(rel_pilot) & (rel_pilot < opts["pilot_factor"] * opts["rel_tol"]))
    rate[keep], rel[keep] = run(keep, opts["n_paths"], opts["horizon"])
    reliable = np.isfinite(rate) & np.isfinite(rel) & (rel < opts["rel_tol"])
    verdict = np.where(~reliable, "undecided", np.where(rate < opts["bounded_tol"], "bounded",
                                                         np.where(rate > opts["unbounded_tol"], "unbounded", "undecided")))
    return rate, rel, verdict



def decide_estimator(means, long_rate, long_rel, bounded_tol, unbounded_tol, rel_tol, refine_bounded_tol,
                     refine_unbounded_tol):
    """Re-decide the estimator verdicts with other thresholds (for the sensitivity table).

    The exact stage is :func:`classify_growth`; points it leaves undecided take the long-horizon verdict
    of :func:`refine_long_horizon` where that was computed (``long_rate`` finite), with the same rule.

    Parameters
    ----------
    means : ndarray
        ``(..., K)`` exact ``E||P_k||``.
    long_rate, long_rel : ndarray
        Long-horizon growth rate and relative half-width (``nan`` / ``inf`` where not computed).
    bounded_tol, unbounded_tol : float
        Thresholds of :func:`classify_growth`.
    rel_tol, refine_bounded_tol, refine_unbounded_tol : float
        Thresholds of the long-horizon stage.

    Returns
    -------
    ndarray of str
        ``bounded`` / ``unbounded`` / ``undecided``.
    """
    _, _, verdict = classify_growth(means, bounded_tol, unbounded_tol)
    long_rate, long_rel = np.asarray(long_rate, float), np.asarray(long_rel, float)
    with np.errstate(invalid="ignore"):
        reliable = np.isfinite(long_rate) & np.isfinite(long_rel) & (long_rel < rel_tol)
        v_long = np.where(~reliable, "undecided", np.where(long_rate < refine_bounded_tol, "bounded",
                                                            np.where(long_rate > refine_unbounded_tol, "unbounded",
                                                                     "undecided")))
    return np.where(verdict == "undecided", v_long, verdict)


def single_transition(example, p, q, verdict):
    """Whether, at every ``q`` of the certified map, every bounded ``p`` lies below every unbounded ``p``.

    The conclusion of Proposition 2 (one critical value ``p_c(q)`` per ``q``), checked on a map.

    Parameters
    ----------
    example, p, q, verdict : array_like
        The columns ``example, p, q, verdict`` of ``stability_map.csv`` (one entry per map point;
        ``verdict`` in ``bounded``, ``unbounded``, ``undecided``).

    Returns
    -------
    (bool, str)
        The property over all examples and ``q``, and a note with the counts.
    """
    example, verdict = np.asarray(example).astype(str), np.asarray(verdict).astype(str)
    p, q = np.asarray(p, dtype=float), np.asarray(q, dtype=float)
    bad, parts = 0, []
    for name in sorted(set(example)):
        mine = example == name
        qs = np.unique(q[mine])
        viol = 0
        for qv in qs:
            at = mine & (q == qv)
            bounded, unbounded = p[at & (verdict == "bounded")], p[at & (verdict == "unbounded")]
            viol += int(bounded.size > 0 and unbounded.size > 0 and bounded.max() >= unbounded.min())
        bad += viol
        parts.append(f"Example {name}: {viol} of {qs.size} q with a bounded p above an unbounded p, "
                     f"{int((verdict[mine] == 'undecided').sum())} undecided points")
    return bool(bad == 0), "; ".join(parts)
