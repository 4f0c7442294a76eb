"""Configuration checks of the `onebit` section that the JSON schema cannot express."""

from __future__ import annotations

from ...pipeline.config import require_matrix, require_pd
from ...errors import ConfigError

__all__ = ["check_config"]


def check_config(section: dict) -> None:
    """Checks the schema cannot express: grids, the vector model's shapes and definiteness.

    Called by :func:`netrepro.pipeline.config.validate_config` after the schema check. Checked: the SNR
    grid's ``stop`` exceeds its ``start``; ``fig1_one_minus_alpha`` is one of ``one_minus_alpha``;
    ``convergence.n_steps`` and ``convergence.n_lag_steps`` have one entry per ``one_minus_alpha``;
    ``estimator.snr_db`` is strictly increasing; the optional ``estimator.crossing`` has strictly
    increasing SNRs, more of them than its fit ``degree``, and only ``one_minus_alpha`` values of
    ``estimator.one_minus_alpha``; in ``vector_check``, ``A`` is square (n x n), ``C`` is m x n,
    and ``Q`` (n x n), ``R`` (m x m) and ``P0`` (n x n) are symmetric positive definite.

    Parameters
    ----------
    section : dict
        The ``onebit`` section of the configuration.

    Raises
    ------
    ConfigError
        Naming the configuration key whose value fails one of the checks above.
    """
    g = section["snr_grid_db"]
    if g["stop"] <= g["start"]:
        raise ConfigError(f"config key 'onebit.snr_grid_db' = {g!r}: stop must exceed start")
    if section["fig1_one_minus_alpha"] not in section["one_minus_alpha"]:
        raise ConfigError(f"config key 'onebit.fig1_one_minus_alpha' = {section['fig1_one_minus_alpha']!r} must be one "
                          f"of onebit.one_minus_alpha = {section['one_minus_alpha']!r}")
    conv = section["convergence"]
    for key in ("n_steps", "n_lag_steps"):
        if len(conv[key]) != len(section["one_minus_alpha"]):
            raise ConfigError(f"config key 'onebit.convergence.{key}' = {conv[key]!r} needs one entry per "
                              f"onebit.one_minus_alpha ({len(section['one_minus_alpha'])})")
    est = section["estimator"]
    if any(b <= a for a, b in zip(est["snr_db"], est["snr_db"][1:])):
        raise ConfigError(f"config key 'onebit.estimator.snr_db' = {est['snr_db']!r} must be strictly increasing "
                          "(the 0 dB crossing is interpolated along it)")
    cr = est.get("crossing")
    if cr:
        if any(b <= a for a, b in zip(cr["snr_db"], cr["snr_db"][1:])) or len(cr["snr_db"]) <= cr["degree"]:
            raise ConfigError(f"config key 'onebit.estimator.crossing.snr_db' = {cr['snr_db']!r} must be strictly "
                              f"increasing with more than degree = {cr['degree']} SNRs (a local fit)")
        missing = [e for e in cr["one_minus_alpha"] if e not in est["one_minus_alpha"]]
        if missing:
            raise ConfigError(f"config key 'onebit.estimator.crossing.one_minus_alpha' = {cr['one_minus_alpha']!r}: "
                              f"{missing!r} not in onebit.estimator.one_minus_alpha = {est['one_minus_alpha']!r}")
    vec = section["vector_check"]
    A = require_matrix("onebit.vector_check.A", vec["A"], square=True)
    n = A.shape[0]
    require_pd("onebit.vector_check.Q", vec["Q"])
    require_matrix("onebit.vector_check.Q", vec["Q"], shape=(n, n))
    C = require_matrix("onebit.vector_check.C", vec["C"])
    if C.shape[1] != n:
        raise ConfigError(f"config key 'onebit.vector_check.C' has shape {C.shape}; expected (m, {n})")
    require_pd("onebit.vector_check.R", vec["R"])
    require_matrix("onebit.vector_check.R", vec["R"], shape=(C.shape[0], C.shape[0]))
    require_pd("onebit.vector_check.P0", vec["P0"])
    require_matrix("onebit.vector_check.P0", vec["P0"], shape=(n, n))

