# The combined report: report/index.html from every paper's claims, errata, figures and sidecars,
# plus report/files/ (copies of every table and figure with their sidecars, the workflow and its
# configuration, browsable source files), so that report/ works offline as static files, and
# report/ro-crate-metadata.json, the Workflow Run Crate of the run (netrepro.release.crate). `snakemake --report` uses the description below.
import os
import platform

from netrepro.pipeline.provenance import params_hash


report: "../report/workflow.rst"


rule scale_verdicts:
    input:
        code=code("netrepro.scale.record:scale_step"),
        claims=[spec["claims"] for spec in PAPER_OUTPUTS.values()],
        findings=[spec["findings"] for spec in PAPER_OUTPUTS.values()],
        provenance=f"{SCALE_REFERENCE}/provenance.json",
        reference=sorted(str(p) for p in Path(SCALE_REFERENCE).glob("*/*.csv")),
        sources=scale_sources,
    output:
        table="results/scale/verdicts_by_scale.csv",
        findings="results/scale/findings_by_scale.csv",
        stale="results/scale/stale_sources.csv",
    log:
        "logs/scale_verdicts.log",
    localrule: True
    conda:
        CONDA_ENV
    params:
        cfg=as_json({"reference": SCALE_REFERENCE}),
        rule="scale_verdicts",
        io=io_json,
    shell:
        step("netrepro.scale.record:scale_step")


# The report's source pages (report/files/source/), highlighted ahead of the report, which did this last
# (~2-3 CPU s in every build and figure rerun): every file of the steps' code (CODE_FILES, read when the
# DAG is built, after all rules are defined); rerun when that code or the page template changes.
rule report_sources:
    input:
        code=code("netrepro.report.site:source_pages_step"),
        sources=lambda wildcards: sorted(CODE_FILES),
        templates=[
            f"src/netrepro/report/templates/{t}" for t in ("source.html", "source_lines.html")
        ],
    output:
        pages=directory("report/files/source"),
    log:
        "logs/report_sources.log",
    conda:
        CONDA_ENV
    params:
        cfg=as_json({}),
        rule="report_sources",
        io=io_json,
    shell:
        step("netrepro.report.site:source_pages_step")


rule report:
    input:
        unpack(report_inputs),
        code=code("netrepro.report.build:build_index"),
        # titles and citations: a title fix reruns the report, and nothing of any paper
        registry="src/netrepro/papers.yaml",
        # the markup and the style sheet are data, not code: a change of look reruns the report
        templates=sorted(str(p) for p in Path("src/netrepro/report/templates").glob("*.*")),
        scale=rules.scale_verdicts.output if SCALE_RECORDED else [],
        source_pages=rules.report_sources.output.pages,
    output:
        # one page per paper (the index holds the summary, the scorecard and the claims explorer)
        **{f"page_{slug}": f"report/paper-{slug}.html" for slug in PAPER_OUTPUTS},
        html="report/index.html",
        files_data=directory("report/files/data"),
        files_workflow=directory("report/files/workflow"),
        crate="report/ro-crate-metadata.json",
    log:
        "logs/report.log",
    conda:
        CONDA_ENV
    threads: 1
    params:
        cfg=as_json(
            {
                "papers": PAPER_OUTPUTS,
                "order": [slug for slug in config["papers"] if slug in PAPER_OUTPUTS],
                # the science's hash: shard counts split the work and change no table
                "config_hash": params_hash({k: v for k, v in config.items() if k != "shards"}),
                "config": {slug: config.get(slug, {}) for slug in PAPER_OUTPUTS},
                "configfiles": [os.path.relpath(f) for f in workflow.overwrite_configfiles or []],
                "machine": f"{platform.system()} {platform.machine()}",
                "benchmarks": "results/benchmarks.csv",
                "scale": (
                    {**rules.scale_verdicts.output, "reference": SCALE_REFERENCE}
                    if SCALE_RECORDED
                    else {}
                ),
            }
        ),
        # a function: the plain string "report" prefixes the outputs' paths, which the lint flags
        rule=lambda wildcards: "report",
        io=io_json,
    shell:
        step("netrepro.report.build:build_index")
