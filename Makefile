# Entry points for a fresh machine with Python 3.11 (see README):
#   make venv           - build .venv from environment.lock and, while it installs, compile what
#                         every job would otherwise compile again
#   make warm-up        - build .venv, then compile again what changed since (make study and
#                         make test run it first)
#   make study          - build .venv from environment.lock, then run the full study
#   make test           - build .venv from environment.lock, then run the fast tier of the tests
#                         (all but the end-to-end workflow runs, marker `workflow`, and the
#                         pages in a real browser, marker `browser`)
#   make test-workflow  - the end-to-end workflow tier alone (CI runs make test, then this)
#   make test-browser   - the browser tier alone: the 3-D pages in headless Chromium
#                         (/usr/bin/chromium: apt-get install chromium; CI installs it)
#   make test-all       - every test, the end-to-end workflow runs and the browser included
#   make lint           - ruff check (pyflakes, pycodestyle's errors, 130 characters), snakefmt --check,
#                         snakemake --lint (conda/container advice aside) and the package's layers and
#                         no import circle (import-linter, pyproject.toml); ruff format --check too once
#                         the tree is formatted (the marker file .ruff-formatted)
#   make format         - ruff format on the Python files, then the marker .ruff-formatted (the
#                         integrator runs it once after the open branches are merged)
#   make cluster-test   - the small study on a single-node SLURM started here (root; installs SLURM)
#   make bench          - the benchmarks, recorded in benchmarks/results/, and docs/measurements.md
#   make bench-study    - the default study timed from an empty results/, recorded likewise
PYTHON ?= python3.11
VENV   ?= .venv
BIN    := $(VENV)/bin
CORES  ?= 2

.PHONY: venv warm-up study test test-workflow test-browser test-all lint format cluster-test bench bench-study lock report clean-venv

# The installer is uv (tools/uv.lock.txt, installed by pip with --require-hashes): it installs the
# same hash-checked files as pip would, side by side (docs/measurements.md, fresh_clone). Every
# file is checked against its hash, so every index the lock names is considered for a version
# (unsafe-best-match; uv's default would stop at the first index that has the name).
# The venv gets no pip of its own (ensurepip would write pip's thousand modules, seconds of the
# set-up): the interpreter's pip (22.3 or later, `--python`) installs uv into it, or, where that
# interpreter has no such pip, the venv's own pip installed then.
UV = $(BIN)/uv pip install --quiet --python $(BIN)/python --no-deps --index-strategy unsafe-best-match
PIP_UV = install --quiet --require-hashes --no-deps -r tools/uv.lock.txt
STEP = $(BIN)/python -m synergrasp.warm_up

# The set-up after installation (`python -m synergrasp.warm_up`): the compiled code (the solver's
# kernel, the closure's queries and steps), cached per user and named by its sources' hash (any
# checkout path loads it), and the bytecode of every module the workflow imports, written even
# where PYTHONDONTWRITEBYTECODE is set. Built once, not in every job, and while the venv is
# built: the kernel's compile, the longest step, starts as soon as what it imports is installed
# (KERNEL_NEEDS, each file checked against environment.lock's hashes by `-c`; the list is checked
# by tests/test_warm_up.py) and runs beside uv installing the rest; then the closure's compile and
# the imports' bytecode, which yield to the kernel's (nice). A failed install stops the kernel's.
KERNEL_NEEDS = numba llvmlite numpy scipy clarabel piqp pyyaml charset-normalizer cffi pycparser
AFTER_KERNEL = ( nice -n 10 $(STEP) imports & imports=$$!; nice -n 10 $(STEP) closure; rc=$$?; wait $$imports && exit $$rc )
$(BIN)/.installed: environment.lock pyproject.toml tools/uv.lock.txt
	$(PYTHON) -m venv --without-pip $(VENV)
	$(PYTHON) -m pip --python $(BIN)/python $(PIP_UV) 2>/dev/null || \
		{ $(BIN)/python -m ensurepip --default-pip >/dev/null && $(BIN)/python -m pip $(PIP_UV); }
	$(UV) -c environment.lock $(KERNEL_NEEDS)
	PYTHONPATH=src $(STEP) kernel & kernel=$$!; rc=0; \
	$(UV) --require-hashes -r environment.lock && $(UV) --no-build-isolation -e . && $(AFTER_KERNEL) || \
		{ rc=$$?; kill $$kernel 2>/dev/null; }; \
	wait $$kernel && exit $$rc
	touch $@

venv: $(BIN)/.installed

# Every later run compiles again only what changed (each compile loads its cache otherwise).
WARM_UP = nice -n 10 $(STEP) closure & closure=$$!; $(STEP) kernel && wait $$closure

warm-up: $(BIN)/.installed
	$(WARM_UP)

study: $(BIN)/.installed
	$(WARM_UP)
	$(BIN)/snakemake -j$(CORES) figures

# The report gathers the study's outputs: say so in one line when the study has not run yet.
report: $(BIN)/.installed
	@test -e results/tables/claims.csv || { echo "make report: the study has not run yet (no results/tables/claims.csv): run 'make study' first"; exit 1; }
	$(BIN)/snakemake --report results/report.html
	$(BIN)/snakemake --report results/report.zip

# pytest's exit code 5 (no test collected, e.g. a tier left empty by a selection) is no failure.
PYTEST = rc=0; $(BIN)/python -m pytest $(1) || rc=$$?; if [ $$rc -eq 5 ]; then echo "no tests collected"; exit 0; fi; exit $$rc

test: $(BIN)/.installed
	$(WARM_UP)
	$(call PYTEST,-m "not workflow and not browser")

# The end-to-end tier alone (what `make test` leaves out); CI runs `make test` then this.
test-workflow: $(BIN)/.installed
	$(WARM_UP)
	$(call PYTEST,-m workflow)

# The browser tier alone (what `make test` leaves out besides the workflow runs); CI runs it.
test-browser: $(BIN)/.installed
	$(call PYTEST,-m browser)

test-all: $(BIN)/.installed
	$(WARM_UP)
	$(call PYTEST,)

# The format is checked only once `make format` has been run on the tree (its marker file).
lint: $(BIN)/.installed
	$(BIN)/ruff check .
	@if [ -e .ruff-formatted ]; then $(BIN)/ruff format --check .; else echo "ruff format --check: skipped, the tree is not formatted yet (make format)"; fi
	$(BIN)/snakefmt --check Snakefile workflow
	$(BIN)/python tools/check_lint.py
	$(BIN)/lint-imports

format: $(BIN)/.installed
	$(BIN)/ruff format .
	touch .ruff-formatted

cluster-test: $(BIN)/.installed
	$(WARM_UP)
	tools/cluster_test.sh $(BIN)

# One core, as the targets are stated per core. Each benchmark's machine-read lines are recorded
# in benchmarks/results/ (tools/measurements.py record), then docs/measurements.md is rewritten
# from them. bench_study describes the last `make study` (nothing recorded if there was none).
RECORD = OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 $(BIN)/python tools/measurements.py record
bench: $(BIN)/.installed
	$(RECORD) compile -- $(BIN)/python benchmarks/bench_compile.py
	$(RECORD) gfo -- $(BIN)/python benchmarks/bench_gfo.py
	$(RECORD) pyramid -- $(BIN)/python benchmarks/bench_pyramid.py
	$(RECORD) set_size -- $(BIN)/python benchmarks/bench_set_size.py
	$(RECORD) closure -- $(BIN)/python benchmarks/bench_closure.py
	$(RECORD) search -- $(BIN)/python benchmarks/bench_search.py
	-$(RECORD) study_rate -- $(BIN)/python benchmarks/bench_study.py --root results
	-$(RECORD) inspector -- $(BIN)/python benchmarks/bench_inspector.py --results results
	-$(RECORD) plan_on_demand --timed -- $(BIN)/python benchmarks/bench_plan_on_demand.py --results results
	$(RECORD) scheduler -- $(BIN)/python benchmarks/bench_scheduler.py
	-$(RECORD) figure_imports -- $(BIN)/python benchmarks/bench_figure_imports.py --root results
	$(BIN)/python tools/measurements.py

# The default study timed from an empty results/ (move a previous one away first) and recorded
# with its jobs' costs in benchmarks/results/, then docs/measurements.md rewritten.
bench-study: $(BIN)/.installed
	@test -z "$$(ls results)" || { echo "make bench-study: results/ is not empty: move it away first"; exit 1; }
	$(WARM_UP)
	$(BIN)/python tools/measurements.py record study --timed -- $(BIN)/snakemake -j$(CORES) figures
	$(BIN)/python tools/measurements.py jobs results
	$(BIN)/python tools/measurements.py

# Regenerate the pinned, hashed lock from pyproject.toml (Python 3.11, Linux x86_64).
lock:
	$(PYTHON) -m pip install --quiet pip-tools
	$(PYTHON) -m piptools compile --quiet --generate-hashes --allow-unsafe --extra test --strip-extras --output-file environment.lock pyproject.toml

clean-venv:
	rm -rf $(VENV)
