"""``python -m netrepro``: the pipeline runner's command line (:func:`netrepro.pipeline.runner.main`), and the
commands for people (:mod:`netrepro.cli.main`: new-paper, check-paper, register-findings, diff, scale-record, scaling),
the build driver behind ``make report``/``repair``/``unlock`` (:mod:`netrepro.pipeline.build`), and ``prune``
(:mod:`netrepro.pipeline.stale`: the outputs no rule produces any more, ``make prune``)."""

import sys

__all__: list[str] = []

if sys.argv[1:2] and sys.argv[1] in ("build", "repair", "unlock"):
    # the build driver (netrepro.pipeline.build) imports nothing of the pipeline: it starts before Snakemake
    from .pipeline.build import main as build_main

    sys.exit(build_main(sys.argv[1:]))
if sys.argv[1:2] == ["prune"]:
    # like the build driver, it runs Snakemake and imports nothing of the pipeline
    from .pipeline.stale import main as prune_main

    sys.exit(prune_main(sys.argv[1:]))

from .pipeline.runner import exit_process, main  # noqa: E402 - after the build driver's early exit

if sys.argv[1:2] and sys.argv[1] in ("new-paper", "check-paper", "register-findings", "diff", "scale-record", "scaling"):
    from .cli.main import main as commands_main

    exit_process(commands_main(sys.argv[1:]))
exit_process(main())
