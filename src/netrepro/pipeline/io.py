"""Atomic file output and checksums.

Every table and figure is first written to a temporary file in the target
directory and then renamed over the target, so a killed job never leaves a
file that looks complete.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import tempfile
from pathlib import Path


__all__ = ["atomic_path", "new_file_mode", "current_umask", "write_table", "read_table", "write_json", "sha256_file",
           "load_yaml", "yaml_loader_class"]


def yaml_loader_class(base=None):
    """A safe loader class (libyaml's by default) that reads YAML 1.2 floats such as ``1.0e12``.

    YAML 1.1, which PyYAML implements, reads a float written without a dot or without a sign in
    its exponent (``1e-5``, ``1.0e12``) as text; YAML 1.2 and every other reader take it as a
    number. The default class is built once per process.

    Parameters
    ----------
    base : type, optional
        The loader to extend (default: ``yaml.CSafeLoader`` when PyYAML has libyaml, else
        ``yaml.SafeLoader``).

    Returns
    -------
    type
        A subclass of ``base`` with the YAML 1.2 float resolver added.
    """
    import re

    import yaml

    if base is None and _LOADER:
        return _LOADER[0]
    parent = base or getattr(yaml, "CSafeLoader", yaml.SafeLoader)
    loader = type("NetreproLoader", (parent,), {})
    loader.add_implicit_resolver(
        "tag:yaml.org,2002:float",
        re.compile(r"^[-+]?(?:[0-9][0-9_]*(?:\.[0-9_]*)?|\.[0-9_]+)[eE][-+]?[0-9]+$"),
        list("-+0123456789."))
    if base is None:
        _LOADER.append(loader)
    return loader


_LOADER: list = []


def load_yaml(text: str):
    """``yaml.safe_load`` through libyaml's parser when PyYAML has it (same objects, ~10x faster).

    The workflow parses the papers' claims, errata, findings and figure lists at every start
    (also a no-op rerun), where the pure-Python parser took seconds. Floats in exponent form are
    read as numbers whether or not they carry a dot and an exponent sign (``1e-5``, ``1.0e12``:
    YAML 1.2), where YAML 1.1 would read them as text.

    Parameters
    ----------
    text : str
        YAML text (or an open stream, which PyYAML also accepts).

    Returns
    -------
    object
        The parsed document (dict, list, scalar, or None for an empty document).
    """
    import yaml

    return yaml.load(text, Loader=yaml_loader_class())  # noqa: S506 (a safe loader)


@contextlib.contextmanager
def atomic_path(target: str | os.PathLike):
    """Yield a temporary path next to ``target``; rename it onto ``target`` on success.

    The temporary file is fsynced before the rename and the directory after it. On an
    exception the temporary file is removed and ``target`` is untouched. Before the rename the file
    gets the mode of any new file, ``0o666 & ~umask`` (:func:`new_file_mode`): ``mkstemp`` creates
    it 0600, readable by its owner alone, which a shared group folder or a web server cannot read.

    Parameters
    ----------
    target : str or os.PathLike
        The file to write; its parent directories are created.

    Yields
    ------
    pathlib.Path
        The temporary file (``.<name>.<random>.part<suffix>`` in the same directory) to write into.
    """
    target = Path(target)
    target.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".part" + target.suffix, dir=target.parent)
    os.close(fd)
    try:
        yield Path(tmp)
        os.chmod(tmp, new_file_mode(current_umask()))
        with open(tmp, "rb") as fh:
            os.fsync(fh.fileno())
        os.replace(tmp, target)
        _fsync_dir(target.parent)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


def new_file_mode(umask: int) -> int:
    """The permission bits ``open()`` gives a new file under ``umask``: ``0o666 & ~umask``.

    Parameters
    ----------
    umask : int
        The process's file mode creation mask (e.g. ``0o022``).

    Returns
    -------
    int
        The mode (``0o644`` under umask ``0o022``, ``0o600`` under ``0o077``).
    """
    return 0o666 & ~umask


def current_umask() -> int:
    """The process's umask, read without changing it where the system allows.

    On Linux it is the ``Umask:`` line of ``/proc/self/status``; elsewhere it is set and restored
    at once (``os.umask`` returns the previous mask only by setting a new one).

    Returns
    -------
    int
        The umask (e.g. ``0o022``).
    """
    try:
        with open("/proc/self/status", encoding="ascii", errors="replace") as fh:
            for line in fh:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError, IndexError):
        pass
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _fsync_dir(directory: Path) -> None:
    """Make a rename durable (best effort: not every platform can open a directory)."""
    try:
        fd = os.open(directory, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def write_table(frame: pd.DataFrame, path: str | os.PathLike) -> Path:
    r"""Write ``frame`` as CSV atomically, with a fixed float format for byte stability.

    Parameters
    ----------
    frame : pandas.DataFrame
        The table; its index is not written, floats as ``%.12g``, lines end in ``\n``.
    path : str or os.PathLike
        Destination file (written through :func:`atomic_path`).

    Returns
    -------
    pathlib.Path
        ``path``.
    """
    with atomic_path(path) as tmp:
        frame.to_csv(tmp, index=False, float_format="%.12g", lineterminator="\n")
    return Path(path)


def read_table(path: str | os.PathLike) -> pd.DataFrame:
    """Read a CSV table written by :func:`write_table`.

    Parameters
    ----------
    path : str or os.PathLike
        The CSV file.

    Returns
    -------
    pandas.DataFrame
        The table, with pandas' default type inference.
    """
    import pandas as pd

    return pd.read_csv(path)


def write_json(obj, path: str | os.PathLike) -> Path:
    """Write ``obj`` as sorted, indented JSON atomically.

    Parameters
    ----------
    obj : object
        JSON-serialisable object; other values are written as their ``str``.
    path : str or os.PathLike
        Destination file (written through :func:`atomic_path`, with a final newline).

    Returns
    -------
    pathlib.Path
        ``path``.
    """
    with atomic_path(path) as tmp:
        tmp.write_text(json.dumps(obj, indent=2, sort_keys=True, default=str) + "\n")
    return Path(path)


def sha256_file(path: str | os.PathLike) -> str:
    """Hex SHA-256 of a file's bytes.

    Parameters
    ----------
    path : str or os.PathLike
        The file, read in 1 MiB chunks.

    Returns
    -------
    str
        The 64-character hexadecimal digest.
    """
    digest = hashlib.sha256()
    with open(path, "rb") as fh:
        for chunk in iter(lambda: fh.read(1 << 20), b""):
            digest.update(chunk)
    return digest.hexdigest()
