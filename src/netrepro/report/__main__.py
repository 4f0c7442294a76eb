"""``python -m netrepro report`` (:func:`netrepro.report.cli.main`)."""

from ..pipeline.runner import exit_process
from .cli import main

__all__: list[str] = []

exit_process(main())
