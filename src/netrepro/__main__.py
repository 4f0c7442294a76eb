"""``python -m netrepro``: the pipeline runner's command line (:func:`netrepro.runner.main`)."""

from .runner import exit_process, main

__all__: list[str] = []

exit_process(main())
