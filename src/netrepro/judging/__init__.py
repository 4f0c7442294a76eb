"""Judging: the paper's side, the verdicts, the paper contract, summaries and comparisons of runs."""

__all__: list[str] = []
