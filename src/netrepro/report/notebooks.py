"""The papers' notebooks: the default thin notebook of a paper, the helpers its cells call
(figures with captions, tables), and its execution with papermill into static, offline HTML.

A notebook cell that fails, or runs longer than the execution timeout, stops the execution with
:class:`NotebookError` naming the notebook, the cell and the error: the notebook's rule fails,
the build never hangs on it.
"""

from __future__ import annotations

import html
import os
import re
import shlex
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from markupsafe import Markup

from ..errors import NetreproError
from ..pipeline.io import atomic_path
from .captions import caption_html
from .csp import with_csp
from .markup import relocate, strip_external_scripts

__all__ = ["EXECUTION_TIMEOUT_S", "NotebookError", "make_notebook", "figure_captions", "figure_sort_key",
           "show_figures", "figure_heading_html", "show_table", "execute_notebook", "page_notebook"]

# Seconds one cell may run. The slowest cell of the five notebooks (the figures, embedded as
# PNG) takes about 2 s; ten minutes only stops a cell that hangs.
EXECUTION_TIMEOUT_S = 600


class NotebookError(NetreproError):
    """A paper's notebook failed or timed out."""


def _cells(slug: str):
    import nbformat.v4 as nbf

    params = nbf.new_code_cell(f'slug = "{slug}"\nroot = "."')
    params.metadata["tags"] = ["parameters"]
    return [
        params,
        nbf.new_code_cell(
            "from pathlib import Path\nimport pandas as pd\n"
            "from netrepro.report.notebooks import figure_captions, show_figures, show_table\n"
            "root = Path(root)"
        ),
        nbf.new_markdown_cell(f"# Paper `{slug}`\nFigures (rendered by the pipeline's figure rules), then the claim, "
                              "erratum, finding and reconstruction tables. Every value below is read from `results/`."),
        nbf.new_code_cell("show_figures(root, slug)"),
        nbf.new_markdown_cell("## Claims"),
        nbf.new_code_cell('show_table(root / "results" / "claims" / f"{slug}.csv")'),
        nbf.new_markdown_cell("## Errata"),
        nbf.new_code_cell('show_table(root / "results" / "errata" / f"{slug}.csv")'),
        nbf.new_markdown_cell("## Findings (ours, beyond the paper)"),
        nbf.new_code_cell('show_table(root / "results" / "findings" / f"{slug}.csv")'),
        nbf.new_markdown_cell("## Reconstructions"),
        nbf.new_code_cell('show_table(root / "results" / "reconstructions" / f"{slug}.csv")'),
        nbf.new_markdown_cell("## Result tables (first rows)"),
        nbf.new_code_cell(
            'for table in sorted((root / "results" / slug).glob("*.csv")):\n'
            '    print(table.relative_to(root))\n'
            '    show_table(table, max_rows=8)'
        ),
    ]


def make_notebook(slug: str, path: str | Path) -> Path:
    """Write the default thin notebook of paper ``slug``.

    Parameters
    ----------
    slug : str
        The paper.
    path : str or Path
        Where to write it (``workflow/notebooks/<slug>.ipynb``).

    Returns
    -------
    Path
        ``path``.
    """
    import nbformat
    import nbformat.v4 as nbf

    nb = nbf.new_notebook(cells=_cells(slug))
    nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3", "language": "python"}
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    nbformat.write(nb, str(path))
    return path


def figure_captions(root: Path, slug: str) -> dict:
    """Figure stem -> caption text from ``workflow/report/<slug>/<stem>.rst``.

    Parameters
    ----------
    root : Path
        The checkout.
    slug : str
        The paper.

    Returns
    -------
    dict
        ``{stem: caption}``.
    """
    folder = Path(root) / "workflow" / "report" / slug
    return {p.stem: p.read_text().strip() for p in sorted(folder.glob("*.rst"))}


def figure_sort_key(path: Path):
    """Sort key of a figure file: the paper's figures by number, then ours (``figS<n>``).

    Parameters
    ----------
    path : Path
        A figure file.

    Returns
    -------
    tuple
        ``(ours, number, stem)``.
    """
    match = re.match(r"fig(S?)(\d+)", path.stem)
    return (bool(match and match.group(1)), int(match.group(2)) if match else 0, path.stem)


def show_figures(root, slug):
    """Display the paper's figures with captions (used inside notebooks).

    Parameters
    ----------
    root : str or Path
        The checkout.
    slug : str
        The paper.
    """
    from IPython.display import HTML, Image, display

    captions = figure_captions(root, slug)
    for fig in sorted((Path(root) / "figures" / slug).glob("*.png"), key=figure_sort_key):
        display(HTML(figure_heading_html(fig.stem, captions.get(fig.stem, ""))))
        display(Image(filename=str(fig)))


def figure_heading_html(stem: str, caption: str) -> str:
    """A figure's heading and caption in a notebook, rendered as the report renders captions.

    The caption goes through :func:`netrepro.report.captions.caption_html` (raw HTML and file
    insertion off, links only to safe addresses), not through the notebook's Markdown, which
    passes raw HTML through: a ``<script>`` in a caption is shown as text.

    Parameters
    ----------
    stem : str
        The figure's name (``fig1``).
    caption : str
        Its caption (reStructuredText).

    Returns
    -------
    str
        ``<h3 id=stem>`` with the escaped name, then the caption's HTML.
    """
    return str(Markup('<h3 id="{}">{}</h3>').format(stem, stem) + caption_html(caption))


def show_table(path, max_rows=None):
    """Display a CSV table as HTML (used inside notebooks).

    Parameters
    ----------
    path : str or Path
        The table.
    max_rows : int, optional
        Show only the first rows.
    """
    import pandas as pd  # here, not at the top: the driver that executes the notebook never reads a table
    from IPython.display import HTML, display

    path = Path(path)
    if not path.is_file():
        display(HTML(f"<p><em>{html.escape(str(path))} not built</em></p>"))
        return
    frame = pd.read_csv(path)
    if max_rows is not None:
        frame = frame.head(max_rows)
    display(HTML(frame.to_html(index=False, escape=True, na_rep="")))


def execute_notebook(slug: str, notebook: str | Path, html_out: str | Path, root: str | Path = ".",
                     timeout: float = EXECUTION_TIMEOUT_S) -> Path:
    """Run ``notebook`` with papermill (parameters ``slug``, ``root``) and export static HTML.

    Parameters
    ----------
    slug : str
        The paper.
    notebook : str or Path
        The notebook to run.
    html_out : str or Path
        The page to write (the executed notebook is kept beside it as ``.ipynb``), offline and with
        the report's content security policy (no script runs, :data:`netrepro.report.csp.PAGE_POLICY`).
    root : str or Path, default "."
        The checkout; the kernel runs there.
    timeout : float, default :data:`EXECUTION_TIMEOUT_S`
        Seconds one cell may run (papermill's ``execution_timeout``).

    Returns
    -------
    Path
        ``html_out``.

    Raises
    ------
    NotebookError
        A cell raised, or ran longer than ``timeout``, or the kernel did not start; no page is written.
    """
    import nbformat

    print("command:", shlex.join(getattr(sys, "orig_argv", sys.argv)), flush=True)
    root = Path(root).resolve()
    html_out = Path(html_out)
    executed = html_out.with_suffix(".ipynb")
    # The exporter (nbconvert's import, its templates) is made in a thread while this process waits for
    # the kernel: 1.57 -> 1.42 s of wall for a notebook job, and the last one is on the build's critical
    # path. papermill is imported first: two imports at once only take turns holding the GIL.
    import papermill  # noqa: F401

    with ThreadPoolExecutor(max_workers=1) as pool:
        exporter = pool.submit(_html_exporter)
        with tempfile.TemporaryDirectory(prefix=SOCKET_FOLDER_PREFIX, dir=_socket_parent()) as sockets:
            _run_papermill(slug, notebook, executed, root, timeout, sockets)
        exporter = exporter.result()
    body, _ = exporter.from_notebook_node(page_notebook(nbformat.read(str(executed), as_version=4), slug))
    with atomic_path(html_out) as tmp:
        tmp.write_text(with_csp(relocate(strip_external_scripts(body), root)))
    return html_out


def page_notebook(nb, slug: str, title: str | None = None):
    """The executed notebook as its page shows it: titled by its paper, its parameters cell once.

    papermill keeps the notebook's own ``parameters`` cell (its defaults) and adds the values it
    ran with in an ``injected-parameters`` cell right after it: the page showed the parameters
    twice. The page keeps the injected cell (what ran) and drops the defaults it replaced; the
    executed ``.ipynb`` beside the page keeps both. The page's ``<title>`` (nbconvert's lab
    template reads ``metadata.title``) is ``<slug>: <paper's title> — notebook``.

    Parameters
    ----------
    nb : nbformat.NotebookNode
        The executed notebook (changed in place).
    slug : str
        The paper.
    title : str, optional
        The paper's title (default: from the paper registry; the slug if it has none).

    Returns
    -------
    nbformat.NotebookNode
        ``nb``.
    """
    def tags(cell):
        return set(cell.get("metadata", {}).get("tags", []))

    if any("injected-parameters" in tags(c) for c in nb.cells):
        nb.cells = [c for c in nb.cells if "parameters" not in tags(c) or "injected-parameters" in tags(c)]
    if title is None:
        from ..pipeline.registry import load_registry

        title = load_registry().get(slug, {}).get("title") or slug
    nb.metadata["title"] = f"{slug}: {title} \u2014 notebook"
    return nb


# A Unix socket's path must fit in sun_path: 108 bytes on Linux, 104 on macOS, including the final NUL.
SOCKET_PATH_MAX = 103
# The kernel's sockets: <parent>/<prefix><8 random characters>/<name>-<channel number 1..5>.
SOCKET_FOLDER_PREFIX = "netrepro-kernel-"
SOCKET_NAME = "kernel"


def _socket_parent(tmp: str | None = None) -> str:
    """Where the kernel's socket folder goes: the temporary directory, or /tmp when the socket paths
    under it would be too long for a Unix socket (a long ``TMPDIR``, as some clusters set).

    Raises
    ------
    NotebookError
        Neither folder gives short enough socket paths.
    """
    longest = os.path.join(SOCKET_FOLDER_PREFIX + "x" * 8, SOCKET_NAME + "-99")  # a margin over channel 5
    for parent in (tmp or tempfile.gettempdir(), "/tmp"):
        if len(os.path.join(parent, longest).encode()) <= SOCKET_PATH_MAX and os.path.isdir(parent):
            return parent
    raise NotebookError(f"the kernel's Unix sockets would have paths longer than {SOCKET_PATH_MAX} bytes under "
                        f"{tmp or tempfile.gettempdir()!r}, and /tmp is not usable: set TMPDIR to a shorter folder")


def _html_exporter():
    """nbconvert's HTML exporter, its templates loaded (an empty notebook exported once)."""
    import nbformat
    from nbconvert import HTMLExporter

    exporter = HTMLExporter()
    exporter.from_notebook_node(nbformat.v4.new_notebook())
    return exporter


def _run_papermill(slug: str, notebook, executed: Path, root: Path, timeout: float, sockets: str) -> None:
    """Execute ``notebook`` into ``executed`` on a kernel whose channels are Unix sockets in ``sockets``.

    Why not TCP: Jupyter picks a kernel's five TCP ports by binding port 0 and releasing it, so
    kernels started at the same moment by other processes (the other notebook job, a test) can
    take the same port. The kernel then dies at its bind and the client waits out its 60-s
    start-up timeout ("Address already in use", seen in CI). Socket files in a private folder
    cannot collide.
    """
    import papermill
    from nbclient.exceptions import CellTimeoutError, DeadKernelError
    from traitlets.config import Config

    # configured, not passed as ``km=``: nbclient shuts down only a kernel manager it created
    kernel = Config({"KernelManager": {"transport": "ipc", "ip": os.path.join(sockets, SOCKET_NAME)}})

    # The kernel runs in ``root``, so the parameter cell says ``root = "."``: the page shows no
    # path of the machine that built it (and any path a warning prints is made relative too).
    try:
        papermill.execute_notebook(str(notebook), str(executed), parameters={"slug": slug, "root": "."},
                                   kernel_name="python3", cwd=str(root), progress_bar=False,
                                   request_save_on_cell_execute=False, execution_timeout=timeout, config=kernel)
    except papermill.PapermillExecutionError as exc:
        raise NotebookError(f"notebook {notebook} (paper {slug}): cell {exc.exec_count} failed: "
                            f"{exc.ename}: {exc.evalue}") from None
    except CellTimeoutError as exc:
        raise NotebookError(f"notebook {notebook} (paper {slug}): a cell ran longer than the execution timeout "
                            f"of {timeout:g} s and was stopped ({str(exc).splitlines()[0]})") from None
    except DeadKernelError as exc:
        raise NotebookError(f"notebook {notebook} (paper {slug}): the kernel died ({exc})") from None
    except RuntimeError as exc:  # nbclient's only signal that the kernel did not start
        raise NotebookError(f"notebook {notebook} (paper {slug}): the kernel did not start ({exc}); "
                            "its own error is printed above") from None
