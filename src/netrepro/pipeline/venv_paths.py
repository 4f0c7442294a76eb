"""Keep a checkout's ``.venv/`` importing that checkout's ``src/`` (issue 40 item 1), run as a script.

``pip install -e .`` writes the absolute path of ``src/`` into a ``.pth`` file of the virtual
environment, so a moved checkout, or a ``.venv/`` copied along with a checkout, kept importing the
original's code while its provenance recorded the copy's files. A ``.pth`` line may be relative to
its own directory (the ``site`` module joins it to the site-packages directory), so this rewrites
the line as the relative path from site-packages to ``<checkout>/src``: the environment then moves
with its checkout. Run by every ``make`` target that uses the environment (``python
src/netrepro/pipeline/venv_paths.py .venv``: a file, not a module, so that the package it repairs is not
imported through the stale path); silent when nothing is to be done.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

__all__ = ["editable_pth_files", "relocate", "interpreter"]


def interpreter(cwd: str | Path | None = None, executable: str | None = None) -> str:
    """The interpreter as the workflow's commands name it: relative to the checkout when it lies inside it.

    Snakemake records each rule's command as code, so an absolute ``/old/place/.venv/bin/python``
    reran every job of a moved or copied checkout.

    Parameters
    ----------
    cwd : str or Path, optional
        The checkout (default: the working directory).
    executable : str, optional
        The interpreter (default ``sys.executable``, not resolved: ``.venv/bin/python`` is a symlink).

    Returns
    -------
    str
        A shell-quoted path.
    """
    import shlex

    here = Path(cwd or Path.cwd()).resolve()
    python = Path(executable or sys.executable)
    try:
        return shlex.quote(str(python.absolute().relative_to(here)))
    except ValueError:
        return shlex.quote(str(python))


def editable_pth_files(venv: Path) -> list[Path]:
    """The ``.pth`` files of the editable install of netrepro in ``venv``.

    Parameters
    ----------
    venv : Path
        The virtual environment.

    Returns
    -------
    list of Path
    """
    return sorted(Path(venv).glob("lib/python*/site-packages/__editable__.netrepro-*.pth"))


def relocate(venv: Path, src: Path) -> list[str]:
    """Point every editable ``.pth`` of ``venv`` at ``src`` by a relative path; return what changed.

    Parameters
    ----------
    venv : Path
        The virtual environment.
    src : Path
        The checkout's ``src/`` directory.

    Returns
    -------
    list of str
        One sentence per rewritten file (empty when every file already points at ``src``).
    """
    changed = []
    for pth in editable_pth_files(venv):
        site = pth.parent
        lines = pth.read_text().splitlines()
        paths = [line for line in lines if line.strip() and not line.startswith(("#", "import "))]
        wanted = os.path.relpath(Path(src).resolve(), site.resolve())
        if paths == [wanted]:
            continue
        old = [str((site / p).resolve()) for p in paths]
        pth.write_text(wanted + "\n")
        if old != [str(Path(src).resolve())]:
            changed.append(f"{pth.name}: the environment imported netrepro from {', '.join(old) or 'nowhere'}; "
                           f"it now imports this checkout's {Path(src).resolve()} (the checkout moved, or "
                           ".venv/ was copied from another checkout)")
    return changed


if __name__ == "__main__":
    venv = Path(sys.argv[1] if len(sys.argv) > 1 else ".venv")
    for line in relocate(venv, next(p for p in Path(__file__).resolve().parents if p.name == "netrepro").parent):
        print(f"make: {line}", file=sys.stderr)
