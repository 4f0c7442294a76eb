# Paper `hinf` (003): Nelson & Freeman, Decentralized H-infinity filtering in a multi-agent system.
# Compute steps -> tables under results/hinf/, one rule per figure, claims, errata, reconstructions, notebook.

HCFG = config.get("hinf", {})
HINF_SCENARIOS = ["fig2", "fig3", "static_fixed", "static_mobile", "evasive_hinf", "evasive_kalman"]
HINF_PIECES = ["errors", "single", "trajectories", "summary", "per_run"]
HINF_CODE = code("netrepro.papers.hinf")
HINF_PLOT = code("netrepro.papers.hinf")
HINF_SIM_PIECES = {f"{kind}_{s}": f"results/hinf/sim/{s}_{kind}.csv" for kind in HINF_PIECES for s in HINF_SCENARIOS}


rule hinf_noise_model:
    input:
        code=HINF_CODE,
    output:
        table="results/hinf/noise_model.csv",
        fit="results/hinf/noise_fit.csv",
    params:
        cfg=as_json(HCFG),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/hinf/noise_model.log",
    shell:
        step("netrepro.papers.hinf:noise_model_step")


rule hinf_consensus_check:
    input:
        code=HINF_CODE,
    output:
        table="results/hinf/consensus_check.csv",
    params:
        cfg=as_json(HCFG),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/hinf/consensus_check.log",
    shell:
        step("netrepro.papers.hinf:consensus_check_step")


rule hinf_attenuation:
    input:
        code=HINF_CODE,
    output:
        table="results/hinf/attenuation.csv",
        checks="results/hinf/filter_checks.csv",
    params:
        cfg=as_json(HCFG),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/hinf/attenuation.log",
    shell:
        step("netrepro.papers.hinf:attenuation_step")


rule hinf_simulate:
    input:
        code=HINF_CODE,
    output:
        errors="results/hinf/sim/{scenario}_errors.csv",
        single="results/hinf/sim/{scenario}_single.csv",
        trajectories="results/hinf/sim/{scenario}_trajectories.csv",
        summary="results/hinf/sim/{scenario}_summary.csv",
        per_run="results/hinf/sim/{scenario}_per_run.csv",
    params:
        cfg=lambda wildcards: as_json({"scenario": wildcards.scenario, "cfg": HCFG}),
        io=io_json,
    wildcard_constraints:
        scenario="|".join(HINF_SCENARIOS),
    conda:
        CONDA_ENV
    log:
        "logs/hinf/simulate_{scenario}.log",
    shell:
        step("netrepro.papers.hinf:simulate_step")


rule hinf_tables:
    input:
        **HINF_SIM_PIECES,
        code=HINF_CODE,
    output:
        errors="results/hinf/errors.csv",
        single="results/hinf/errors_single.csv",
        trajectories="results/hinf/trajectories.csv",
        summary="results/hinf/summary.csv",
        paired="results/hinf/paired.csv",
    params:
        cfg=as_json({}),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/hinf/tables.log",
    shell:
        step("netrepro.papers.hinf:tables_step")


rule hinf_sensitivity:
    input:
        code=HINF_CODE,
    output:
        table="results/hinf/sensitivity.csv",
    params:
        cfg=as_json(HCFG),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/hinf/sensitivity.log",
    shell:
        step("netrepro.papers.hinf:sensitivity_step")


rule hinf_sensitivity_evasive:
    input:
        code=HINF_CODE,
    output:
        table="results/hinf/sensitivity_evasive.csv",
    params:
        cfg=as_json(HCFG),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/hinf/sensitivity_evasive.log",
    shell:
        step("netrepro.papers.hinf:sensitivity_evasive_step")


rule hinf_errata:
    input:
        code=code("netrepro.papers.hinf:errata_step"),
    output:
        table="results/errata/hinf.csv",
    params:
        cfg=as_json(HCFG),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/hinf/errata.log",
    shell:
        step("netrepro.papers.hinf:errata_step")


rule hinf_reconstructions:
    input:
        code=code("netrepro.papers.hinf:reconstructions_step"),
        sensitivity="results/hinf/sensitivity.csv",
        sensitivity_evasive="results/hinf/sensitivity_evasive.csv",
    output:
        table="results/reconstructions/hinf.csv",
    params:
        cfg=as_json(HCFG),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/hinf/reconstructions.log",
    shell:
        step("netrepro.papers.hinf:reconstructions_step")


rule hinf_claims:
    input:
        code=code("netrepro.papers.hinf:claims_step"),
        noise_fit="results/hinf/noise_fit.csv",
        consensus="results/hinf/consensus_check.csv",
        attenuation="results/hinf/attenuation.csv",
        checks="results/hinf/filter_checks.csv",
        summary="results/hinf/summary.csv",
        paired="results/hinf/paired.csv",
    output:
        table="results/claims/hinf.csv",
    params:
        cfg=as_json(HCFG),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/hinf/claims.log",
    shell:
        step("netrepro.papers.hinf:claims_step")


rule hinf_fig1:
    input:
        code=HINF_PLOT,
        table="results/hinf/noise_model.csv",
    output:
        figure=report("figures/hinf/fig1.png", caption="../report/hinf/fig1.rst", category="hinf"),
    params:
        cfg=as_json({"scale": 3.0}),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/hinf/fig1.log",
    shell:
        step("netrepro.papers.hinf:figure_noise")


rule hinf_fig2:
    input:
        code=HINF_PLOT,
        errors="results/hinf/errors.csv",
        single="results/hinf/errors_single.csv",
    output:
        figure=report("figures/hinf/fig2.png", caption="../report/hinf/fig2.rst", category="hinf"),
    params:
        cfg=as_json({"series": [["fig2", "local", "local"], ["fig2", "decentralized", "decentralized"]],
                     "title": "Fig 2: local vs decentralized H-inf filter, W = 0.01 I"}),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/hinf/fig2.log",
    shell:
        step("netrepro.papers.hinf:figure_errors")


rule hinf_fig3:
    input:
        code=HINF_PLOT,
        errors="results/hinf/errors.csv",
        single="results/hinf/errors_single.csv",
    output:
        figure=report("figures/hinf/fig3.png", caption="../report/hinf/fig3.rst", category="hinf"),
    params:
        cfg=as_json({"series": [["fig3", "local", "local"], ["fig3", "decentralized", "decentralized"]],
                     "title": "Fig 3: local vs decentralized H-inf filter, W = 0.001 I"}),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/hinf/fig3.log",
    shell:
        step("netrepro.papers.hinf:figure_errors")


rule hinf_fig4:
    input:
        code=HINF_PLOT,
        errors="results/hinf/errors.csv",
        single="results/hinf/errors_single.csv",
    output:
        figure=report("figures/hinf/fig4.png", caption="../report/hinf/fig4.rst", category="hinf"),
    params:
        cfg=as_json({"series": [["static_fixed", "local", "stationary, local"],
                                ["static_mobile", "decentralized", "mobile, decentralized"]],
                     "title": "Fig 4: stationary target", "log": True}),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/hinf/fig4.log",
    shell:
        step("netrepro.papers.hinf:figure_errors")


rule hinf_fig5:
    input:
        code=HINF_PLOT,
        errors="results/hinf/errors.csv",
        single="results/hinf/errors_single.csv",
    output:
        figure=report("figures/hinf/fig5.png", caption="../report/hinf/fig5.rst", category="hinf"),
    params:
        cfg=as_json({"series": [["static_fixed", "decentralized", "stationary, decentralized"],
                                ["static_mobile", "decentralized", "mobile, decentralized"]],
                     "title": "Fig 5: stationary target", "log": True}),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/hinf/fig5.log",
    shell:
        step("netrepro.papers.hinf:figure_errors")


rule hinf_fig6:
    input:
        code=HINF_PLOT,
        trajectories="results/hinf/trajectories.csv",
    output:
        figure=report("figures/hinf/fig6.png", caption="../report/hinf/fig6.rst", category="hinf"),
    params:
        cfg=as_json({"scenario": "evasive_hinf", "run": 0, "title": "Fig 6: four agents and an evasive target"}),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/hinf/fig6.log",
    shell:
        step("netrepro.papers.hinf:figure_trajectories")


rule hinf_figS1:
    input:
        code=HINF_PLOT,
        summary="results/hinf/summary.csv",
    output:
        figure=report("figures/hinf/figS1.png", caption="../report/hinf/figS1.rst", category="hinf"),
    params:
        cfg=as_json({}),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/hinf/figS1.log",
    shell:
        step("netrepro.papers.hinf:figure_hinf_vs_kalman")


rule hinf_figS2:
    input:
        code=HINF_PLOT,
        table="results/hinf/sensitivity.csv",
        evasive="results/hinf/sensitivity_evasive.csv",
    output:
        figure=report("figures/hinf/figS2.png", caption="../report/hinf/figS2.rst", category="hinf"),
    params:
        cfg=as_json({}),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/hinf/figS2.log",
    shell:
        step("netrepro.papers.hinf:figure_sensitivity")


rule hinf_figS3:
    input:
        code=HINF_PLOT,
        table="results/hinf/consensus_check.csv",
    output:
        figure=report("figures/hinf/figS3.png", caption="../report/hinf/figS3.rst", category="hinf"),
    params:
        cfg=as_json({}),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/hinf/figS3.log",
    shell:
        step("netrepro.papers.hinf:figure_consensus")


HINF_FIGURES = [f"figures/hinf/{f}.png" for f in ("fig1", "fig2", "fig3", "fig4", "fig5", "fig6", "figS1", "figS2", "figS3")]
HINF_TABLES = [
    "results/hinf/errors.csv",
    "results/hinf/errors_single.csv",
    "results/hinf/trajectories.csv",
    "results/hinf/summary.csv",
    "results/hinf/paired.csv",
    "results/hinf/consensus_check.csv",
    "results/hinf/noise_model.csv",
    "results/hinf/noise_fit.csv",
    "results/hinf/attenuation.csv",
    "results/hinf/filter_checks.csv",
    "results/hinf/sensitivity.csv",
    "results/hinf/sensitivity_evasive.csv",
]


rule hinf_notebook:
    input:
        notebook="workflow/notebooks/hinf.ipynb",
        code=code("netrepro.reportgen"),
        figures=HINF_FIGURES,
        tables=HINF_TABLES,
        claims="results/claims/hinf.csv",
        errata="results/errata/hinf.csv",
        reconstructions="results/reconstructions/hinf.csv",
    output:
        html="report/hinf.html",
    conda:
        CONDA_ENV
    log:
        "logs/hinf/notebook.log",
    shell:
        notebook("hinf")


if enabled("hinf"):
    PAPER_OUTPUTS["hinf"] = dict(
        figures=HINF_FIGURES,
        tables=HINF_TABLES,
        claims="results/claims/hinf.csv",
        errata="results/errata/hinf.csv",
        reconstructions="results/reconstructions/hinf.csv",
        notebook="report/hinf.html",
    )


# light steps run in the main Snakemake process, never as cluster jobs
localrules:
    hinf_tables,
    hinf_reconstructions,
    hinf_claims,
    hinf_fig1,
    hinf_fig2,
    hinf_fig3,
    hinf_fig4,
    hinf_fig5,
    hinf_fig6,
    hinf_figS1,
    hinf_figS2,
    hinf_figS3,
    hinf_notebook,
