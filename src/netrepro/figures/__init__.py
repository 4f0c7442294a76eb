"""Figures: deterministic drawing, the data a figure draws, the check against its reference."""

__all__: list[str] = []
