# Paper `onebit` (002): Zhang, Stein, Nossek, asymptotic performance analysis for 1-bit Bayesian smoothing.
# Compute steps -> tables under results/onebit/, one rule per figure, claims, errata, reconstructions, notebook.

OCFG = config.get("onebit", {})
ONEBIT_CODE = "papers/onebit.py"


rule onebit_efq:
    input:
        code=src(ONEBIT_CODE),
    output:
        table="results/onebit/efq.csv",
    params:
        cfg=as_json(OCFG),
        io=io_json,
    log:
        "logs/onebit/efq.log",
    shell:
        step("netrepro.papers.onebit:efq_step")


rule onebit_ratios:
    input:
        code=src(ONEBIT_CODE),
    output:
        table="results/onebit/ratios.csv",
    params:
        cfg=as_json(OCFG),
        io=io_json,
    log:
        "logs/onebit/ratios.log",
    shell:
        step("netrepro.papers.onebit:ratios_step")


rule onebit_lag:
    input:
        code=src(ONEBIT_CODE),
    output:
        table="results/onebit/lag.csv",
    params:
        cfg=as_json(OCFG),
        io=io_json,
    log:
        "logs/onebit/lag.log",
    shell:
        step("netrepro.papers.onebit:lag_step")


rule onebit_convergence:
    input:
        code=src(ONEBIT_CODE),
    output:
        table="results/onebit/convergence.csv",
        transient="results/onebit/transient.csv",
    params:
        cfg=as_json(OCFG),
        io=io_json,
    log:
        "logs/onebit/convergence.log",
    threads: 1
    resources:
        mem_mb=2000,
        runtime=10,
    shell:
        step("netrepro.papers.onebit:convergence_step")


rule onebit_estimator:
    input:
        code=src(ONEBIT_CODE, "engines/montecarlo.py"),
    output:
        table="results/onebit/estimator_mse.csv",
    params:
        cfg=as_json(OCFG),
        io=io_json,
    log:
        "logs/onebit/estimator.log",
    threads: 1
    resources:
        mem_mb=2000,
        runtime=10,
    shell:
        step("netrepro.papers.onebit:estimator_step")


rule onebit_vector_check:
    input:
        code=src(ONEBIT_CODE),
    output:
        table="results/onebit/vector_check.csv",
    params:
        cfg=as_json(OCFG),
        io=io_json,
    log:
        "logs/onebit/vector_check.log",
    shell:
        step("netrepro.papers.onebit:vector_check_step")


rule onebit_errata:
    input:
        code=src(ONEBIT_CODE, "claims.py"),
    output:
        table="results/errata/onebit.csv",
    params:
        cfg=as_json(OCFG),
        io=io_json,
    log:
        "logs/onebit/errata.log",
    shell:
        step("netrepro.papers.onebit:errata_step")


rule onebit_reconstructions:
    input:
        code=src(ONEBIT_CODE, "claims.py"),
    output:
        table="results/reconstructions/onebit.csv",
    params:
        cfg=as_json(OCFG),
        io=io_json,
    log:
        "logs/onebit/reconstructions.log",
    shell:
        step("netrepro.papers.onebit:reconstructions_step")


rule onebit_claims:
    input:
        code=src(ONEBIT_CODE, "claims.py"),
        ratios="results/onebit/ratios.csv",
        lag="results/onebit/lag.csv",
        efq="results/onebit/efq.csv",
        estimator="results/onebit/estimator_mse.csv",
    output:
        table="results/claims/onebit.csv",
    params:
        cfg=as_json(OCFG),
        io=io_json,
    log:
        "logs/onebit/claims.log",
    shell:
        step("netrepro.papers.onebit:claims_step")


rule onebit_fig1:
    input:
        code=src(ONEBIT_CODE, "plotting.py"),
        ratios="results/onebit/ratios.csv",
    output:
        figure=report("figures/onebit/fig1.png", caption="../report/onebit/fig1.rst", category="onebit"),
    params:
        cfg=as_json({"fig1_one_minus_alpha": OCFG.get("fig1_one_minus_alpha")}),
        io=io_json,
    log:
        "logs/onebit/fig1.log",
    shell:
        step("netrepro.papers.onebit:figure_rho_sl")


rule onebit_fig2:
    input:
        code=src(ONEBIT_CODE, "plotting.py"),
        ratios="results/onebit/ratios.csv",
    output:
        figure=report("figures/onebit/fig2.png", caption="../report/onebit/fig2.rst", category="onebit"),
    params:
        cfg=as_json({}),
        io=io_json,
    log:
        "logs/onebit/fig2.log",
    shell:
        step("netrepro.papers.onebit:figure_rho_s_f")


rule onebit_figS1:
    input:
        code=src(ONEBIT_CODE, "plotting.py"),
        estimator="results/onebit/estimator_mse.csv",
    output:
        figure=report("figures/onebit/figS1.png", caption="../report/onebit/figS1.rst", category="onebit"),
    params:
        cfg=as_json({}),
        io=io_json,
    log:
        "logs/onebit/figS1.log",
    shell:
        step("netrepro.papers.onebit:figure_estimator")


rule onebit_figS2:
    input:
        code=src(ONEBIT_CODE, "plotting.py"),
        transient="results/onebit/transient.csv",
    output:
        figure=report("figures/onebit/figS2.png", caption="../report/onebit/figS2.rst", category="onebit"),
    params:
        cfg=as_json({}),
        io=io_json,
    log:
        "logs/onebit/figS2.log",
    shell:
        step("netrepro.papers.onebit:figure_convergence")


rule onebit_figS3:
    input:
        code=src(ONEBIT_CODE, "plotting.py"),
        lag="results/onebit/lag.csv",
    output:
        figure=report("figures/onebit/figS3.png", caption="../report/onebit/figS3.rst", category="onebit"),
    params:
        cfg=as_json({}),
        io=io_json,
    log:
        "logs/onebit/figS3.log",
    shell:
        step("netrepro.papers.onebit:figure_lag")


ONEBIT_FIGURES = [f"figures/onebit/{f}.png" for f in ("fig1", "fig2", "figS1", "figS2", "figS3")]
ONEBIT_TABLES = [
    "results/onebit/ratios.csv",
    "results/onebit/lag.csv",
    "results/onebit/efq.csv",
    "results/onebit/convergence.csv",
    "results/onebit/transient.csv",
    "results/onebit/estimator_mse.csv",
    "results/onebit/vector_check.csv",
]


rule onebit_notebook:
    input:
        notebook="workflow/notebooks/onebit.ipynb",
        code=src("reportgen.py"),
        figures=ONEBIT_FIGURES,
        tables=ONEBIT_TABLES,
        claims="results/claims/onebit.csv",
        errata="results/errata/onebit.csv",
        reconstructions="results/reconstructions/onebit.csv",
    output:
        html="report/onebit.html",
    log:
        "logs/onebit/notebook.log",
    shell:
        notebook("onebit")


if enabled("onebit"):
    PAPER_OUTPUTS["onebit"] = dict(
        figures=ONEBIT_FIGURES,
        tables=ONEBIT_TABLES,
        claims="results/claims/onebit.csv",
        errata="results/errata/onebit.csv",
        reconstructions="results/reconstructions/onebit.csv",
        notebook="report/onebit.html",
    )
