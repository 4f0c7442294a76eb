"""``python -m netrepro``: the pipeline runner's command line (:func:`netrepro.runner.main`), and the
commands for people (:mod:`netrepro.commands`: new-paper, check-paper, register-findings, diff, scale-record, scaling),
and the build driver behind ``make report``/``repair``/``unlock`` (:mod:`netrepro.build`)."""

import sys

__all__: list[str] = []

if sys.argv[1:2] and sys.argv[1] in ("build", "repair", "unlock"):
    # the build driver (netrepro.build) imports nothing of the pipeline: it starts before Snakemake
    from .build import main as build_main

    sys.exit(build_main(sys.argv[1:]))

from .runner import exit_process, main  # noqa: E402 - after the build driver's early exit

if sys.argv[1:2] and sys.argv[1] in ("new-paper", "check-paper", "register-findings", "diff", "scale-record", "scaling"):
    from .commands import main as commands_main

    exit_process(commands_main(sys.argv[1:]))
exit_process(main())
