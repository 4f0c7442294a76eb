# Reproduction pipeline for five papers on networked estimation and control.
# Entry points: `snakemake -j2 report` (everything), `snakemake -j2 <slug>_figN` (one figure).


configfile: "config/config.yaml"


include: "workflow/rules/common.smk"
include: "workflow/rules/intermittent.smk"
include: "workflow/rules/markov.smk"
include: "workflow/rules/onebit.smk"
include: "workflow/rules/gainsched.smk"
include: "workflow/rules/hinf.smk"
include: "workflow/rules/report.smk"


finalize_rules(workflow)
