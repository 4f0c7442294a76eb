"""Scale: paper-scale runs against the default ones, cluster projections, benchmarks."""

__all__: list[str] = []
