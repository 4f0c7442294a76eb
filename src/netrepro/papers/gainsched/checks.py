"""Configuration checks of the `gainsched` paper that the JSON schema cannot express."""

from __future__ import annotations

import numpy as np

from ...errors import ConfigError
from .model import GainschedError, gains_from_dict, system_from_config

__all__ = ["check_config"]


def check_config(section: dict) -> None:
    """Checks the schema cannot express: matrix shapes that agree, sector ordering, p bounds.

    Parameters
    ----------
    section : dict
        The ``gainsched`` section of the configuration (``system``, ``paper_gains``,
        ``simulation``, ``performance``).

    Raises
    ------
    ConfigError
        Naming the key: an invalid system or printed gains (shapes, sector ordering F1 < F2,
        p bounds in (0, 1), sigma2 >= 0, a missing key), ``simulation.x0`` / ``xf0`` without
        n entries, or ``performance.initial_cov`` not a symmetric positive semidefinite n x n matrix.
    """
    try:
        sys = system_from_config(section["system"])
        gains_from_dict(section["paper_gains"], sys)
    except (GainschedError, KeyError, ValueError) as exc:
        raise ConfigError(f"config key 'gainsched.system' / 'gainsched.paper_gains' is invalid: {exc}") from None
    for key in ("x0", "xf0"):
        vec = np.asarray(section["simulation"].get(key, np.zeros(sys.n)), dtype=float)
        if vec.shape != (sys.n,):
            raise ConfigError(f"config key 'gainsched.simulation.{key}' = {vec.tolist()} must have {sys.n} entries")
    cov = np.asarray(section["performance"]["initial_cov"], dtype=float)
    if cov.shape != (sys.n, sys.n) or not np.allclose(cov, cov.T) or np.linalg.eigvalsh(cov).min() < 0:
        raise ConfigError(f"config key 'gainsched.performance.initial_cov' must be a symmetric PSD {sys.n}x{sys.n} "
                          "matrix")
