"""The lock files in ``requirements/`` and the conda environment written from them.

``requirements/default.txt`` (what ``make report`` installs) and ``requirements/test.txt``
(``make test``: the default environment plus the ``test`` extra) pin every package to an exact
version with its hashes; ``make lock`` writes them with uv (``uv pip compile``). pip installs
them (``pip install --require-hashes -r ...``), so installing needs no other tool.

:func:`conda_env` writes ``workflow/envs/netrepro.yaml`` (the software of ``--sdm conda``) with
the same pins: ``python -m netrepro lockfile conda-env requirements/default.txt
workflow/envs/netrepro.yaml`` (run by ``make lock``).
"""

from __future__ import annotations

import argparse
import re
import sys
from dataclasses import dataclass
from pathlib import Path

__all__ = ["Pin", "read_lock", "normalize", "conda_env", "main"]

_PIN = re.compile(r"^(?P<name>[A-Za-z0-9][A-Za-z0-9._-]*)==(?P<version>[^\s;\\]+)\s*(?:;\s*(?P<marker>[^\\]+?))?\s*\\?\s*$")
_HASH = re.compile(r"--hash=(sha256:[0-9a-f]{64})")


@dataclass(frozen=True)
class Pin:
    """One locked package: name, exact version, environment marker (or ""), hashes.

    Parameters
    ----------
    name : str
        Package name as written in the lock file.
    version : str
        Exact pinned version.
    marker : str
        PEP 508 environment marker, ``""`` if none.
    hashes : tuple of str
        The ``--hash`` values, as ``algorithm:hex``.
    """

    name: str
    version: str
    marker: str
    hashes: tuple[str, ...]

    @property
    def requirement(self) -> str:
        return f"{self.name}=={self.version}" + (f" ; {self.marker}" if self.marker else "")


def normalize(name: str) -> str:
    """A package name as PEP 503 compares it (``Foo_Bar`` -> ``foo-bar``).

    Parameters
    ----------
    name : str
        Package name.

    Returns
    -------
    str
        Lower case, each run of ``-``, ``_``, ``.`` replaced by one ``-``.
    """
    return re.sub(r"[-_.]+", "-", name).lower()


def read_lock(path: str | Path) -> dict[str, Pin]:
    """The pins of a lock file written by ``uv pip compile --generate-hashes``, by normalized name.

    Parameters
    ----------
    path : str or Path
        The lock file (``name==version [; marker]`` lines, each followed by indented ``--hash`` lines).

    Returns
    -------
    dict of str to Pin
        :func:`normalize`'d name -> its pin.
    """
    pins: dict[str, Pin] = {}
    current = None
    for line in Path(path).read_text().splitlines():
        match = _PIN.match(line)
        if match:
            current = normalize(match["name"])
            pins[current] = Pin(match["name"], match["version"], (match["marker"] or "").strip(), ())
            continue
        hashed = _HASH.search(line)
        if hashed and current:
            pin = pins[current]
            pins[current] = Pin(pin.name, pin.version, pin.marker, pin.hashes + (hashed.group(1),))
        elif not line.startswith(" "):
            current = None
    return pins


def conda_env(lock: str | Path, out: str | Path, python: str = "3.11") -> Path:
    """Write the conda environment of the rules with the exact pins of ``lock``.

    Parameters
    ----------
    lock : str or Path
        Lock file read by :func:`read_lock`.
    out : str or Path
        Environment file to write (conda-forge Python and pip, the pins as pip requirements
        sorted by normalized name, then the package itself as ``-e ../..``).
    python : str, default "3.11"
        Python version of the environment.

    Returns
    -------
    Path
        ``out``.
    """
    pins = read_lock(lock)
    lines = [
        "# Software of every rule (used with --sdm conda; the default route is `make`, which builds .venv/).",
        f"# Written by `make lock` from {Path(lock).as_posix()}: the same exact versions (pip installs",
        "# them from PyPI; the hashes stay in the lock file, which `make` installs with --require-hashes).",
        "channels:",
        "  - conda-forge",
        "dependencies:",
        f"  - python={python}",
        "  - pip",
        "  - pip:",
        *(f'      - "{pin.requirement}"' for pin in sorted(pins.values(), key=lambda p: normalize(p.name))),
        "      - -e ../..",
    ]
    out = Path(out)
    out.write_text("\n".join(lines) + "\n")
    return out


def main(argv=None) -> int:
    """``python -m netrepro lockfile conda-env LOCK OUT``: write the conda environment file.

    Parameters
    ----------
    argv : list of str, optional
        Command-line arguments (default ``sys.argv[1:]``).

    Returns
    -------
    int
        Exit status 0.
    """
    parser = argparse.ArgumentParser(prog="python -m netrepro lockfile")
    sub = parser.add_subparsers(dest="command", required=True)
    env = sub.add_parser("conda-env", help="write the conda environment file with the pins of a lock file")
    env.add_argument("lock")
    env.add_argument("out")
    args = parser.parse_args(argv)
    print(conda_env(args.lock, args.out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
