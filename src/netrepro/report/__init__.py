"""The report: per-paper papermill notebooks and the combined ``report/index.html``.

* :mod:`.notebooks`: the default thin notebook of a paper, the helpers its cells call, and its
  execution with papermill (with a timeout) into static HTML.
* :mod:`.markup`: offline pages (no network request), relocated paths, the Jinja2 templates.
* :mod:`.site`: the copies under ``report/files/`` and the source pages.
* :mod:`.sections`: scorecard, paper sections, claims, figures.
* :mod:`.panel`: the provenance panel of a figure.
* :mod:`.build`: the report rule's step (:func:`build_index`), with the RO-Crate.
* :mod:`.cli`: ``python -m netrepro report``.
"""

__all__: list[str] = []
