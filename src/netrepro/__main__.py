"""``python -m netrepro``: the pipeline runner's command line (:func:`netrepro.runner.main`)."""

import sys

from .runner import main

__all__: list[str] = []

sys.exit(main())
