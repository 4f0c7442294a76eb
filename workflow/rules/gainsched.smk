# Paper `gainsched` (001): Wei, Wang, Shen, Li, probability-dependent gain-scheduled filtering.
# Designs (Theorem 3 and beyond) -> independent stability checks, Monte Carlo of Algorithm 1,
# sigma^2 sensitivity, Remark 5 timing -> claims, errata, reconstructions, one rule per figure, notebook.

GCFG = config.get("gainsched", {})
GS_MATH = ("papers/gainsched.py", "papers/gainsched_model.py", "papers/gainsched_design.py")


rule gainsched_design:
    input:
        code=code("netrepro.papers.gainsched:design_step"),
    output:
        gains="results/gainsched/gains.csv",
        designs="results/gainsched/designs.csv",
        solutions="results/gainsched/lmi_solutions.csv",
    params:
        cfg=as_json(pick(GCFG, "system", "paper_gains", "lmi", "performance", "tuning", "simulation")),
        io=io_json,
    conda:
        CONDA_ENV
    threads: 1
    resources:
        mem_mb=2000,
        runtime=5,
    log:
        "logs/gainsched/design.log",
    shell:
        step("netrepro.papers.gainsched:design_step")


rule gainsched_stability:
    input:
        code=code("netrepro.papers.gainsched:stability_step"),
        gains="results/gainsched/gains.csv",
        solutions="results/gainsched/lmi_solutions.csv",
    output:
        stability="results/gainsched/stability.csv",
        theorem1="results/gainsched/theorem1.csv",
    params:
        cfg=as_json(pick(GCFG, "system", "lmi", "stability", "simulation")),
        io=io_json,
    conda:
        CONDA_ENV
    threads: 1
    resources:
        mem_mb=2000,
        runtime=5,
    log:
        "logs/gainsched/stability.log",
    shell:
        step("netrepro.papers.gainsched:stability_step")


rule gainsched_simulation:
    input:
        code=code("netrepro.papers.gainsched:simulation_step"),
        gains="results/gainsched/gains.csv",
    output:
        errors="results/gainsched/errors.csv",
        error_summary="results/gainsched/error_summary.csv",
        paths="results/gainsched/sample_paths.csv",
    params:
        cfg=as_json(pick(GCFG, "system", "simulation", "performance")),
        io=io_json,
    conda:
        CONDA_ENV
    threads: 1
    resources:
        mem_mb=2000,
        runtime=2,
    log:
        "logs/gainsched/simulation.log",
    shell:
        step("netrepro.papers.gainsched:simulation_step")


rule gainsched_sensitivity:
    input:
        code=code("netrepro.papers.gainsched:sensitivity_step"),
    output:
        table="results/gainsched/sensitivity.csv",
    params:
        cfg=as_json(pick(GCFG, "system", "lmi", "sensitivity")),
        io=io_json,
    conda:
        CONDA_ENV
    threads: 1
    resources:
        mem_mb=2000,
        runtime=5,
    log:
        "logs/gainsched/sensitivity.log",
    shell:
        step("netrepro.papers.gainsched:sensitivity_step")


rule gainsched_timing:
    input:
        code=code("netrepro.papers.gainsched:timing_step"),
    output:
        table="results/gainsched/timing.csv",
    params:
        cfg=as_json(pick(GCFG, "system", "lmi", "timing")),
        io=io_json,
    conda:
        CONDA_ENV
    threads: 1
    resources:
        mem_mb=4000,
        runtime=10,
    log:
        "logs/gainsched/timing.log",
    shell:
        step("netrepro.papers.gainsched:timing_step")


rule gainsched_errata:
    input:
        code=code("netrepro.papers.gainsched:errata_step"),
        gains="results/gainsched/gains.csv",
        summary="results/gainsched/error_summary.csv",
        theorem1="results/gainsched/theorem1.csv",
        solutions="results/gainsched/lmi_solutions.csv",
    output:
        table="results/errata/gainsched.csv",
    params:
        cfg=as_json(pick(GCFG, "system", "lmi", "simulation")),
        io=io_json,
    conda:
        CONDA_ENV
    threads: 1
    resources:
        mem_mb=2000,
        runtime=2,
    log:
        "logs/gainsched/errata.log",
    shell:
        step("netrepro.papers.gainsched:errata_step")


rule gainsched_reconstructions:
    input:
        code=code("netrepro.papers.gainsched:reconstructions_step"),
        sensitivity="results/gainsched/sensitivity.csv",
        summary="results/gainsched/error_summary.csv",
    output:
        table="results/reconstructions/gainsched.csv",
    params:
        cfg=as_json(pick(GCFG, "system", "lmi", "simulation")),
        io=io_json,
    conda:
        CONDA_ENV
    threads: 1
    resources:
        mem_mb=500,
        runtime=1,
    log:
        "logs/gainsched/reconstructions.log",
    shell:
        step("netrepro.papers.gainsched:reconstructions_step")


rule gainsched_claims:
    input:
        code=code("netrepro.papers.gainsched:claims_step"),
        gains="results/gainsched/gains.csv",
        designs="results/gainsched/designs.csv",
        theorem1="results/gainsched/theorem1.csv",
        errors="results/gainsched/errors.csv",
        stability="results/gainsched/stability.csv",
        sensitivity="results/gainsched/sensitivity.csv",
        timing="results/gainsched/timing.csv",
    output:
        table="results/claims/gainsched.csv",
    params:
        cfg=as_json(pick(GCFG, "system", "sensitivity")),
        io=io_json,
    conda:
        CONDA_ENV
    threads: 1
    resources:
        mem_mb=500,
        runtime=1,
    log:
        "logs/gainsched/claims.log",
    shell:
        step("netrepro.papers.gainsched:claims_step")


rule gainsched_fig1:
    input:
        code=code("netrepro.papers.gainsched:figure_errors"),
        errors="results/gainsched/errors.csv",
        paths="results/gainsched/sample_paths.csv",
    output:
        figure=report("figures/gainsched/fig1.png", caption="../report/gainsched/fig1.rst", category="gainsched"),
    params:
        cfg=as_json({"component": 1, "designs": GCFG.get("simulation", {}).get("fig_designs"),
                     "band": GCFG.get("simulation", {}).get("band")}),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/gainsched/fig1.log",
    shell:
        step("netrepro.papers.gainsched:figure_errors")


rule gainsched_fig2:
    input:
        code=code("netrepro.papers.gainsched:figure_errors"),
        errors="results/gainsched/errors.csv",
        paths="results/gainsched/sample_paths.csv",
    output:
        figure=report("figures/gainsched/fig2.png", caption="../report/gainsched/fig2.rst", category="gainsched"),
    params:
        cfg=as_json({"component": 2, "designs": GCFG.get("simulation", {}).get("fig_designs"),
                     "band": GCFG.get("simulation", {}).get("band")}),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/gainsched/fig2.log",
    shell:
        step("netrepro.papers.gainsched:figure_errors")


rule gainsched_figS1:
    input:
        code=code("netrepro.papers.gainsched:figure_mse"),
        errors="results/gainsched/errors.csv",
        summary="results/gainsched/error_summary.csv",
    output:
        figure=report("figures/gainsched/figS1.png", caption="../report/gainsched/figS1.rst", category="gainsched"),
    params:
        cfg=as_json({}),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/gainsched/figS1.log",
    shell:
        step("netrepro.papers.gainsched:figure_mse")


rule gainsched_figS2:
    input:
        code=code("netrepro.papers.gainsched:figure_sensitivity"),
        sensitivity="results/gainsched/sensitivity.csv",
    output:
        figure=report("figures/gainsched/figS2.png", caption="../report/gainsched/figS2.rst", category="gainsched"),
    params:
        cfg=as_json({"sigma2": GCFG.get("system", {}).get("sigma2")}),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/gainsched/figS2.log",
    shell:
        step("netrepro.papers.gainsched:figure_sensitivity")


GAINSCHED_FIGURES = [f"figures/gainsched/{f}.png" for f in ("fig1", "fig2", "figS1", "figS2")]
GAINSCHED_TABLES = [
    "results/gainsched/gains.csv",
    "results/gainsched/designs.csv",
    "results/gainsched/lmi_solutions.csv",
    "results/gainsched/stability.csv",
    "results/gainsched/theorem1.csv",
    "results/gainsched/errors.csv",
    "results/gainsched/error_summary.csv",
    "results/gainsched/sample_paths.csv",
    "results/gainsched/sensitivity.csv",
    "results/gainsched/timing.csv",
]


rule gainsched_notebook:
    input:
        notebook="workflow/notebooks/gainsched.ipynb",
        code=code("netrepro.reportgen"),
        figures=GAINSCHED_FIGURES,
        tables=GAINSCHED_TABLES,
        claims="results/claims/gainsched.csv",
        errata="results/errata/gainsched.csv",
        reconstructions="results/reconstructions/gainsched.csv",
    output:
        html="report/gainsched.html",
    conda:
        CONDA_ENV
    log:
        "logs/gainsched/notebook.log",
    shell:
        notebook("gainsched")


if enabled("gainsched"):
    PAPER_OUTPUTS["gainsched"] = dict(
        figures=GAINSCHED_FIGURES,
        tables=GAINSCHED_TABLES,
        claims="results/claims/gainsched.csv",
        errata="results/errata/gainsched.csv",
        reconstructions="results/reconstructions/gainsched.csv",
        notebook="report/gainsched.html",
    )


# light steps run in the main Snakemake process, never as cluster jobs
localrules:
    gainsched_reconstructions,
    gainsched_claims,
    gainsched_fig1,
    gainsched_fig2,
    gainsched_figS1,
    gainsched_figS2,
    gainsched_notebook,
