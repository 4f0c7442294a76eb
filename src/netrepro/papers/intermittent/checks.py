"""Configuration checks of the `intermittent` section that the JSON schema cannot express."""

from __future__ import annotations

from ...errors import ConfigError

__all__ = ["check_config"]


def check_config(section: dict) -> None:
    """Check sizes that must agree and probabilities that must lie in [0, 1].

    Parameters
    ----------
    section : dict
        The ``intermittent`` section of the configuration.

    Raises
    ------
    ConfigError
        If ``scalar.exact_horizon`` exceeds ``scalar.horizon``, lambda_c + an offset of
        ``scalar.lambda_offsets`` is not a probability, or ``evidence.sample_path_horizons`` are not
        increasing whole numbers; the message names the key.
    """
    scalar = section.get("scalar", {})
    if scalar and scalar.get("exact_horizon", 0) > scalar.get("horizon", 0):
        raise ConfigError(
            f"config key 'intermittent.scalar.exact_horizon' = {scalar['exact_horizon']} must not exceed "
            f"'intermittent.scalar.horizon' = {scalar['horizon']}")
    # lambda_c = 1 - 1/a^2 (the scalar a of the schema; model.critical_probability for matrices)
    lam_c = 1.0 - 1.0 / float(scalar.get("a", 2.0)) ** 2 if scalar else 0.5
    for off in scalar.get("lambda_offsets", []):
        if not 0.0 <= lam_c + off <= 1.0:
            raise ConfigError(
                f"config key 'intermittent.scalar.lambda_offsets' has {off}: lambda_c + offset = {lam_c + off:.3f} "
                "is not a probability in [0, 1]")
    horizons = section.get("evidence", {}).get("sample_path_horizons", [])
    if any(float(t) != int(float(t)) for t in horizons) or any(b <= a for a, b in zip(horizons, horizons[1:])):
        raise ConfigError(f"config key 'intermittent.evidence.sample_path_horizons' = {horizons} must be increasing "
                          "whole numbers")
