# Paper `onebit` (002): Zhang, Stein, Nossek, asymptotic performance analysis for 1-bit Bayesian smoothing.
# Compute steps -> tables under results/onebit/, one rule per figure, claims, errata, reconstructions, notebook.

OCFG = config.get("onebit", {})
ONEBIT_CODE = "papers/onebit.py"
# config keys each step reads (only these trigger its rerun)
ONEBIT_KEYS = {
    "efq": ("quadrature", "efq_grid_db"),
    "ratios": ("snr_grid_db", "quadrature", "one_minus_alpha", "sigma_eta", "snr_definition"),
    "lag": ("snr_grid_db", "lag_tol_db", "lag_iterate_max", "one_minus_alpha", "sigma_eta", "snr_definition"),
    "convergence": ("convergence", "one_minus_alpha", "sigma_eta", "sigma_theta0", "mu_theta0", "snr_definition"),
    "estimator": ("estimator", "sigma_eta", "snr_definition"),
    "vector_check": ("vector_check",),
    "errata": ("vector_check", "sigma_theta0"),
    "reconstructions": (
        "snr_definition",
        "fig1_one_minus_alpha",
        "reference_snr_db",
        "sigma_eta",
        "estimator",
        "snr_grid_db",
        "lag_tol_db",
        "mu_theta0",
    ),
    "claims": ("fig1_one_minus_alpha",),
}
ONEBIT_SHARDS = OCFG.get("estimator", {}).get("n_shards", 2)


rule onebit_efq:
    input:
        code=code("netrepro.papers.onebit:efq_step"),
    output:
        table="results/onebit/efq.csv",
    params:
        cfg=as_json(pick(OCFG, *ONEBIT_KEYS["efq"])),
        io=io_json,
    threads: 1
    resources:
        mem_mb=500,
        runtime=5,
    conda:
        CONDA_ENV
    log:
        "logs/onebit/efq.log",
    shell:
        step("netrepro.papers.onebit:efq_step")


rule onebit_ratios:
    input:
        code=code("netrepro.papers.onebit:ratios_step"),
    output:
        table="results/onebit/ratios.csv",
    params:
        cfg=as_json(pick(OCFG, *ONEBIT_KEYS["ratios"])),
        io=io_json,
    threads: 1
    resources:
        mem_mb=500,
        runtime=5,
    conda:
        CONDA_ENV
    log:
        "logs/onebit/ratios.log",
    shell:
        step("netrepro.papers.onebit:ratios_step")


rule onebit_lag:
    input:
        code=code("netrepro.papers.onebit:lag_step"),
    output:
        table="results/onebit/lag.csv",
    params:
        cfg=as_json(pick(OCFG, *ONEBIT_KEYS["lag"])),
        io=io_json,
    threads: 1
    resources:
        mem_mb=500,
        runtime=5,
    conda:
        CONDA_ENV
    log:
        "logs/onebit/lag.log",
    shell:
        step("netrepro.papers.onebit:lag_step")


rule onebit_convergence:
    input:
        code=code("netrepro.papers.onebit:convergence_step"),
    output:
        table="results/onebit/convergence.csv",
        transient="results/onebit/transient.csv",
    params:
        cfg=as_json(pick(OCFG, *ONEBIT_KEYS["convergence"])),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/onebit/convergence.log",
    threads: 1
    resources:
        mem_mb=2000,
        runtime=10,
    shell:
        step("netrepro.papers.onebit:convergence_step")


rule onebit_estimator_shard:
    input:
        code=code("netrepro.papers.onebit:estimator_shard_step"),
    output:
        sums="results/onebit/shards/estimator_{shard}.npz",
    wildcard_constraints:
        shard=r"\d+",
    params:
        cfg=lambda w: as_json(
            {**pick(OCFG, *ONEBIT_KEYS["estimator"]), "shard": int(w.shard), "n_shards": ONEBIT_SHARDS}
        ),
        io=io_json,
    threads: 1
    resources:
        mem_mb=1500,
        runtime=10,
    conda:
        CONDA_ENV
    log:
        "logs/onebit/estimator_{shard}.log",
    shell:
        step("netrepro.papers.onebit:estimator_shard_step")


rule onebit_estimator:
    input:
        code=code("netrepro.papers.onebit:estimator_step"),
        shards=expand("results/onebit/shards/estimator_{shard}.npz", shard=range(ONEBIT_SHARDS)),
    output:
        table="results/onebit/estimator_mse.csv",
    params:
        cfg=as_json(pick(OCFG, *ONEBIT_KEYS["estimator"])),
        io=io_json,
    threads: 1
    resources:
        mem_mb=500,
        runtime=5,
    conda:
        CONDA_ENV
    log:
        "logs/onebit/estimator.log",
    shell:
        step("netrepro.papers.onebit:estimator_step")


rule onebit_vector_check:
    input:
        code=code("netrepro.papers.onebit:vector_check_step"),
    output:
        table="results/onebit/vector_check.csv",
    params:
        cfg=as_json(pick(OCFG, *ONEBIT_KEYS["vector_check"])),
        io=io_json,
    threads: 1
    resources:
        mem_mb=500,
        runtime=5,
    conda:
        CONDA_ENV
    log:
        "logs/onebit/vector_check.log",
    shell:
        step("netrepro.papers.onebit:vector_check_step")


rule onebit_errata:
    input:
        code=code("netrepro.papers.onebit:errata_step"),
    output:
        table="results/errata/onebit.csv",
    params:
        cfg=as_json(pick(OCFG, *ONEBIT_KEYS["errata"])),
        io=io_json,
    threads: 1
    resources:
        mem_mb=500,
        runtime=5,
    conda:
        CONDA_ENV
    log:
        "logs/onebit/errata.log",
    shell:
        step("netrepro.papers.onebit:errata_step")


rule onebit_reconstructions:
    input:
        code=code("netrepro.papers.onebit:reconstructions_step"),
    output:
        table="results/reconstructions/onebit.csv",
    params:
        cfg=as_json(pick(OCFG, *ONEBIT_KEYS["reconstructions"])),
        io=io_json,
    threads: 1
    resources:
        mem_mb=500,
        runtime=5,
    conda:
        CONDA_ENV
    log:
        "logs/onebit/reconstructions.log",
    shell:
        step("netrepro.papers.onebit:reconstructions_step")


rule onebit_claims:
    input:
        code=code("netrepro.papers.onebit:claims_step"),
        ratios="results/onebit/ratios.csv",
        lag="results/onebit/lag.csv",
        efq="results/onebit/efq.csv",
        estimator="results/onebit/estimator_mse.csv",
    output:
        table="results/claims/onebit.csv",
    params:
        cfg=as_json(pick(OCFG, *ONEBIT_KEYS["claims"])),
        io=io_json,
    threads: 1
    resources:
        mem_mb=500,
        runtime=5,
    conda:
        CONDA_ENV
    log:
        "logs/onebit/claims.log",
    shell:
        step("netrepro.papers.onebit:claims_step")


rule onebit_fig1:
    input:
        code=code("netrepro.papers.onebit:figure_rho_sl"),
        ratios="results/onebit/ratios.csv",
    output:
        figure=report("figures/onebit/fig1.png", caption="../report/onebit/fig1.rst", category="onebit"),
    params:
        cfg=as_json(pick(OCFG, "fig1_one_minus_alpha")),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/onebit/fig1.log",
    shell:
        step("netrepro.papers.onebit:figure_rho_sl")


rule onebit_fig2:
    input:
        code=code("netrepro.papers.onebit:figure_rho_s_f"),
        ratios="results/onebit/ratios.csv",
    output:
        figure=report("figures/onebit/fig2.png", caption="../report/onebit/fig2.rst", category="onebit"),
    params:
        cfg=as_json({}),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/onebit/fig2.log",
    shell:
        step("netrepro.papers.onebit:figure_rho_s_f")


rule onebit_figS1:
    input:
        code=code("netrepro.papers.onebit:figure_estimator"),
        estimator="results/onebit/estimator_mse.csv",
    output:
        figure=report("figures/onebit/figS1.png", caption="../report/onebit/figS1.rst", category="onebit"),
    params:
        cfg=as_json({}),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/onebit/figS1.log",
    shell:
        step("netrepro.papers.onebit:figure_estimator")


rule onebit_figS2:
    input:
        code=code("netrepro.papers.onebit:figure_convergence"),
        transient="results/onebit/transient.csv",
    output:
        figure=report("figures/onebit/figS2.png", caption="../report/onebit/figS2.rst", category="onebit"),
    params:
        cfg=as_json({}),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/onebit/figS2.log",
    shell:
        step("netrepro.papers.onebit:figure_convergence")


rule onebit_figS3:
    input:
        code=code("netrepro.papers.onebit:figure_lag"),
        lag="results/onebit/lag.csv",
    output:
        figure=report("figures/onebit/figS3.png", caption="../report/onebit/figS3.rst", category="onebit"),
    params:
        cfg=as_json({}),
        io=io_json,
    conda:
        CONDA_ENV
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
        code=code("netrepro.reportgen"),
        figures=ONEBIT_FIGURES,
        tables=ONEBIT_TABLES,
        claims="results/claims/onebit.csv",
        errata="results/errata/onebit.csv",
        reconstructions="results/reconstructions/onebit.csv",
    output:
        html="report/onebit.html",
    conda:
        CONDA_ENV
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


# light steps run in the main Snakemake process, never as cluster jobs
localrules:
    onebit_estimator,
    onebit_reconstructions,
    onebit_claims,
    onebit_fig1,
    onebit_fig2,
    onebit_figS1,
    onebit_figS2,
    onebit_figS3,
    onebit_notebook,
