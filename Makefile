# Two commands do everything: `make report` and `make test`.
# Each creates .venv/ on first use (from the package registry only).
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
JOBS ?= 2

.PHONY: report test lint bench verify clean-results

$(STAMP): pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[test]'
	$(BIN)/python -m ipykernel install --prefix $(VENV) --name python3 >/dev/null
	touch $(STAMP)

report: $(STAMP)
	$(BIN)/snakemake --profile workflow/profiles/default -j$(JOBS) report
	$(BIN)/snakemake --profile workflow/profiles/default --report report/snakemake_report.html report

test: $(STAMP)
	$(BIN)/python -m pytest -n 2 --dist loadgroup tests

# Check every result table against the checksum in its provenance sidecar.
verify: $(STAMP)
	$(BIN)/python -m netrepro verify

lint: $(STAMP)
	$(BIN)/snakemake --lint

# Benchmarks with ratios against simple references (issue 9); `make bench BENCH_ARGS=--quick` skips the pipeline.
BENCH_ARGS ?=
bench: $(STAMP)
	$(BIN)/python -m netrepro.bench --out results/benchmarks.csv $(BENCH_ARGS)

clean-results:
	rm -rf results logs .snakemake/metadata
