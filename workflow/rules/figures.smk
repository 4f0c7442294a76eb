# Generated rules: one per figure of each paper's figure list
# (src/netrepro/papers/<slug>/figures.yaml), and one notebook per paper.
# Included after the papers' own rules, whose outputs the figures read.


for _slug in [s for s in config["papers"] if s in PAPER_TABLES]:
    _specs = figure_specs(_slug)
    for _spec in _specs:

        rule:
            name:
                _spec.rule
            input:
                **figure_inputs(_spec),
                code=code(_spec.func),
            output:
                figure=report(
                    _spec.path,
                    caption=f"../report/{_slug}/{_spec.figure_id}.rst",
                    category=_slug,
                ),
                # what the figure draws (netrepro.figures.plotting.save_figure), compared by `make check`
                data=f"figures/{_slug}/{_spec.figure_id}.data.json",
            log:
                f"logs/{_slug}/{_spec.figure_id}.log",
            localrule: True
            conda:
                CONDA_ENV
            params:
                func=_spec.func,
                cfg=as_json(_spec.params),
                rule=_spec.rule,
                io=io_json,
            shell:
                step()

    _figures = [_spec.path for _spec in _specs]
    # what each figure draws: read by `make check`; an input here so that a missing one is rebuilt
    _figure_data = [f"figures/{_slug}/{_spec.figure_id}.data.json" for _spec in _specs]
    # the notebook and the report show the captions and the figure list's layout notes
    _captions = [f"workflow/report/{_slug}/{_spec.figure_id}.rst" for _spec in _specs]
    _figure_list = f"src/netrepro/papers/{_slug}/figures.yaml"
    _verdicts = getattr(rules, f"{_slug}_claims").output
    _claims = _verdicts.table
    _errata = _verdicts.errata
    _reconstructions = _verdicts.reconstructions
    _findings = _verdicts.findings

    rule:
        name:
            f"{_slug}_notebook"
        input:
            notebook=f"workflow/notebooks/{_slug}.ipynb",
            code=code("netrepro.report.notebooks"),
            figures=_figures,
            figure_data=_figure_data,
            tables=PAPER_TABLES[_slug],
            claims=_claims,
            errata=_errata,
            reconstructions=_reconstructions,
            findings=_findings,
            captions=_captions,
            figure_list=_figure_list,
        output:
            html=f"report/{_slug}.html",
        log:
            f"logs/{_slug}/notebook.log",
        localrule: True
        conda:
            CONDA_ENV
        params:
            slug=_slug,
        shell:
            notebook()

    PAPER_OUTPUTS[_slug] = dict(
        figures=_figures,
        tables=PAPER_TABLES[_slug],
        claims=_claims,
        errata=_errata,
        reconstructions=_reconstructions,
        findings=_findings,
        captions=_captions,
        figure_list=_figure_list,
        notebook=f"report/{_slug}.html",
    )
