# Paper `onebit` (002): Zhang, Stein, Nossek, asymptotic performance analysis for 1-bit Bayesian smoothing.
# Compute steps -> tables under results/onebit/ and the evidence table results/evidence/onebit.csv; the claims,
# errata, reconstructions and findings tables come from the shared rule onebit_claims (verdicts.smk).

OCFG = config.get("onebit", {})
# config keys each step reads (only these trigger its rerun)
ONEBIT_KEYS = {
    "efq": ("quadrature", "efq_grid_db"),
    "ratios": ("snr_grid_db", "quadrature", "one_minus_alpha", "sigma_eta", "snr_definition"),
    "lag": (
        "snr_grid_db",
        "lag_tol_db",
        "lag_iterate_max",
        "one_minus_alpha",
        "sigma_eta",
        "snr_definition",
    ),
    "convergence": (
        "convergence",
        "one_minus_alpha",
        "sigma_eta",
        "sigma_theta0",
        "mu_theta0",
        "snr_definition",
    ),
    "estimator": ("estimator", "sigma_eta", "snr_definition"),
    "alpha_scan": ("alpha_scan", "sigma_eta", "snr_definition"),
    "vector_check": ("vector_check",),
    "evidence": (
        "sigma_eta",
        "sigma_theta0",
        "mu_theta0",
        "snr_definition",
        "one_minus_alpha",
        "fig1_one_minus_alpha",
        "reference_snr_db",
        "snr_grid_db",
        "quadrature",
        "lag_tol_db",
        "estimator",
        "evidence",
        "vector_check",
    ),
}


rule onebit_efq:
    input:
        code=code("netrepro.papers.onebit.steps:efq_step"),
    output:
        table="results/onebit/efq.csv",
    log:
        "logs/onebit/efq.log",
    conda:
        CONDA_ENV
    threads: 1
    resources:
        mem_mb=500,
        runtime=5,
    params:
        cfg=as_json(pick(OCFG, *ONEBIT_KEYS["efq"])),
        rule="onebit_efq",
        io=io_json,
    shell:
        step("netrepro.papers.onebit.steps:efq_step")


rule onebit_ratios:
    input:
        code=code("netrepro.papers.onebit.steps:ratios_step"),
    output:
        table="results/onebit/ratios.csv",
    log:
        "logs/onebit/ratios.log",
    conda:
        CONDA_ENV
    threads: 1
    resources:
        mem_mb=500,
        runtime=5,
    params:
        cfg=as_json(pick(OCFG, *ONEBIT_KEYS["ratios"])),
        rule="onebit_ratios",
        io=io_json,
    shell:
        step("netrepro.papers.onebit.steps:ratios_step")


rule onebit_lag:
    input:
        code=code("netrepro.papers.onebit.steps:lag_step"),
    output:
        table="results/onebit/lag.csv",
    log:
        "logs/onebit/lag.log",
    conda:
        CONDA_ENV
    threads: 1
    resources:
        mem_mb=500,
        runtime=5,
    params:
        cfg=as_json(pick(OCFG, *ONEBIT_KEYS["lag"])),
        rule="onebit_lag",
        io=io_json,
    shell:
        step("netrepro.papers.onebit.steps:lag_step")


rule onebit_convergence:
    input:
        code=code("netrepro.papers.onebit.steps:convergence_step"),
    output:
        table="results/onebit/convergence.csv",
        transient="results/onebit/transient.csv",
    log:
        "logs/onebit/convergence.log",
    conda:
        CONDA_ENV
    threads: 1
    resources:
        mem_mb=2000,
        runtime=10,
    params:
        cfg=as_json(pick(OCFG, *ONEBIT_KEYS["convergence"])),
        rule="onebit_convergence",
        io=io_json,
    shell:
        step("netrepro.papers.onebit.steps:convergence_step")


rule onebit_estimator_shard:
    input:
        code=code("netrepro.papers.onebit.steps:estimator_shard_step"),
    output:
        runs="results/onebit/shards/estimator_{shard}.npz",
    log:
        "logs/onebit/estimator_{shard}.log",
    wildcard_constraints:
        shard=r"\d+",
    conda:
        CONDA_ENV
    threads: 1
    resources:
        mem_mb=1500,
        runtime=10,
    params:
        cfg=lambda w: as_json(
            {
                **pick(OCFG, *ONEBIT_KEYS["estimator"]),
                "shard": int(w.shard),
                "n_shards": len(shards("onebit_estimator")),
            }
        ),
        rule="onebit_estimator_shard",
        io=io_json,
    shell:
        step("netrepro.papers.onebit.steps:estimator_shard_step")


rule onebit_estimator:
    input:
        code=code("netrepro.papers.onebit.steps:estimator_step"),
        shards=expand(rules.onebit_estimator_shard.output.runs, shard=shards("onebit_estimator")),
    output:
        table="results/onebit/estimator_mse.csv",
        ratios="results/onebit/estimator_ratios.csv",
        crossing="results/onebit/estimator_crossing.csv",
        coverage="results/onebit/estimator_coverage.csv",
        edge="results/onebit/estimator_edge.csv",
    log:
        "logs/onebit/estimator.log",
    localrule: True
    conda:
        CONDA_ENV
    threads: 1
    resources:
        mem_mb=1000,
        runtime=5,
    params:
        cfg=as_json(pick(OCFG, *ONEBIT_KEYS["estimator"])),
        rule="onebit_estimator",
        io=io_json,
    shell:
        step("netrepro.papers.onebit.steps:estimator_step")


rule onebit_alpha_scan:
    input:
        code=code("netrepro.papers.onebit.steps:alpha_scan_step"),
    output:
        table="results/onebit/alpha_scan.csv",
        threshold="results/onebit/alpha_threshold.csv",
    log:
        "logs/onebit/alpha_scan.log",
    conda:
        CONDA_ENV
    threads: 1
    resources:
        mem_mb=500,
        runtime=5,
    params:
        cfg=as_json(pick(OCFG, *ONEBIT_KEYS["alpha_scan"])),
        rule="onebit_alpha_scan",
        io=io_json,
    shell:
        step("netrepro.papers.onebit.steps:alpha_scan_step")


rule onebit_vector_check:
    input:
        code=code("netrepro.papers.onebit.steps:vector_check_step"),
    output:
        table="results/onebit/vector_check.csv",
    log:
        "logs/onebit/vector_check.log",
    conda:
        CONDA_ENV
    threads: 1
    resources:
        mem_mb=500,
        runtime=5,
    params:
        cfg=as_json(pick(OCFG, *ONEBIT_KEYS["vector_check"])),
        rule="onebit_vector_check",
        io=io_json,
    shell:
        step("netrepro.papers.onebit.steps:vector_check_step")


rule onebit_evidence:
    input:
        code=code("netrepro.papers.onebit.evidence:evidence_step"),
        ratios=rules.onebit_ratios.output.table,
        efq=rules.onebit_efq.output.table,
        lag=rules.onebit_lag.output.table,
        estimator=rules.onebit_estimator.output.table,
        estimator_ratios=rules.onebit_estimator.output.ratios,
        crossing=rules.onebit_estimator.output.crossing,
        coverage=rules.onebit_estimator.output.coverage,
        edge=rules.onebit_estimator.output.edge,
        alpha_threshold=rules.onebit_alpha_scan.output.threshold,
        shards=rules.onebit_estimator.input.shards,
        findings_file="src/netrepro/papers/onebit/findings.yaml",
        errata_file="src/netrepro/papers/onebit/errata.yaml",
        claims_file="src/netrepro/papers/onebit/claims.yaml",
    output:
        table="results/evidence/onebit.csv",
    log:
        "logs/onebit/evidence.log",
    localrule: True
    conda:
        CONDA_ENV
    threads: 1
    resources:
        mem_mb=500,
        runtime=5,
    params:
        cfg=as_json(pick(OCFG, *ONEBIT_KEYS["evidence"])),
        rule="onebit_evidence",
        io=io_json,
    shell:
        step("netrepro.papers.onebit.evidence:evidence_step")


if enabled("onebit"):
    PAPER_TABLES["onebit"] = [
        rules.onebit_ratios.output.table,
        rules.onebit_lag.output.table,
        rules.onebit_efq.output.table,
        rules.onebit_convergence.output.table,
        rules.onebit_convergence.output.transient,
        rules.onebit_estimator.output.table,
        rules.onebit_vector_check.output.table,
        rules.onebit_estimator.output.ratios,
        rules.onebit_estimator.output.crossing,
        rules.onebit_estimator.output.coverage,
        rules.onebit_estimator.output.edge,
        rules.onebit_alpha_scan.output.table,
        rules.onebit_alpha_scan.output.threshold,
        rules.onebit_evidence.output.table,
    ]
