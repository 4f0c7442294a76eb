"""Configuration checks of the `markov` paper that the JSON schema cannot express."""

from __future__ import annotations

from ...pipeline.config import require_matrix, require_pd
from ...errors import ConfigError
from .model import observability_index

__all__ = ["check_config"]


def check_config(section: dict) -> None:
    """Checks a schema cannot express: matrix shapes agree, Q >= 0, R > 0, Sigma0 >= 0, (C, A) observable.

    Parameters
    ----------
    section : dict
        The ``markov`` section of the configuration; each entry of its ``examples`` is checked.

    Raises
    ------
    ConfigError
        Naming the configuration key: a matrix that is not a matrix, shapes that disagree with
        ``A`` (n x n) and ``C`` (m x n), Q or Sigma0 not positive semidefinite, R not positive
        definite, or (C, A) not observable.
    """
    for name, ex in section.get("examples", {}).items():
        A = require_matrix(f"markov.examples.{name}.A", ex["A"], square=True)
        n = A.shape[0]
        C = require_matrix(f"markov.examples.{name}.C", ex["C"])
        if C.shape[1] != n:
            raise ConfigError(f"config key 'markov.examples.{name}.C' has {C.shape[1]} columns; expected {n} (A is {n}x{n})")
        require_pd(f"markov.examples.{name}.Q", ex["Q"], semi=True)
        R = require_pd(f"markov.examples.{name}.R", ex["R"])
        if R.shape[0] != C.shape[0]:
            raise ConfigError(f"config key 'markov.examples.{name}.R' is {R.shape}; expected {C.shape[0]}x{C.shape[0]}")
        S0 = require_pd(f"markov.examples.{name}.Sigma0", ex["Sigma0"], semi=True)
        if S0.shape != A.shape:
            raise ConfigError(f"config key 'markov.examples.{name}.Sigma0' is {S0.shape}; expected {A.shape}")
        try:
            observability_index(A, C)
        except ValueError:
            raise ConfigError(f"config key 'markov.examples.{name}': (C, A) must be observable") from None

