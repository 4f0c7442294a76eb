"""The pipeline: declared rules, the step runner, provenance, code inputs, configuration, files."""

__all__: list[str] = []
