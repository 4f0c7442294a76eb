"""Paths the report reads or copies stay inside the checkout (issue 38).

The report copies tables, sidecars and source files into ``report/files/`` by the paths the
provenance sidecars record. A sidecar edited to say ``../../etc/hostname`` made the report build
read that file and copy it outside the report and the checkout. Every such path is now checked
first: one that resolves (symbolic links followed) outside the checkout stops the build with a
message naming the sidecar, the field and the path, and nothing is read or copied.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path

from ..errors import NetreproError

__all__ = ["OutsideCheckoutError", "resolves_outside", "confined", "sidecar_paths", "confine_sidecar"]


class OutsideCheckoutError(NetreproError, ValueError):
    """A path the report would read or copy resolves outside the checkout; the message names where it came from."""


def resolves_outside(path: str | Path, root: str | Path) -> bool:
    """Whether ``path`` (relative to ``root``, or absolute) resolves outside ``root``.

    Parameters
    ----------
    path : str or Path
        A path as recorded (``results/x.csv``, ``../x``, ``/etc/x``).
    root : str or Path
        The checkout.

    Returns
    -------
    bool
        True if the resolved path (``..`` and symbolic links followed) is not ``root`` or under it.
    """
    root = Path(root).resolve()
    return not (root / path).resolve().is_relative_to(root)


def confined(path: str | Path, root: str | Path, named_by: str) -> str:
    """``path`` relative to the checkout, refused if it resolves outside.

    Parameters
    ----------
    path : str or Path
        A path the report would read or copy.
    root : str or Path
        The checkout.
    named_by : str
        Where the path was found, for the message (``"the provenance sidecar X (field 'output')"``).

    Returns
    -------
    str
        The path relative to ``root`` (POSIX form): its name as written, with ``.`` and ``..`` parts
        removed (a symbolic link inside the checkout keeps its own name).

    Raises
    ------
    OutsideCheckoutError
        The path resolves outside ``root``.
    """
    root = Path(root).resolve()
    resolved = (root / path).resolve()
    if not resolved.is_relative_to(root):
        raise OutsideCheckoutError(
            f"{named_by} names the path {str(path)!r}, which resolves to {resolved}, outside the checkout "
            f"{root}: the report reads and copies nothing from outside the checkout. Rebuild the output "
            "whose sidecar this is (a sidecar edited by hand, or copied from another checkout?)")
    written = Path(os.path.normpath(root / path))
    return (written if written.is_relative_to(root) else resolved).relative_to(root).as_posix()


def sidecar_paths(meta: dict) -> list[tuple[str, str]]:
    """The paths a provenance sidecar records, with the field that records each.

    Parameters
    ----------
    meta : dict
        A sidecar (``<output>.meta.json``).

    Returns
    -------
    list of tuple
        ``(field, path)``: ``output``, ``inputs.<name>.path`` and ``source_file``, where present.
    """
    found = [("output", meta["output"])] if meta.get("output") else []
    inputs = meta.get("inputs")
    for name, item in (inputs.items() if isinstance(inputs, dict) else ()):
        if isinstance(item, dict) and item.get("path"):
            found.append((f"inputs.{name}.path", item["path"]))
    if meta.get("source_file"):
        found.append(("source_file", meta["source_file"]))
    return [(field, str(path)) for field, path in found]


def confine_sidecar(meta: dict, sidecar: str | Path, root: str | Path,
                    source_form: Callable[[str], str] = str) -> None:
    """Refuse a sidecar that names a path outside the checkout.

    Parameters
    ----------
    meta : dict
        The sidecar's content.
    sidecar : str or Path
        The sidecar's file, for the message.
    root : str or Path
        The checkout.
    source_form : callable, default str
        How the report reads ``source_file`` (an absolute path into ``src/netrepro/`` of an editable
        install becomes its ``src/netrepro/...`` form, :func:`netrepro.report.panel.repo_relative`).

    Raises
    ------
    OutsideCheckoutError
        A path field resolves outside ``root``; the message names the sidecar, the field and the path.
    """
    for field, path in sidecar_paths(meta):
        shown = source_form(path) if field == "source_file" else path
        if shown != "?":  # a step without a source file records "?"
            confined(shown, root, f"the provenance sidecar {sidecar} (field {field!r})")
