# Two commands do everything: `make report` and `make test`.
# Each creates .venv/ on first use from the lock files in requirements/ (exact versions and
# hashes, from the package registry only); `make lock` refreshes the lock files.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
LOCK := requirements
# default environment (make report) and test environment (make test, make lint: default + test extra)
STAMP := $(VENV)/.installed-default
STAMP_TEST := $(VENV)/.installed-test
JOBS ?= 2
# the lock tool (used by `make lock` only; installing from the lock needs pip alone)
UV_VERSION ?= 0.13.9
LOCK_FLAGS = --universal --python-version 3.11.5 --generate-hashes --quiet \
	--custom-compile-command 'make lock'
# `make lock UPGRADE=1`: newest versions the bounds in pyproject.toml allow (else: keep the pins)
UPGRADE ?=

.PHONY: venv-paths report repair unlock prune test test-fast lint lock bench verify clean clean-results readme check update-references archive

$(STAMP): $(LOCK)/bootstrap.txt $(LOCK)/default.txt pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --require-hashes -r $(LOCK)/bootstrap.txt
	$(BIN)/python -m pip install --quiet --require-hashes -r $(LOCK)/default.txt
	$(BIN)/python -m pip install --quiet --no-deps --no-build-isolation -e .
	$(BIN)/python src/netrepro/pipeline/venv_paths.py $(VENV)
	$(BIN)/python -m ipykernel install --prefix $(VENV) --name python3 >/dev/null
	touch $(STAMP)

$(STAMP_TEST): $(STAMP) $(LOCK)/test.txt
	$(BIN)/python -m pip install --quiet --require-hashes -r $(LOCK)/test.txt
	touch $(STAMP_TEST)

# The environment moves with its checkout: its editable install names src/ by a relative path, and a
# .venv/ moved or copied from another checkout is pointed at this one's src/ (said when it happens).
# The tools are started through the environment's python, not their scripts, whose first line names
# the interpreter by its absolute path at install time.
venv-paths: $(STAMP)
	@$(BIN)/python src/netrepro/pipeline/venv_paths.py $(VENV)

# Console: one line per finished job and the warnings (workflow/profiles/default); each job's
# full command is in its log (logs/) and its provenance sidecar (*.meta.json).
# `make report CONFIG=paper-scale [PROFILE=slurm]`: the overlay config/$(CONFIG).yaml on top of
# config/config.yaml, through the profile workflow/profiles/$(PROFILE) (a cluster profile sets its own
# job limit; the shard counts come from the profile or SHARDS='{onebit_estimator: 8}').
CONFIG ?=
PROFILE ?= default
SHARDS ?=
SMK_OPTS = --profile workflow/profiles/$(PROFILE) $(if $(filter default,$(PROFILE)),-j$(JOBS)) \
	$(if $(SHARDS),--config 'shards=$(SHARDS)') $(if $(CONFIG),--configfile config/config.yaml config/$(CONFIG).yaml)
# The build driver (netrepro.pipeline.build) runs `snakemake report $(SMK_OPTS)`: it says "interrupted; rerun" after
# Ctrl-C, refuses to start beside a running build of this checkout, and says whose a lock is.
BUILD = $(BIN)/python -m netrepro

# Bytecode of the package compiled once: where PYTHONDONTWRITEBYTECODE is set (containers, CI), every job
# would otherwise compile the modules it imports again (~0.05-0.1 CPU s per job); elsewhere a no-op.
# Snakemake's own report is written by the run itself (--report-after-run): a second `snakemake --report`
# parsed the workflow and built the DAG again (~1.3 s after every build), and the run's report overlaps the
# wait for its last re-evaluation timer (max-jobs-per-timespan, workflow/profiles/default/config.yaml).
report: $(STAMP) venv-paths
	$(BIN)/python -m compileall -q src
	$(BUILD) build -- $(SMK_OPTS) --report report/snakemake_report.html --report-after-run
	$(BIN)/python -m netrepro report relocate report/snakemake_report.html

# A damaged build repaired in one command: removes every output `verify` finds corrupt, unfinished or
# unverifiable, rebuilds those and every declared output that is missing, and what depends on them.
repair: $(STAMP) venv-paths
	$(BIN)/python -m compileall -q src
	$(BUILD) repair -- $(SMK_OPTS) --report report/snakemake_report.html --report-after-run
	$(BIN)/python -m netrepro report relocate report/snakemake_report.html

# Removes the lock a killed build left (Snakemake's --unlock); refuses while a build of this checkout runs.
unlock: $(STAMP) venv-paths
	$(BUILD) unlock -- $(SMK_OPTS)

test: $(STAMP_TEST) venv-paths
	$(BIN)/python -m pytest -n 2 --dist loadgroup tests

# The fast lane: every test that runs no Snakemake and no build (marked `slow`), with fewer
# property-test examples (the hypothesis profile "fast", tests/conftest.py).
test-fast: $(STAMP_TEST) venv-paths
	$(BIN)/python -m pytest -n 2 -m "not slow" --hypothesis-profile fast tests

# Check every result table against the checksum in its provenance sidecar.
verify: $(STAMP) venv-paths
	$(BIN)/python -m netrepro verify

lint: $(STAMP_TEST) venv-paths
	$(BIN)/python -m snakefmt --check Snakefile workflow
	$(BIN)/python -m snakemake --lint
	$(BIN)/python -m netrepro check-paper
	$(BIN)/python $(BIN)/actionlint .github/workflows/regenerate.yml .github/workflows/pages.yml

# What CI runs after its build (after `make report`): every table against the checksum in its
# provenance sidecar, then tables and figures against the committed references; it always writes
# results/regeneration/index.html and summary.json/summary.md (what was compared) and fails on a difference (README: "Checking that figures regenerate").
# Then the stale outputs (files in results/ and figures/ no rule of this workflow produces, with the
# same CONFIG/PROFILE as the build): listed with `make prune`, and they fail the check, since a stale
# table could be frozen into the references by `make update-references`. Last, the README's results table
# against this build (`make readme` rewrites it).
check: $(STAMP) venv-paths
	$(BIN)/python -m netrepro verify
	status=0; $(BIN)/python -m netrepro regression compare --reference tests/reference --results results \
		|| status=$$?; $(BIN)/python -m netrepro prune --check -- $(SMK_OPTS) || status=1; \
		$(BIN)/python -m netrepro readme --check README.md || status=1; exit $$status

# Removes the stale outputs (netrepro.pipeline.stale): files in results/ and figures/ that no rule of the current
# workflow produces (a renamed or removed step's), with their sidecars; `make prune PRUNE_ARGS=--dry-run` lists them.
PRUNE_ARGS ?=
prune: $(STAMP) venv-paths
	$(BIN)/python -m netrepro prune $(PRUNE_ARGS) -- $(SMK_OPTS)

# An intended change: the last build becomes the reference (tables into tests/reference/; the
# figures and their data sidecars are already in figures/). Prints what changed; then commit both.
# `make update-references PAPER=markov` (or PAPER='markov hinf'): only those papers' tables (their folder and
# their rows of the shared claims/, errata/, findings/, evidence/, reconstructions/); every other reference
# stays byte-identical. Timing columns (netrepro.judging.regression.TIMING_COLUMNS) are never copied.
PAPER ?=
update-references: $(STAMP) venv-paths
	$(BIN)/python -m netrepro regression update --reference tests/reference --results results \
		$(foreach p,$(PAPER),--paper $(p))

# Refresh the lock files from pyproject.toml (pins kept unless UPGRADE=1); then `make test`.
lock: $(STAMP)
	$(BIN)/python -m pip install --quiet 'uv==$(UV_VERSION)'
	$(BIN)/uv pip compile $(LOCK)/bootstrap.in $(LOCK_FLAGS) $(if $(UPGRADE),--upgrade) -o $(LOCK)/bootstrap.txt
	$(BIN)/uv pip compile pyproject.toml $(LOCK_FLAGS) $(if $(UPGRADE),--upgrade) -o $(LOCK)/default.txt
	$(BIN)/uv pip compile pyproject.toml --extra test $(LOCK_FLAGS) $(if $(UPGRADE),--upgrade) -c $(LOCK)/default.txt -o $(LOCK)/test.txt
	$(BIN)/uv pip compile pyproject.toml --extra archive $(LOCK_FLAGS) $(if $(UPGRADE),--upgrade) -c $(LOCK)/default.txt -o $(LOCK)/archive.txt
	$(BIN)/python -m netrepro lockfile conda-env $(LOCK)/default.txt workflow/envs/netrepro.yaml

# Rewrite the results table of README.md from the claims, errata and figures of the last build.
readme: $(STAMP) venv-paths
	$(BIN)/python -m netrepro readme README.md

# Benchmarks with ratios against simple references (issue 9); `make bench BENCH_ARGS=--quick` skips the pipeline.
BENCH_ARGS ?=
bench: $(STAMP) venv-paths
	$(BIN)/python -m netrepro bench --out results/benchmarks.csv $(BENCH_ARGS)

# Everything the pipeline makes: tables, logs, figures (committed, but rebuilt), the report and
# Snakemake's metadata (its conda/container caches stay). `make report` afterwards runs every job.
CLEAN_PATHS = results logs report/*.html report/*.ipynb report/*.meta.json report/files \
	report/ro-crate-metadata.json report/README.md report/*.png figures/*/*.png figures/*/*.data.json figures/*/*.meta.json
clean:
	rm -rf $(CLEAN_PATHS)
	test ! -d .snakemake || find .snakemake -mindepth 1 -maxdepth 1 ! -name conda ! -name singularity \
		-exec rm -rf {} +

# Kept for old habits: a rebuild needs the figures and the report gone too, so this is `make clean`.
clean-results: clean

# One deposit of this commit (issue 41): a BagIt bag archive/netrepro-<commit12>/ (and its .zip) with the
# git archive of HEAD, the built report/ (run `make report` first), the lock files, CITATION.cff and, made
# from it, .zenodo.json and codemeta.json. bagit is installed on demand from its own lock (hashes).
archive: $(STAMP) venv-paths $(LOCK)/archive.txt
	$(BIN)/python -m pip install --quiet --require-hashes -r $(LOCK)/archive.txt
	$(BIN)/python -m netrepro archive --out archive --zip
