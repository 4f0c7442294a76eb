"""``python -m netrepro new-paper SLUG --title ... --source FILE``: a working skeleton of a paper."""

__all__: list[str] = []
