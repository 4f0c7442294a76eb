# Paper `intermittent` (000): Teerikoski, Kalman filtering with measurement losses.
# Compute steps -> tables under results/intermittent/, and the evidence table the shared
# intermittent_claims rule (workflow/rules/verdicts.smk) judges the claims against.
# Figures and the notebook are generated (src/netrepro/papers/intermittent/figures.yaml).

ICFG = config.get("intermittent", {})
# keys the Monte Carlo results depend on (n_chunks and the shard count do not change them)
MC_KEYS = ("a", "R1", "R2", "Ep0", "lambda_offsets", "horizon", "n_paths", "block_size", "seed")


rule intermittent_exact_mean:
    input:
        code=code("netrepro.papers.intermittent.steps:exact_mean_step"),
    output:
        table="results/intermittent/exact_mean.csv",
    log:
        "logs/intermittent/exact_mean.log",
    conda:
        CONDA_ENV
    params:
        cfg=as_json(
            pick(
                ICFG.get("scalar", {}),
                "a",
                "R1",
                "R2",
                "Ep0",
                "lambda_offsets",
                "horizon",
                "exact_horizon",
            )
        ),
        rule="intermittent_exact_mean",
        io=io_json,
    shell:
        step("netrepro.papers.intermittent.steps:exact_mean_step")


rule intermittent_stationary_mean:
    input:
        code=code("netrepro.papers.intermittent.steps:stationary_mean_step"),
    output:
        table="results/intermittent/stationary_mean.csv",
    log:
        "logs/intermittent/stationary_mean.log",
    localrule: True
    conda:
        CONDA_ENV
    params:
        cfg=as_json(pick(ICFG.get("scalar", {}), "a", "R1", "R2", "Ep0", "lambda_offsets")),
        rule="intermittent_stationary_mean",
        io=io_json,
    shell:
        step("netrepro.papers.intermittent.steps:stationary_mean_step")


rule intermittent_monte_carlo_shard:
    input:
        code=code("netrepro.papers.intermittent.steps:monte_carlo_shard_step"),
    output:
        sums="results/intermittent/shards/monte_carlo_{shard}.npz",
    log:
        "logs/intermittent/monte_carlo_{shard}.log",
    wildcard_constraints:
        shard=r"\d+",
    conda:
        CONDA_ENV
    threads: 1
    resources:
        mem_mb=3000,
        runtime=20,
    params:
        cfg=lambda w: as_json(
            {
                **pick(ICFG["scalar"], *MC_KEYS),
                "shard": int(w.shard),
                "n_shards": len(shards("intermittent_monte_carlo")),
            }
        ),
        rule="intermittent_monte_carlo_shard",
        io=io_json,
    shell:
        step("netrepro.papers.intermittent.steps:monte_carlo_shard_step")


rule intermittent_monte_carlo:
    input:
        code=code("netrepro.papers.intermittent.steps:monte_carlo_merge_step"),
        exact=rules.intermittent_exact_mean.output.table,
        shards=expand(
            rules.intermittent_monte_carlo_shard.output.sums,
            shard=shards("intermittent_monte_carlo"),
        ),
    output:
        table="results/intermittent/monte_carlo.csv",
    log:
        "logs/intermittent/monte_carlo.log",
    localrule: True
    conda:
        CONDA_ENV
    threads: 1
    resources:
        mem_mb=1000,
        runtime=5,
    params:
        cfg=as_json(pick(ICFG.get("scalar", {}), *MC_KEYS)),
        rule="intermittent_monte_carlo",
        io=io_json,
    shell:
        step("netrepro.papers.intermittent.steps:monte_carlo_merge_step")


rule intermittent_scalar_bounds:
    input:
        code=code("netrepro.papers.intermittent.steps:scalar_bounds_step"),
        exact=rules.intermittent_exact_mean.output.table,
        mc=rules.intermittent_monte_carlo.output.table,
    output:
        table="results/intermittent/scalar_bounds.csv",
    log:
        "logs/intermittent/scalar_bounds.log",
    localrule: True
    conda:
        CONDA_ENV
    params:
        cfg=as_json(
            pick(ICFG.get("scalar", {}), "a", "R1", "R2", "Ep0", "lambda_offsets", "horizon")
        ),
        rule="intermittent_scalar_bounds",
        io=io_json,
    shell:
        step("netrepro.papers.intermittent.steps:scalar_bounds_step")


rule intermittent_two_sensor_region_shard:
    input:
        code=code("netrepro.papers.intermittent.steps:two_sensor_region_shard_step"),
    output:
        table="results/intermittent/shards/two_sensor_region_{shard}.csv",
    log:
        "logs/intermittent/two_sensor_region_{shard}.log",
    wildcard_constraints:
        shard=r"\d+",
    conda:
        CONDA_ENV
    threads: 1
    resources:
        mem_mb=1000,
        runtime=20,
    params:
        cfg=lambda w: as_json(
            {
                **pick(ICFG["two_sensor"], "a", "lambda1_grid", "bisection_tol"),
                "shard": int(w.shard),
                "n_shards": len(shards("intermittent_two_sensor_region")),
            }
        ),
        rule="intermittent_two_sensor_region_shard",
        io=io_json,
    shell:
        step("netrepro.papers.intermittent.steps:two_sensor_region_shard_step")


rule intermittent_two_sensor_region:
    input:
        code=code("netrepro.papers.intermittent.steps:two_sensor_region_merge_step"),
        shards=expand(
            rules.intermittent_two_sensor_region_shard.output.table,
            shard=shards("intermittent_two_sensor_region"),
        ),
    output:
        table="results/intermittent/two_sensor_region.csv",
    log:
        "logs/intermittent/two_sensor_region.log",
    localrule: True
    conda:
        CONDA_ENV
    params:
        cfg=as_json(pick(ICFG.get("two_sensor", {}), "a", "lambda1_grid", "bisection_tol")),
        rule="intermittent_two_sensor_region",
        io=io_json,
    shell:
        step("netrepro.papers.intermittent.steps:two_sensor_region_merge_step")


rule intermittent_two_sensor_simulation:
    input:
        code=code("netrepro.papers.intermittent.steps:two_sensor_simulation_step"),
    output:
        table="results/intermittent/two_sensor_simulation.csv",
    log:
        "logs/intermittent/two_sensor_simulation.log",
    conda:
        CONDA_ENV
    params:
        cfg=as_json(
            pick(
                ICFG.get("two_sensor", {}),
                "a",
                "R1",
                "sigma2",
                "check_lambda1",
                "check_offset",
                "check_horizon",
                "check_paths",
                "block_size",
                "seed",
            )
        ),
        rule="intermittent_two_sensor_simulation",
        io=io_json,
    shell:
        step("netrepro.papers.intermittent.steps:two_sensor_simulation_step")


rule intermittent_stationary_curve:
    input:
        code=code("netrepro.papers.intermittent.steps:stationary_curve_step"),
    output:
        table="results/intermittent/stationary_curve.csv",
    log:
        "logs/intermittent/stationary_curve.log",
    localrule: True
    conda:
        CONDA_ENV
    params:
        cfg=as_json(
            {
                **pick(ICFG.get("scalar", {}), "a", "R1", "R2", "lambda_offsets"),
                **ICFG.get("stationary_curve", {}),
            }
        ),
        rule="intermittent_stationary_curve",
        io=io_json,
    shell:
        step("netrepro.papers.intermittent.steps:stationary_curve_step")


rule intermittent_heavy_tail:
    input:
        code=code("netrepro.papers.intermittent.steps:heavy_tail_step"),
    output:
        table="results/intermittent/heavy_tail.csv",
    log:
        "logs/intermittent/heavy_tail.log",
    localrule: True
    conda:
        CONDA_ENV
    params:
        cfg=as_json(
            {
                **pick(ICFG.get("scalar", {}), "a", "R1", "R2", "Ep0", "lambda_offsets"),
                **ICFG.get("heavy_tail", {}),
            }
        ),
        rule="intermittent_heavy_tail",
        io=io_json,
    shell:
        step("netrepro.papers.intermittent.steps:heavy_tail_step")


rule intermittent_region_closed_form:
    input:
        code=code("netrepro.papers.intermittent.steps:region_closed_form_step"),
    output:
        table="results/intermittent/region_closed_form.csv",
    log:
        "logs/intermittent/region_closed_form.log",
    localrule: True
    conda:
        CONDA_ENV
    params:
        cfg=as_json(pick(ICFG.get("two_sensor", {}), "a", "n_dense")),
        rule="intermittent_region_closed_form",
        io=io_json,
    shell:
        step("netrepro.papers.intermittent.steps:region_closed_form_step")


rule intermittent_evidence:
    input:
        code=code("netrepro.papers.intermittent.evidence:evidence_step"),
        bounds=rules.intermittent_scalar_bounds.output.table,
        region=rules.intermittent_two_sensor_region.output.table,
        simulation=rules.intermittent_two_sensor_simulation.output.table,
        stationary=rules.intermittent_stationary_mean.output.table,
        curve=rules.intermittent_stationary_curve.output.table,
        tails=rules.intermittent_heavy_tail.output.table,
        claims="src/netrepro/papers/intermittent/claims.yaml",
    output:
        table="results/evidence/intermittent.csv",
    log:
        "logs/intermittent/evidence.log",
    localrule: True
    conda:
        CONDA_ENV
    threads: 1
    resources:
        mem_mb=1000,
        runtime=5,
    params:
        cfg=as_json(
            {
                "scalar": pick(ICFG.get("scalar", {}), "a", "R1", "R2", "Ep0", "lambda_offsets"),
                "two_sensor": pick(
                    ICFG.get("two_sensor", {}),
                    "a",
                    "sigma2",
                    "bisection_tol",
                    "check_lambda1",
                ),
                "evidence": ICFG.get("evidence", {}),
            }
        ),
        rule="intermittent_evidence",
        io=io_json,
    shell:
        step("netrepro.papers.intermittent.evidence:evidence_step")


if enabled("intermittent"):
    PAPER_TABLES["intermittent"] = [
        rules.intermittent_scalar_bounds.output.table,
        rules.intermittent_exact_mean.output.table,
        rules.intermittent_stationary_mean.output.table,
        rules.intermittent_monte_carlo.output.table,
        rules.intermittent_two_sensor_region.output.table,
        rules.intermittent_two_sensor_simulation.output.table,
        rules.intermittent_stationary_curve.output.table,
        rules.intermittent_heavy_tail.output.table,
        rules.intermittent_region_closed_form.output.table,
        rules.intermittent_evidence.output.table,
    ]
