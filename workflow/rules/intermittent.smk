# Paper `intermittent` (000): Teerikoski, Kalman filtering with measurement losses.
# Compute steps -> tables under results/intermittent/, one rule per figure, claims, errata, notebook.

ICFG = config.get("intermittent", {})
# keys the Monte Carlo results depend on (n_chunks and n_shards do not change them)
MC_KEYS = ("a", "R1", "R2", "Ep0", "lambda_offsets", "horizon", "n_paths", "block_size", "seed")


rule intermittent_exact_mean:
    input:
        code=code("netrepro.papers.intermittent:exact_mean_step"),
    output:
        table="results/intermittent/exact_mean.csv",
    params:
        cfg=as_json(pick(ICFG.get("scalar", {}), "a", "R1", "R2", "Ep0", "lambda_offsets", "exact_horizon")),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/intermittent/exact_mean.log",
    shell:
        step("netrepro.papers.intermittent:exact_mean_step")


rule intermittent_monte_carlo_shard:
    input:
        code=code("netrepro.papers.intermittent:monte_carlo_shard_step"),
    output:
        sums="results/intermittent/shards/monte_carlo_{shard}.npz",
    wildcard_constraints:
        shard=r"\d+",
    params:
        cfg=lambda w: as_json(
            {
                **pick(ICFG["scalar"], *MC_KEYS),
                "shard": int(w.shard),
                "n_shards": ICFG["scalar"].get("n_shards", 1),
            }
        ),
        io=io_json,
    threads: 1
    resources:
        mem_mb=3000,
        runtime=20,
    conda:
        CONDA_ENV
    log:
        "logs/intermittent/monte_carlo_{shard}.log",
    shell:
        step("netrepro.papers.intermittent:monte_carlo_shard_step")


rule intermittent_monte_carlo:
    input:
        code=code("netrepro.papers.intermittent:monte_carlo_merge_step"),
        shards=expand(
            "results/intermittent/shards/monte_carlo_{shard}.npz",
            shard=range(ICFG.get("scalar", {}).get("n_shards", 1)),
        ),
    output:
        table="results/intermittent/monte_carlo.csv",
    params:
        cfg=as_json(pick(ICFG.get("scalar", {}), *MC_KEYS)),
        io=io_json,
    threads: 1
    resources:
        mem_mb=1000,
        runtime=5,
    conda:
        CONDA_ENV
    log:
        "logs/intermittent/monte_carlo.log",
    shell:
        step("netrepro.papers.intermittent:monte_carlo_merge_step")


rule intermittent_scalar_bounds:
    input:
        code=code("netrepro.papers.intermittent:scalar_bounds_step"),
        exact="results/intermittent/exact_mean.csv",
        mc="results/intermittent/monte_carlo.csv",
    output:
        table="results/intermittent/scalar_bounds.csv",
    params:
        cfg=as_json(pick(ICFG.get("scalar", {}), "a", "R1", "R2", "Ep0", "lambda_offsets", "horizon")),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/intermittent/scalar_bounds.log",
    shell:
        step("netrepro.papers.intermittent:scalar_bounds_step")


rule intermittent_two_sensor_region_shard:
    input:
        code=code("netrepro.papers.intermittent:two_sensor_region_shard_step"),
    output:
        table="results/intermittent/shards/two_sensor_region_{shard}.csv",
    wildcard_constraints:
        shard=r"\d+",
    params:
        cfg=lambda w: as_json(
            {
                **pick(ICFG["two_sensor"], "a", "lambda1_grid", "bisection_tol"),
                "shard": int(w.shard),
                "n_shards": ICFG["two_sensor"].get("n_shards", 1),
            }
        ),
        io=io_json,
    threads: 1
    resources:
        mem_mb=1000,
        runtime=20,
    conda:
        CONDA_ENV
    log:
        "logs/intermittent/two_sensor_region_{shard}.log",
    shell:
        step("netrepro.papers.intermittent:two_sensor_region_shard_step")


rule intermittent_two_sensor_region:
    input:
        code=code("netrepro.papers.intermittent:two_sensor_region_merge_step"),
        shards=expand(
            "results/intermittent/shards/two_sensor_region_{shard}.csv",
            shard=range(ICFG.get("two_sensor", {}).get("n_shards", 1)),
        ),
    output:
        table="results/intermittent/two_sensor_region.csv",
    params:
        cfg=as_json(pick(ICFG.get("two_sensor", {}), "a", "lambda1_grid", "bisection_tol")),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/intermittent/two_sensor_region.log",
    shell:
        step("netrepro.papers.intermittent:two_sensor_region_merge_step")


rule intermittent_two_sensor_simulation:
    input:
        code=code("netrepro.papers.intermittent:two_sensor_simulation_step"),
    output:
        table="results/intermittent/two_sensor_simulation.csv",
    params:
        cfg=as_json(
            pick(ICFG.get("two_sensor", {}), "a", "R1", "sigma2", "check_lambda1", "check_offset",
                 "check_horizon", "check_paths", "block_size", "seed")
        ),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/intermittent/two_sensor_simulation.log",
    shell:
        step("netrepro.papers.intermittent:two_sensor_simulation_step")


rule intermittent_errata:
    input:
        code=code("netrepro.papers.intermittent:errata_step"),
    output:
        table="results/errata/intermittent.csv",
    params:
        cfg=as_json(
            {
                "scalar": pick(ICFG.get("scalar", {}), "a", "R1", "R2", "Ep0"),
                "two_sensor": pick(ICFG.get("two_sensor", {}), "sigma2"),
            }
        ),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/intermittent/errata.log",
    shell:
        step("netrepro.papers.intermittent:errata_step")


rule intermittent_reconstructions:
    input:
        code=code("netrepro.papers.intermittent:reconstructions_step"),
    output:
        table="results/reconstructions/intermittent.csv",
    params:
        cfg=as_json(ICFG),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/intermittent/reconstructions.log",
    shell:
        step("netrepro.papers.intermittent:reconstructions_step")


rule intermittent_claims:
    input:
        code=code("netrepro.papers.intermittent:claims_step"),
        bounds="results/intermittent/scalar_bounds.csv",
        region="results/intermittent/two_sensor_region.csv",
        simulation="results/intermittent/two_sensor_simulation.csv",
    output:
        table="results/claims/intermittent.csv",
    params:
        cfg=as_json(
            {
                "scalar": pick(ICFG.get("scalar", {}), "a", "R1", "R2", "Ep0"),
                "two_sensor": pick(ICFG.get("two_sensor", {}), "bisection_tol"),
            }
        ),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/intermittent/claims.log",
    shell:
        step("netrepro.papers.intermittent:claims_step")


rule intermittent_fig1:
    input:
        code=code("netrepro.papers.intermittent:figure_bounds"),
        bounds="results/intermittent/scalar_bounds.csv",
    output:
        figure=report("figures/intermittent/fig1.png", caption="../report/intermittent/fig1.rst", category="intermittent"),
    params:
        cfg=as_json({"which": "stable"}),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/intermittent/fig1.log",
    shell:
        step("netrepro.papers.intermittent:figure_bounds")


rule intermittent_fig2:
    input:
        code=code("netrepro.papers.intermittent:figure_bounds"),
        bounds="results/intermittent/scalar_bounds.csv",
    output:
        figure=report("figures/intermittent/fig2.png", caption="../report/intermittent/fig2.rst", category="intermittent"),
    params:
        cfg=as_json({"which": "unstable"}),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/intermittent/fig2.log",
    shell:
        step("netrepro.papers.intermittent:figure_bounds")


rule intermittent_fig4:
    input:
        code=code("netrepro.papers.intermittent:figure_region"),
        region="results/intermittent/two_sensor_region.csv",
    output:
        figure=report("figures/intermittent/fig4.png", caption="../report/intermittent/fig4.rst", category="intermittent"),
    params:
        cfg=as_json({"show_upper": False}),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/intermittent/fig4.log",
    shell:
        step("netrepro.papers.intermittent:figure_region")


rule intermittent_fig5:
    input:
        code=code("netrepro.papers.intermittent:figure_region"),
        region="results/intermittent/two_sensor_region.csv",
        simulation="results/intermittent/two_sensor_simulation.csv",
    output:
        figure=report("figures/intermittent/fig5.png", caption="../report/intermittent/fig5.rst", category="intermittent"),
    params:
        cfg=as_json({"show_upper": True}),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/intermittent/fig5.log",
    shell:
        step("netrepro.papers.intermittent:figure_region")


rule intermittent_figS1:
    input:
        code=code("netrepro.papers.intermittent:figure_estimators"),
        mc="results/intermittent/monte_carlo.csv",
        exact="results/intermittent/exact_mean.csv",
    output:
        figure=report("figures/intermittent/figS1.png", caption="../report/intermittent/figS1.rst", category="intermittent"),
    params:
        cfg=as_json({}),
        io=io_json,
    conda:
        CONDA_ENV
    log:
        "logs/intermittent/figS1.log",
    shell:
        step("netrepro.papers.intermittent:figure_estimators")


# light steps run in the main Snakemake process, never as cluster jobs
localrules:
    intermittent_monte_carlo,
    intermittent_two_sensor_region,
    intermittent_scalar_bounds,
    intermittent_errata,
    intermittent_reconstructions,
    intermittent_claims,
    intermittent_fig1,
    intermittent_fig2,
    intermittent_fig4,
    intermittent_fig5,
    intermittent_figS1,
    intermittent_notebook,


INTERMITTENT_FIGURES = [f"figures/intermittent/{f}.png" for f in ("fig1", "fig2", "fig4", "fig5", "figS1")]
INTERMITTENT_TABLES = [
    "results/intermittent/scalar_bounds.csv",
    "results/intermittent/exact_mean.csv",
    "results/intermittent/monte_carlo.csv",
    "results/intermittent/two_sensor_region.csv",
    "results/intermittent/two_sensor_simulation.csv",
]


rule intermittent_notebook:
    input:
        notebook="workflow/notebooks/intermittent.ipynb",
        code=code("netrepro.reportgen"),
        figures=INTERMITTENT_FIGURES,
        tables=INTERMITTENT_TABLES,
        claims="results/claims/intermittent.csv",
        errata="results/errata/intermittent.csv",
        reconstructions="results/reconstructions/intermittent.csv",
    output:
        html="report/intermittent.html",
    conda:
        CONDA_ENV
    log:
        "logs/intermittent/notebook.log",
    shell:
        notebook("intermittent")


if enabled("intermittent"):
    PAPER_OUTPUTS["intermittent"] = dict(
        figures=INTERMITTENT_FIGURES,
        tables=INTERMITTENT_TABLES,
        claims="results/claims/intermittent.csv",
        errata="results/errata/intermittent.csv",
        reconstructions="results/reconstructions/intermittent.csv",
        notebook="report/intermittent.html",
    )
