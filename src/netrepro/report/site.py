"""The static site around ``report/index.html``: copies of the tables (with relocated sidecars),
of the workflow and configuration files, and one highlighted page per source file, all under
``report/files/`` so that the report works offline."""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

from markupsafe import Markup

from ..pipeline.provenance import sidecar_path
from .confine import confined
from .markup import relocate_json, render
from .panel import repo_relative

__all__ = ["Site", "source_page", "source_pages", "source_pages_step"]


class Site:
    """Files the index links to, copied under ``report/files/`` so the report is self-contained.

    Parameters
    ----------
    root : Path
        The checkout.
    out_dir : Path or None
        ``report/files``; ``None`` links to the checkout's own files instead.
    workers : int, default 1
        Processes that highlight the source pages.
    pages_made : bool, default False
        The source pages are already under ``out_dir/source/`` (rule ``report_sources``,
        :func:`source_pages_step`): link those, and a file without a page to the checkout's copy; else
        the pages of the linked files are highlighted by :meth:`write`.
    """

    def __init__(self, root: Path, out_dir: Path | None, workers: int = 1, pages_made: bool = False):
        self.root = root
        self.workers = workers
        self.pages_made = pages_made
        self.out_dir = out_dir
        self.sources: set[str] = set()
        self.tables: set[str] = set()
        self.raw: dict[str, str] = {}  # copy target under files/ -> source file (workflow, config)

    def source_link(self, source_file: str, line=None) -> str:
        """Link to the page of a source file (at line ``line``), registering the page.

        Raises :class:`~netrepro.report.confine.OutsideCheckoutError` for a file outside the checkout.
        """
        rel = confined(repo_relative(source_file), self.root, "a source file linked from the report")
        if self.out_dir is None or not (self.root / rel).is_file():
            return f"../{rel}"
        if self.pages_made and not (self.out_dir / "source" / f"{rel}.html").is_file():
            return f"../{rel}"
        self.sources.add(rel)
        return f"files/source/{rel}.html" + (f"#L-{int(line)}" if line else "")

    def table_link(self, path: str) -> str:
        """Link to the copy of a table, registering the copy.

        Raises :class:`~netrepro.report.confine.OutsideCheckoutError` for a table outside the checkout.
        """
        path = confined(path, self.root, "a table linked from the report")
        if self.out_dir is None or not (self.root / path).is_file():
            return f"../{path}"
        self.tables.add(str(path))
        return f"files/data/{path}"

    def write(self) -> None:
        """Copy the registered tables, workflow files and source pages under ``out_dir``.

        Every file copied comes from inside the checkout and lands inside ``out_dir``; checked for all
        of them before the first copy (:class:`~netrepro.report.confine.OutsideCheckoutError` names the
        file), so a refused path leaves nothing copied.
        """
        if self.out_dir is None:
            return
        self._confine_copies()
        for sub in ("data", "workflow"):  # the report rule's two folder outputs, even if empty
            (self.out_dir / sub).mkdir(parents=True, exist_ok=True)
        for rel in sorted(self.tables):
            target = self.out_dir / "data" / rel
            target.parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(self.root / rel, target)
            side = sidecar_path(self.root / rel)
            if side.is_file():  # relocated: no absolute path of the build machine in the report
                meta = relocate_json(json.loads(side.read_text()), self.root)
                sidecar_path(target).write_text(json.dumps(meta, indent=2, sort_keys=True) + "\n")
        for rel, source in sorted(self.raw.items()):
            target = self.out_dir / rel
            target.parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(self.root / source, target)
        if self.pages_made:
            return
        rels = sorted(self.sources)
        for rel, page in zip(rels, source_pages(self.root, rels, self.workers)):
            target = self.out_dir / "source" / f"{rel}.html"
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_text(page)

    def _confine_copies(self) -> None:
        """Refuse a copy whose source is outside the checkout or whose target is outside ``out_dir``."""
        pages = [] if self.pages_made else sorted(self.sources)
        copies = [*((rel, f"data/{rel}") for rel in sorted(self.tables)),
                  *((source, rel) for rel, source in sorted(self.raw.items())),
                  *((rel, f"source/{rel}.html") for rel in pages)]
        out = Path(self.out_dir).resolve()
        for source, target in copies:
            confined(source, self.root, f"the report's copy {target}")
            confined(out / target, out, f"the report's copy of {source}")


def source_pages_step(params: dict, inputs: dict, outputs: dict) -> dict:
    """Pipeline step: the report's source pages, highlighted ahead of the report (rule ``report_sources``).

    Highlighting the source files the report links takes ~2-3 CPU s; done by the report rule, it was part of
    the last job of every build and of every rerun of a figure. This step writes the page of every file of the
    workflow's code inputs (a superset of the linked ones) into ``report/files/source/``, once per change of
    the code, in parallel with the other jobs; the report links the pages it finds there.

    Parameters
    ----------
    params : dict
        Unused (the files are the inputs).
    inputs : dict
        ``sources``: the source files (repository-relative), besides the step's own ``code``.
    outputs : dict
        ``pages``: the folder of pages, ``<pages>/<file>.html``.

    Returns
    -------
    dict
        The number of pages, for the provenance.
    """
    root = Path(".").resolve()
    rels = sorted({str(p) for p in inputs["sources"]})
    out = Path(outputs["pages"])
    workers = int(os.environ.get("OMP_NUM_THREADS") or 1)
    for rel, page in zip(rels, source_pages(root, rels, workers)):
        target = out / f"{rel}.html"
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_text(page)
    return {"provenance": {"pages": len(rels)}}


def _source_pages_of(root: Path, rels: list[str]) -> list[str]:
    """:func:`source_page` of each file ``rels`` (relative to ``root``), in order."""
    return [source_page(rel, (root / rel).read_text()) for rel in rels]


def source_pages(root: Path, rels: list[str], workers: int = 1) -> list[str]:
    """The source pages of ``rels``, in order, highlighted by up to ``workers`` processes.

    Highlighting (pygments' Python lexer) is most of the report rule's time, and the rule runs
    last, alone: with ``threads: 2`` the second core takes half of the files (interleaved by
    size, so both halves take about as long). The pages do not depend on the split.

    Parameters
    ----------
    root : Path
        The checkout.
    rels : list of str
        Source files relative to ``root``.
    workers : int, default 1
        Processes (never more than files).

    Returns
    -------
    list of str
        One page per file, in the order of ``rels``.
    """
    workers = max(1, min(int(workers), len(rels)))
    if workers == 1:
        return _source_pages_of(root, rels)
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    by_size = sorted(range(len(rels)), key=lambda i: -(root / rels[i]).stat().st_size)
    shares = [by_size[w::workers] for w in range(workers)]
    context = multiprocessing.get_context("fork" if "fork" in multiprocessing.get_all_start_methods() else None)
    with ProcessPoolExecutor(max_workers=workers, mp_context=context) as pool:
        done = pool.map(_source_pages_of, [root] * workers, [[rels[i] for i in share] for share in shares])
        pages = [""] * len(rels)
        for share, share_pages in zip(shares, done):
            for i, page in zip(share, share_pages):
                pages[i] = page
    return pages


def source_page(rel: str, code: str) -> str:
    """A static, offline page of one source file; line N has the anchor ``#L-N``.

    Parameters
    ----------
    rel : str
        The file, relative to the checkout.
    code : str
        Its text.

    Returns
    -------
    str
        The page.
    """
    try:
        import re

        from pygments import highlight
        from pygments.formatters import HtmlFormatter
        from pygments.lexers import PythonLexer

        formatter = HtmlFormatter(linenos="inline", linespans="L", anchorlinenos=True, lineanchors="N",
                                  cssclass="code")
        body = highlight(code, PythonLexer(), formatter)
        style = formatter.get_style_defs(".code")
        body = re.sub(r'<span id="L-(\d+)">', r'<span id="L-\1" class="line">', body)
    except ImportError:
        style = ""
        body = render("source_lines.html", lines=code.splitlines())
    return render("source.html", rel=rel, style=Markup(style), body=Markup(body), up="../" * (rel.count("/") + 2))
