"""Where the package finds its files: its own data, and the checkout it may run in.

Two kinds of files, found in two ways:

* **Package data** ships in the wheel beside the modules and is found through
  :mod:`importlib.resources`, wherever the package is installed: the papers' data files
  (``papers/<slug>/*.yaml``, ``findings.lock``), the registry ``papers.yaml``, the schemas
  (``schemas/*.schema.yaml``, ``schemas/paper/*.schema.yaml``), the report's and the
  scaffold's templates. :func:`package_file` names one of them.
* **Checkout files** exist only in a clone of the repository (``config/``,
  ``tests/platform_dependent.yaml``, ``results/``, the sources the benchmarks copy).
  :func:`checkout_root` finds the clone: the one whose ``src/`` holds the imported package
  (a source tree or an editable install), else the one around the current directory (an
  installed wheel run inside a clone), else none.

In a clone, ``src/netrepro/schemas`` is a symbolic link to ``workflow/schemas``: the
workflow reads its schemas where they have always been (``workflow/rules/common.smk``), and
the wheel holds a copy of them as package data (the build follows the link). A clone made
without symbolic links (the link is then a small text file) reads ``workflow/schemas`` directly.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

__all__ = ["PACKAGE", "package_root", "package_file", "SCHEMA_DIR", "PAPER_SCHEMA_DIR", "PAPERS_DIR",
           "is_checkout", "checkout_root", "checkout_file"]

PACKAGE = "netrepro"
# files that only a clone of the repository has at its top level
_CHECKOUT_MARKERS = ("pyproject.toml", "Snakefile", "workflow/rules")


def package_root() -> Path:
    """The directory of the installed ``netrepro`` package (where its data files are).

    Returns
    -------
    pathlib.Path
        ``src/netrepro`` of a clone, or ``.../site-packages/netrepro`` of an installed wheel.

    Raises
    ------
    RuntimeError
        When the package is not a directory of files (imported from a zip archive): its
        schemas and data are read as files.
    """
    root = resources.files(PACKAGE)
    if not isinstance(root, Path):
        raise RuntimeError(f"the {PACKAGE} package is imported from {root}, not a directory; install it from "
                           "its wheel with pip (the package reads its data files from disk)")
    return root


def package_file(*parts: str) -> Path:
    """A data file (or folder) of the package, e.g. ``package_file("papers", "onebit", "claims.yaml")``.

    Parameters
    ----------
    *parts : str
        Path components below the package directory.

    Returns
    -------
    pathlib.Path
        The path (whether or not it exists).
    """
    return package_root().joinpath(*parts)


def is_checkout(path: str | Path) -> bool:
    """Whether ``path`` is the top of a clone of the repository (its ``pyproject.toml``, ``Snakefile``, rules).

    Parameters
    ----------
    path : str or Path
        A directory.

    Returns
    -------
    bool
        True for a clone's top-level directory.
    """
    return all((Path(path) / marker).exists() for marker in _CHECKOUT_MARKERS)


def checkout_root(start: str | Path | None = None) -> Path | None:
    """The clone of the repository the package runs from, or None outside any clone.

    Parameters
    ----------
    start : str or Path, optional
        Where to look when the package itself is not in a clone (default: the current
        directory); it and its parents are tried.

    Returns
    -------
    pathlib.Path or None
        The clone whose ``src/`` holds the imported package (a source tree, an editable
        install), else the nearest clone around ``start``, else None (an installed wheel run
        elsewhere).
    """
    package = package_root().resolve()
    if package.parent.name == "src" and is_checkout(package.parents[1]):
        return package.parents[1]
    here = Path(start if start is not None else Path.cwd()).resolve()
    return next((d for d in (here, *here.parents) if is_checkout(d)), None)


def checkout_file(*parts: str) -> Path:
    """A file of the clone (``checkout_file("config", "config.yaml")``).

    Outside any clone the path is relative to the current directory, where such a file is
    normally absent: the caller reports it missing (or, for optional files, does without).

    Parameters
    ----------
    *parts : str
        Path components below the clone's top-level directory.

    Returns
    -------
    pathlib.Path
        The path (whether or not it exists).
    """
    root = checkout_root()
    return (root if root is not None else Path()).joinpath(*parts)


def _schema_dir() -> Path:
    packaged = package_file("schemas")
    if packaged.is_dir():
        return packaged
    # a clone made without symbolic links (git on Windows without core.symlinks) has the link as a text file
    root = checkout_root()
    return root / "workflow" / "schemas" if root is not None else packaged


# the configuration schemas (config.schema.yaml and one per paper) and the papers' data schemas
SCHEMA_DIR = _schema_dir()
PAPER_SCHEMA_DIR = SCHEMA_DIR / "paper"
# one package (or module) per paper; a package holds the paper's data files
PAPERS_DIR = package_file("papers")
