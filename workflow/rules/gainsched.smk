# Paper `gainsched` (001): Wei, Wang, Shen, Li, probability-dependent gain-scheduled filtering.
# Designs (Theorem 3 and beyond) -> independent stability checks, Monte Carlo of Algorithm 1,
# sigma^2 sensitivity, what scheduling buys, Remark 5 timing, certified vertex LMIs -> evidence
# (which also reads the claims' and findings' at: settings); the shared rule
# gainsched_claims judges it against claims.yaml, errata.yaml, reconstructions.yaml and
# findings.yaml. Figures and the notebook are generated (workflow/rules/figures.smk)
# from src/netrepro/papers/gainsched/figures.yaml.

GCFG = config.get("gainsched", {})


rule gainsched_design:
    input:
        code=code("netrepro.papers.gainsched.steps:design_step"),
    output:
        gains="results/gainsched/gains.csv",
        designs="results/gainsched/designs.csv",
        solutions="results/gainsched/lmi_solutions.csv",
    log:
        "logs/gainsched/design.log",
    conda:
        CONDA_ENV
    threads: 1
    resources:
        mem_mb=2000,
        runtime=5,
    params:
        cfg=as_json(
            pick(GCFG, "system", "paper_gains", "lmi", "performance", "tuning", "simulation")
        ),
        rule="gainsched_design",
        io=io_json,
    shell:
        step("netrepro.papers.gainsched.steps:design_step")


rule gainsched_stability:
    input:
        code=code("netrepro.papers.gainsched.steps:stability_step"),
        gains=rules.gainsched_design.output.gains,
        solutions=rules.gainsched_design.output.solutions,
    output:
        stability="results/gainsched/stability.csv",
        theorem1="results/gainsched/theorem1.csv",
    log:
        "logs/gainsched/stability.log",
    conda:
        CONDA_ENV
    threads: 1
    resources:
        mem_mb=2000,
        runtime=5,
    params:
        cfg=as_json(pick(GCFG, "system", "lmi", "stability", "simulation")),
        rule="gainsched_stability",
        io=io_json,
    shell:
        step("netrepro.papers.gainsched.steps:stability_step")


rule gainsched_simulation:
    input:
        code=code("netrepro.papers.gainsched.steps:simulation_step"),
        gains=rules.gainsched_design.output.gains,
    output:
        errors="results/gainsched/errors.csv",
        error_summary="results/gainsched/error_summary.csv",
        paths="results/gainsched/sample_paths.csv",
    log:
        "logs/gainsched/simulation.log",
    conda:
        CONDA_ENV
    threads: 1
    resources:
        mem_mb=2000,
        runtime=2,
    params:
        cfg=as_json(pick(GCFG, "system", "simulation", "performance")),
        rule="gainsched_simulation",
        io=io_json,
    shell:
        step("netrepro.papers.gainsched.steps:simulation_step")


rule gainsched_exact_moments:
    input:
        code=code("netrepro.papers.gainsched.steps:exact_moments_step"),
        gains=rules.gainsched_design.output.gains,
        designs=rules.gainsched_design.output.designs,
    output:
        table="results/gainsched/exact_moments.csv",
        per_k="results/gainsched/exact_mse.csv",
        performance="results/gainsched/performance.csv",
    log:
        "logs/gainsched/exact_moments.log",
    conda:
        CONDA_ENV
    threads: 1
    resources:
        mem_mb=1000,
        runtime=1,
    params:
        cfg=as_json(pick(GCFG, "system", "simulation")),
        rule="gainsched_exact_moments",
        io=io_json,
    shell:
        step("netrepro.papers.gainsched.steps:exact_moments_step")


rule gainsched_sensitivity:
    input:
        code=code("netrepro.papers.gainsched.steps:sensitivity_step"),
    output:
        table="results/gainsched/sensitivity.csv",
        limits="results/gainsched/feasibility_limit.csv",
    log:
        "logs/gainsched/sensitivity.log",
    conda:
        CONDA_ENV
    threads: 1
    resources:
        mem_mb=2000,
        runtime=5,
    params:
        cfg=as_json(pick(GCFG, "system", "paper_gains", "lmi", "sensitivity")),
        rule="gainsched_sensitivity",
        io=io_json,
    shell:
        step("netrepro.papers.gainsched.steps:sensitivity_step")


rule gainsched_scheduling:
    input:
        code=code("netrepro.papers.gainsched.steps:scheduling_step"),
        gains=rules.gainsched_design.output.gains,
    output:
        table="results/gainsched/scheduling.csv",
    log:
        "logs/gainsched/scheduling.log",
    conda:
        CONDA_ENV
    threads: 1
    resources:
        mem_mb=2000,
        runtime=5,
    params:
        cfg=as_json(pick(GCFG, "system", "lmi", "performance", "simulation", "scheduling")),
        rule="gainsched_scheduling",
        io=io_json,
    shell:
        step("netrepro.papers.gainsched.steps:scheduling_step")


rule gainsched_timing:
    input:
        code=code("netrepro.papers.gainsched.steps:timing_step"),
    output:
        table="results/gainsched/timing.csv",
    log:
        "logs/gainsched/timing.log",
    conda:
        CONDA_ENV
    threads: 1
    resources:
        mem_mb=4000,
        runtime=10,
    params:
        cfg=as_json(pick(GCFG, "system", "lmi", "timing")),
        rule="gainsched_timing",
        io=io_json,
    shell:
        step("netrepro.papers.gainsched.steps:timing_step")


rule gainsched_vertex_lmis:
    input:
        code=code("netrepro.papers.gainsched.steps:vertex_lmi_step"),
    output:
        table="results/gainsched/vertex_lmis.csv",
    log:
        "logs/gainsched/vertex_lmis.log",
    conda:
        CONDA_ENV
    threads: 1
    resources:
        mem_mb=2000,
        runtime=5,
    params:
        cfg=as_json(pick(GCFG, "system", "paper_gains", "lmi", "sensitivity")),
        rule="gainsched_vertex_lmis",
        io=io_json,
    shell:
        step("netrepro.papers.gainsched.steps:vertex_lmi_step")


rule gainsched_evidence:
    input:
        code=code("netrepro.papers.gainsched.evidence:evidence_step"),
        gains=rules.gainsched_design.output.gains,
        designs=rules.gainsched_design.output.designs,
        solutions=rules.gainsched_design.output.solutions,
        theorem1=rules.gainsched_stability.output.theorem1,
        exact=rules.gainsched_exact_moments.output.table,
        exact_mse=rules.gainsched_exact_moments.output.per_k,
        sensitivity=rules.gainsched_sensitivity.output.table,
        limits=rules.gainsched_sensitivity.output.limits,
        scheduling=rules.gainsched_scheduling.output.table,
        vertex=rules.gainsched_vertex_lmis.output.table,
        claims="src/netrepro/papers/gainsched/claims.yaml",
        findings="src/netrepro/papers/gainsched/findings.yaml",
    output:
        table="results/evidence/gainsched.csv",
    log:
        "logs/gainsched/evidence.log",
    localrule: True
    conda:
        CONDA_ENV
    threads: 1
    resources:
        mem_mb=1000,
        runtime=2,
    params:
        cfg=as_json(
            pick(
                GCFG,
                "system",
                "paper_gains",
                "lmi",
                "simulation",
                "stability",
                "sensitivity",
                "evidence",
            )
        ),
        rule="gainsched_evidence",
        io=io_json,
    shell:
        step("netrepro.papers.gainsched.evidence:evidence_step")


if enabled("gainsched"):
    PAPER_TABLES["gainsched"] = [
        rules.gainsched_design.output.gains,
        rules.gainsched_design.output.designs,
        rules.gainsched_design.output.solutions,
        rules.gainsched_stability.output.stability,
        rules.gainsched_stability.output.theorem1,
        rules.gainsched_simulation.output.errors,
        rules.gainsched_simulation.output.error_summary,
        rules.gainsched_simulation.output.paths,
        rules.gainsched_exact_moments.output.table,
        rules.gainsched_exact_moments.output.per_k,
        rules.gainsched_exact_moments.output.performance,
        rules.gainsched_sensitivity.output.table,
        rules.gainsched_sensitivity.output.limits,
        rules.gainsched_scheduling.output.table,
        rules.gainsched_timing.output.table,
        rules.gainsched_vertex_lmis.output.table,
        rules.gainsched_evidence.output.table,
    ]
