# Entry point at the repository root; the workflow lives in workflow/Snakefile (standard layout).
include: "workflow/Snakefile"
