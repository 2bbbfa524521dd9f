# haptic_dob: the two commands of the README, plus a few helpers.
#   make demo       create .venv, install, run OL / CL / DOB at 800 N/m through the node graph
#   make test       install if needed, run the whole test suite (two phases, see below)
#   make reproduce  the thesis's experiments through the node graph, report in report/
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed
# files copied into the environment at install time (ament index, package.xml, shims, config)
INSTALLED_DATA := $(shell find ros config -type f 2>/dev/null)

.PHONY: demo test reproduce install lint bench lock clean

demo: $(STAMP)
	@$(BIN)/haptic-experiment --quick --out build/demo

reproduce: $(STAMP)
	@$(BIN)/haptic-experiment --out report

# Three phases, by directory: test/unit/ (no DDS, no node processes) on every CPU
# (pytest-xdist, at most 4 workers); then test/graph/ (marked dds by test/conftest.py), bounded
# in samples, two at a time (one on one CPU), each on a domain id of its worker's; then the ones
# whose premise is real time (test/graph/realtime/, marked alone) one at a time, alone.
# Every phase always runs; the exit code is the worst.
# CI= : pytest prints whole assertion diffs when CI is set; one failure's diff of a 5000-sample
# list could then hide every other failure in a truncated log
TEST_JOBS ?= $(shell $(PYTHON) -c "import os; print(min(4, len(os.sched_getaffinity(0))))")
DDS_JOBS ?= $(shell $(PYTHON) -c "import os; print(min(2, len(os.sched_getaffinity(0))))")
PYTEST := CI= BUILD_NUMBER= $(BIN)/python -m pytest -q -rs -p no:cacheprovider
test: $(STAMP)
	@status=0; \
	$(PYTEST) -m "not dds" -n $(TEST_JOBS) || status=$$?; \
	$(PYTEST) -m "dds and not alone" -n $(DDS_JOBS) || status=$$?; \
	$(PYTEST) -m alone || status=$$?; \
	exit $$status

install: $(STAMP)

$(STAMP): pyproject.toml constraints.txt $(INSTALLED_DATA)
	@test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	@echo "installing haptic_dob into $(VENV) (first run takes about a minute)"
	@PIP_CONSTRAINT=$(CURDIR)/constraints.txt $(BIN)/python -m pip install -qq \
		--disable-pip-version-check -e '.[dev,arms]'
	@touch $@

lint: $(STAMP)
	@$(BIN)/ruff check src test scripts
	@$(BIN)/ruff format --check src test scripts
	@$(BIN)/mypy

# Measure BENCHMARKS.md's marked tables on this machine and rewrite their rows in place
# (BENCH_ARGS: --only NAME..., --note TEXT, --print; scripts/bench_tables.py --help)
bench: $(STAMP)
	@$(BIN)/python scripts/bench_tables.py $(BENCH_ARGS)

# Re-resolve the dependency set and rewrite constraints.txt (review the diff).
lock:
	@$(PYTHON) -m venv /tmp/haptic-dob-lock && /tmp/haptic-dob-lock/bin/pip install -qq \
		--dry-run --ignore-installed --report /tmp/haptic-dob-lock.json -e '.[dev,arms]'
	@$(PYTHON) scripts/write_constraints.py /tmp/haptic-dob-lock.json constraints.txt

clean:
	rm -rf $(VENV) build dist .pytest_cache .ruff_cache
