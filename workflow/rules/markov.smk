# Paper `markov` (004): Wu, Shi, Anderson, Johansson, Kalman filtering over Gilbert-Elliott channels.
# Compute steps -> tables under results/markov/, one rule per figure, claims, errata, notebook.

MCFG = config.get("markov", {})
MARKOV_CODE = ("papers/markov.py", "papers/markov_math.py")


rule markov_critical_curves:
    input:
        code=code("netrepro.papers.markov:critical_curves_step"),
    output:
        table="results/markov/critical_curves.csv",
        benchmark="results/markov/lmi_benchmark.csv",
    params:
        cfg=as_json(pick(MCFG, "examples", "curves")),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/markov/critical_curves.log",
    shell:
        step("netrepro.papers.markov:critical_curves_step")


rule markov_lmi_checks:
    input:
        code=code("netrepro.papers.markov:lmi_checks_step"),
    output:
        table="results/markov/lmi_checks.csv",
    params:
        cfg=as_json(pick(MCFG, "examples", "checks")),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/markov/lmi_checks.log",
    shell:
        step("netrepro.papers.markov:lmi_checks_step")


rule markov_iid_line:
    input:
        code=code("netrepro.papers.markov:iid_line_step"),
    output:
        table="results/markov/iid_line.csv",
    params:
        cfg=as_json(pick(MCFG, "examples", "iid")),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/markov/iid_line.log",
    shell:
        step("netrepro.papers.markov:iid_line_step")


rule markov_exact_moments:
    input:
        code=code("netrepro.papers.markov:exact_moments_step"),
    output:
        table="results/markov/exact_moments.csv",
    params:
        cfg=as_json(pick(MCFG, "examples", "exact")),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/markov/exact_moments.log",
    resources:
        mem_mb=1000,
    shell:
        step("netrepro.papers.markov:exact_moments_step")


rule markov_stability_map:
    input:
        code=code("netrepro.papers.markov:stability_map_step"),
        moments="results/markov/exact_moments.csv",
    output:
        table="results/markov/stability_map.csv",
    params:
        cfg=as_json(pick(MCFG, "examples", "map")),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/markov/stability_map.log",
    shell:
        step("netrepro.papers.markov:stability_map_step")


rule markov_sample_paths:
    input:
        code=code("netrepro.papers.markov:sample_paths_step"),
        moments="results/markov/exact_moments.csv",
    output:
        table="results/markov/sample_paths.csv",
        check="results/markov/estimator_check.csv",
    params:
        cfg=as_json(pick(MCFG, "examples", "paths")),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/markov/sample_paths.log",
    shell:
        step("netrepro.papers.markov:sample_paths_step")


rule markov_errata:
    input:
        code=code("netrepro.papers.markov:errata_step"),
        checks="results/markov/lmi_checks.csv",
    output:
        table="results/errata/markov.csv",
    params:
        cfg=as_json(pick(MCFG, "examples")),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/markov/errata.log",
    shell:
        step("netrepro.papers.markov:errata_step")


rule markov_reconstructions:
    input:
        code=code("netrepro.papers.markov:reconstructions_step"),
    output:
        table="results/reconstructions/markov.csv",
    params:
        cfg=as_json(pick(MCFG, "examples", "paths", "checks", "exact", "map", "curves")),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/markov/reconstructions.log",
    shell:
        step("netrepro.papers.markov:reconstructions_step")


rule markov_claims:
    input:
        code=code("netrepro.papers.markov:claims_step"),
        checks="results/markov/lmi_checks.csv",
        curves="results/markov/critical_curves.csv",
        iid="results/markov/iid_line.csv",
        map="results/markov/stability_map.csv",
        moments="results/markov/exact_moments.csv",
    output:
        table="results/claims/markov.csv",
    params:
        cfg=as_json(pick(MCFG, "examples", "map")),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/markov/claims.log",
    shell:
        step("netrepro.papers.markov:claims_step")


rule markov_fig2:
    input:
        code=code("netrepro.papers.markov:figure_plane"),
        curves="results/markov/critical_curves.csv",
        map="results/markov/stability_map.csv",
        iid="results/markov/iid_line.csv",
    output:
        figure=report("figures/markov/fig2.png", caption="../report/markov/fig2.rst", category="markov"),
    params:
        cfg=as_json(pick(MCFG, "examples")),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/markov/fig2.log",
    shell:
        step("netrepro.papers.markov:figure_plane")


rule markov_fig3:
    input:
        code=code("netrepro.papers.markov:figure_path"),
        paths="results/markov/sample_paths.csv",
    output:
        figure=report("figures/markov/fig3.png", caption="../report/markov/fig3.rst", category="markov"),
    params:
        cfg=as_json({"figure": "fig3"}),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/markov/fig3.log",
    shell:
        step("netrepro.papers.markov:figure_path")


rule markov_fig4:
    input:
        code=code("netrepro.papers.markov:figure_path"),
        paths="results/markov/sample_paths.csv",
    output:
        figure=report("figures/markov/fig4.png", caption="../report/markov/fig4.rst", category="markov"),
    params:
        cfg=as_json({"figure": "fig4"}),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/markov/fig4.log",
    shell:
        step("netrepro.papers.markov:figure_path")


rule markov_fig5:
    input:
        code=code("netrepro.papers.markov:figure_path"),
        paths="results/markov/sample_paths.csv",
    output:
        figure=report("figures/markov/fig5.png", caption="../report/markov/fig5.rst", category="markov"),
    params:
        cfg=as_json({"figure": "fig5"}),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/markov/fig5.log",
    shell:
        step("netrepro.papers.markov:figure_path")


rule markov_fig6:
    input:
        code=code("netrepro.papers.markov:figure_mean"),
        paths="results/markov/sample_paths.csv",
    output:
        figure=report("figures/markov/fig6.png", caption="../report/markov/fig6.rst", category="markov"),
    params:
        cfg=as_json({"figure": "fig6"}),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/markov/fig6.log",
    shell:
        step("netrepro.papers.markov:figure_mean")


rule markov_figS1:
    input:
        code=code("netrepro.papers.markov:figure_estimators"),
        check="results/markov/estimator_check.csv",
    output:
        figure=report("figures/markov/figS1.png", caption="../report/markov/figS1.rst", category="markov"),
    params:
        cfg=as_json({}),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/markov/figS1.log",
    shell:
        step("netrepro.papers.markov:figure_estimators")


rule markov_figS2:
    input:
        code=code("netrepro.papers.markov:figure_curves"),
        curves="results/markov/critical_curves.csv",
    output:
        figure=report("figures/markov/figS2.png", caption="../report/markov/figS2.rst", category="markov"),
    params:
        cfg=as_json(pick(MCFG, "examples")),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/markov/figS2.log",
    shell:
        step("netrepro.papers.markov:figure_curves")


MARKOV_FIGURES = [f"figures/markov/{f}.png" for f in ("fig2", "fig3", "fig4", "fig5", "fig6", "figS1", "figS2")]
MARKOV_TABLES = [
    "results/markov/critical_curves.csv",
    "results/markov/lmi_benchmark.csv",
    "results/markov/lmi_checks.csv",
    "results/markov/iid_line.csv",
    "results/markov/exact_moments.csv",
    "results/markov/stability_map.csv",
    "results/markov/sample_paths.csv",
    "results/markov/estimator_check.csv",
]


rule markov_notebook:
    input:
        notebook="workflow/notebooks/markov.ipynb",
        code=code("netrepro.reportgen"),
        figures=MARKOV_FIGURES,
        tables=MARKOV_TABLES,
        claims="results/claims/markov.csv",
        errata="results/errata/markov.csv",
        reconstructions="results/reconstructions/markov.csv",
    output:
        html="report/markov.html",
    conda:
        CONDA_ENV
    log:
        "logs/markov/notebook.log",
    shell:
        notebook("markov")


if enabled("markov"):
    PAPER_OUTPUTS["markov"] = dict(
        figures=MARKOV_FIGURES,
        tables=MARKOV_TABLES,
        claims="results/claims/markov.csv",
        errata="results/errata/markov.csv",
        reconstructions="results/reconstructions/markov.csv",
        notebook="report/markov.html",
    )


# light steps run in the main Snakemake process, never as cluster jobs
localrules:
    markov_reconstructions,
    markov_claims,
    markov_fig2,
    markov_fig3,
    markov_fig4,
    markov_fig5,
    markov_fig6,
    markov_figS1,
    markov_figS2,
    markov_notebook,
