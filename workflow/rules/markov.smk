# Paper `markov` (004): Wu, Shi, Anderson, Johansson, Kalman filtering over Gilbert-Elliott channels.
# Compute steps -> tables under results/markov/ and the evidence table; the shared rule markov_claims
# (workflow/rules/verdicts.smk) judges the claims in src/netrepro/papers/markov/*.yaml against it.
# Figure and notebook rules are generated (src/netrepro/papers/markov/figures.yaml, figures.smk).

MCFG = config.get("markov", {})


rule markov_critical_curves:
    input:
        code=code("netrepro.papers.markov.steps:critical_curves_step"),
    output:
        table="results/markov/critical_curves.csv",
        benchmark="results/markov/lmi_benchmark.csv",
    log:
        "logs/markov/critical_curves.log",
    conda:
        CONDA_ENV
    params:
        cfg=as_json(pick(MCFG, "examples", "curves")),
        rule="markov_critical_curves",
        io=io_json,
    shell:
        step("netrepro.papers.markov.steps:critical_curves_step")


rule markov_lmi_checks:
    input:
        code=code("netrepro.papers.markov.steps:lmi_checks_step"),
    output:
        table="results/markov/lmi_checks.csv",
    log:
        "logs/markov/lmi_checks.log",
    conda:
        CONDA_ENV
    params:
        cfg=as_json(pick(MCFG, "examples", "checks")),
        rule="markov_lmi_checks",
        io=io_json,
    shell:
        step("netrepro.papers.markov.steps:lmi_checks_step")


rule markov_tight_variants:
    input:
        code=code("netrepro.papers.markov.steps:tight_variants_step"),
    output:
        table="results/markov/tight_variants.csv",
    log:
        "logs/markov/tight_variants.log",
    conda:
        CONDA_ENV
    params:
        cfg=as_json(pick(MCFG, "examples", "checks")),
        rule="markov_tight_variants",
        io=io_json,
    shell:
        step("netrepro.papers.markov.steps:tight_variants_step")


rule markov_iid_line:
    input:
        code=code("netrepro.papers.markov.steps:iid_line_step"),
    output:
        table="results/markov/iid_line.csv",
    log:
        "logs/markov/iid_line.log",
    conda:
        CONDA_ENV
    params:
        cfg=as_json(pick(MCFG, "examples", "iid")),
        rule="markov_iid_line",
        io=io_json,
    shell:
        step("netrepro.papers.markov.steps:iid_line_step")


rule markov_exact_moments:
    input:
        code=code("netrepro.papers.markov.steps:exact_moments_step"),
    output:
        table="results/markov/exact_moments.csv",
    log:
        "logs/markov/exact_moments.log",
    conda:
        CONDA_ENV
    resources:
        mem_mb=1000,
    params:
        cfg=as_json(pick(MCFG, "examples", "exact")),
        rule="markov_exact_moments",
        io=io_json,
    shell:
        step("netrepro.papers.markov.steps:exact_moments_step")


rule markov_stability_map:
    input:
        code=code("netrepro.papers.markov.steps:stability_map_step"),
        moments=rules.markov_exact_moments.output.table,
    output:
        table="results/markov/stability_map.csv",
        sensitivity="results/markov/map_sensitivity.csv",
    log:
        "logs/markov/stability_map.log",
    conda:
        CONDA_ENV
    params:
        cfg=as_json(pick(MCFG, "examples", "map", "estimator")),
        rule="markov_stability_map",
        io=io_json,
    shell:
        step("netrepro.papers.markov.steps:stability_map_step")


rule markov_sample_paths:
    input:
        code=code("netrepro.papers.markov.steps:sample_paths_step"),
        moments=rules.markov_exact_moments.output.table,
    output:
        table="results/markov/sample_paths.csv",
        check="results/markov/estimator_check.csv",
    log:
        "logs/markov/sample_paths.log",
    conda:
        CONDA_ENV
    params:
        cfg=as_json(pick(MCFG, "examples", "paths", "estimator")),
        rule="markov_sample_paths",
        io=io_json,
    shell:
        step("netrepro.papers.markov.steps:sample_paths_step")


rule markov_expectations:
    input:
        code=code("netrepro.papers.markov.steps:expectations_step"),
        moments=rules.markov_exact_moments.output.table,
    output:
        table="results/markov/expectations.csv",
    log:
        "logs/markov/expectations.log",
    conda:
        CONDA_ENV
    threads: 1
    resources:
        mem_mb=1000,
    params:
        cfg=as_json(pick(MCFG, "examples", "paths", "expectations", "estimator")),
        rule="markov_expectations",
        io=io_json,
    shell:
        step("netrepro.papers.markov.steps:expectations_step")


rule markov_asymptote_holdout:
    input:
        code=code("netrepro.papers.markov.steps:asymptote_holdout_step"),
        expectations=rules.markov_expectations.output.table,
    output:
        table="results/markov/asymptote_holdout.csv",
    log:
        "logs/markov/asymptote_holdout.log",
    conda:
        CONDA_ENV
    threads: 1
    resources:
        mem_mb=4000,
    params:
        cfg=as_json(pick(MCFG, "examples", "paths", "expectations")),
        rule="markov_asymptote_holdout",
        io=io_json,
    shell:
        step("netrepro.papers.markov.steps:asymptote_holdout_step")


rule markov_evidence:
    input:
        code=code("netrepro.papers.markov.evidence:evidence_step"),
        checks=rules.markov_lmi_checks.output.table,
        tight=rules.markov_tight_variants.output.table,
        curves=rules.markov_critical_curves.output.table,
        iid=rules.markov_iid_line.output.table,
        map=rules.markov_stability_map.output.table,
        sensitivity=rules.markov_stability_map.output.sensitivity,
        moments=rules.markov_exact_moments.output.table,
        holdout=rules.markov_asymptote_holdout.output.table,
        claims="src/netrepro/papers/markov/claims.yaml",
        findings="src/netrepro/papers/markov/findings.yaml",
    output:
        table="results/evidence/markov.csv",
    log:
        "logs/markov/evidence.log",
    localrule: True
    conda:
        CONDA_ENV
    threads: 1
    resources:
        mem_mb=500,
    params:
        cfg=as_json(
            pick(
                MCFG,
                "examples",
                "paths",
                "checks",
                "exact",
                "map",
                "curves",
                "iid",
                "expectations",
                "estimator",
                "prop2",
                "errata_seed",
            )
        ),
        rule="markov_evidence",
        io=io_json,
    shell:
        step("netrepro.papers.markov.evidence:evidence_step")


if enabled("markov"):
    PAPER_TABLES["markov"] = [
        rules.markov_critical_curves.output.table,
        rules.markov_critical_curves.output.benchmark,
        rules.markov_lmi_checks.output.table,
        rules.markov_tight_variants.output.table,
        rules.markov_iid_line.output.table,
        rules.markov_exact_moments.output.table,
        rules.markov_stability_map.output.table,
        rules.markov_stability_map.output.sensitivity,
        rules.markov_sample_paths.output.table,
        rules.markov_sample_paths.output.check,
        rules.markov_expectations.output.table,
        rules.markov_asymptote_holdout.output.table,
        rules.markov_evidence.output.table,
    ]
