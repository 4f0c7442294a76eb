"""Configuration checks of the `hinf` section that the JSON schema cannot express."""

from __future__ import annotations

from ...pipeline.config import require_matrix, require_pd
from ...errors import ConfigError
from .model import FILTER_KINDS

__all__ = ["check_config"]


def check_config(section: dict) -> None:
    """Matrix shapes, positive definiteness and scenario references of the ``hinf`` section.

    Parameters
    ----------
    section : dict
        The ``hinf`` configuration section.

    Raises
    ------
    ConfigError
        Naming the offending key.
    """
    f = section["filter"]
    require_matrix("hinf.filter.A", f["A"], shape=(2, 2))
    require_matrix("hinf.filter.L", f["L"], shape=(2, 2))
    require_pd("hinf.filter.Q", f["Q"], semi=True)
    for name, sc in section["scenarios"].items():
        if sc["layout"] not in section["layouts"]:
            raise ConfigError(f"config key 'hinf.scenarios.{name}.layout' = {sc['layout']!r} is not a key of hinf.layouts")
        if sc.get("mobile") and sc.get("driver") not in sc["filters"]:
            raise ConfigError(f"config key 'hinf.scenarios.{name}.driver' = {sc.get('driver')!r} must be one of its filters")
        if sc.get("mobile") and FILTER_KINDS[sc["driver"]][0] != "decentralized":
            raise ConfigError(f"config key 'hinf.scenarios.{name}.driver' must be a decentralized filter")
    if section["consensus_check"]["layout"] not in section["layouts"]:
        raise ConfigError("config key 'hinf.consensus_check.layout' is not a key of hinf.layouts")
