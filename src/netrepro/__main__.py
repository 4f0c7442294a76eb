"""``python -m netrepro``: the pipeline runner's command line (:func:`netrepro.runner.main`), and the
commands for people (:mod:`netrepro.commands`: new-paper, check-paper, register-findings, diff, scale-record, scaling)."""

import sys

from .runner import exit_process, main

__all__: list[str] = []

if sys.argv[1:2] and sys.argv[1] in ("new-paper", "check-paper", "register-findings", "diff", "scale-record", "scaling"):
    from .commands import main as commands_main

    exit_process(commands_main(sys.argv[1:]))
exit_process(main())
