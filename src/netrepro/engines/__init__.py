"""Shared numerical engines used by several papers, one concept per module.

:mod:`~netrepro.engines.channels` (packet-loss channels), :mod:`~netrepro.engines.riccati`
(batched Riccati recursions), :mod:`~netrepro.engines.kernels` (their compiled kernels),
:mod:`~netrepro.engines.montecarlo` (seeded, split-invariant Monte Carlo),
:mod:`~netrepro.engines.lmi` (parametrised LMI problems and bisections) and
:mod:`~netrepro.engines.certify` (certified LMI decisions). Submodules are imported on use
(cvxpy and numba cost seconds of import time).
"""

__all__ = ["certify", "channels", "kernels", "lmi", "montecarlo", "riccati"]
