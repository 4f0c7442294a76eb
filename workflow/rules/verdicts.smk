# Generated rules: one `<slug>_claims` per paper. The shared verdict function judges the paper's
# claims (src/netrepro/papers/<slug>/claims.yaml) against its evidence table and result tables,
# and writes its claims, errata, reconstructions and findings tables (issue 15).
# Included after the papers' own rules, whose `<slug>_evidence` outputs it reads.


for _slug in [s for s in config["papers"] if s in PAPER_TABLES]:

    rule:
        name:
            f"{_slug}_claims"
        input:
            **paper_data_files(_slug),
            code=code("netrepro.judging.verdicts:verdicts_step"),
            evidence=getattr(rules, f"{_slug}_evidence").output.table,
            tables=paper_claim_tables(_slug),
        output:
            table=f"results/claims/{_slug}.csv",
            errata=f"results/errata/{_slug}.csv",
            reconstructions=f"results/reconstructions/{_slug}.csv",
            findings=f"results/findings/{_slug}.csv",
        log:
            f"logs/{_slug}/claims.log",
        localrule: True
        conda:
            CONDA_ENV
        threads: 1
        resources:
            mem_mb=500,
            runtime=1,
        params:
            func="netrepro.judging.verdicts:verdicts_step",
            cfg=as_json({"slug": _slug}),
            rule=f"{_slug}_claims",
            io=io_json,
        shell:
            step()
