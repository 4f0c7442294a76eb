"""One package per paper (``src/netrepro/papers/<slug>/``); the list of papers is the registry,
``src/netrepro/papers.yaml`` (:mod:`netrepro.pipeline.registry`)."""

__all__: list[str] = []
