"""Release: the RO-Crate, the README's results table, lock files, citations and the archive."""

__all__: list[str] = []
