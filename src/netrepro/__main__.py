"""``python -m netrepro VERB``: the ``netrepro`` console script (:func:`netrepro.cli.main.console`).

Every verb imports its own module when it runs: ``python -m netrepro run`` (each pipeline job) imports
the runner alone, the build driver (``build``, ``repair``, ``unlock``) and ``prune`` nothing of the pipeline.
"""

from .cli.main import console

__all__: list[str] = []

console()
