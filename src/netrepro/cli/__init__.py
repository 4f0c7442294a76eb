"""The ``netrepro`` console script (``python -m netrepro``): one dispatcher of every verb."""

__all__: list[str] = []
