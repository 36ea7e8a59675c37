# Thin wrapper around CMake/CTest (DESIGN.md §1). `make reproduce-figures` and `make test` each
# work as the very first command on a fresh Debian 12 machine: they install missing packages
# through scripts/install-deps.sh when run as root, and otherwise stop with the command to run.
BUILD_DIR ?= build
JOBS ?= $(shell nproc 2>/dev/null || echo 2)
SCENES ?= $(notdir $(patsubst %/,%,$(dir $(wildcard results/*/scene.toml))))

.PHONY: all deps configure build test test-all reproduce-figures reproduce-quick gates gate-quick bench \
        format clean mutation mutation-check

all: build

deps:
	@bash scripts/install-deps.sh --quiet

configure: deps
	@mkdir -p $(BUILD_DIR) && cmake -S . -B $(BUILD_DIR) -DCMAKE_BUILD_TYPE=Release > $(BUILD_DIR)/configure.log 2>&1 \
	  || (cat $(BUILD_DIR)/configure.log; exit 1)

build: configure
	@cmake --build $(BUILD_DIR) -j $(JOBS)

# Fast suites (< 10 minutes on 2 cores; long runs carry the CTest label "slow"), then what a
# user's CI does: the CI-sized scenes, gated.
test: build
	@cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS) -LE slow
	@$(MAKE) --no-print-directory gate-quick

# Everything: all suites (slow ones included) and the whole mutation list (make mutation).
test-all: build
	@cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS)
	@$(MAKE) --no-print-directory mutation

# Regenerates every committed scene: tables (CSV + Markdown) and gnuplot figures.
reproduce-figures: build
	@bash scripts/reproduce.sh $(BUILD_DIR)/geomint $(SCENES)

# CI-sized variant: quick_* settings, output under results/<scene>/quick/ (not committed).
reproduce-quick: build
	@QUICK=1 bash scripts/reproduce.sh $(BUILD_DIR)/geomint $(SCENES)

# Accuracy gates: the published claims (results/gates.toml) checked against the result tables;
# exits 1 and prints the failing rows when a number left its band. Run after reproduce-figures.
GATES ?= results/gates.toml
gates: build
	@$(BUILD_DIR)/geomint gate $(GATES) $(addprefix results/,$(SCENES))

# The CI-sized scenes (no figures), then the gates on them: each gate uses its quick_* bands
# where the quick run's numbers differ. This is what `make test` ends with.
gate-quick: build
	@QUICK=1 PLOTS=0 bash scripts/reproduce.sh $(BUILD_DIR)/geomint $(SCENES)
	@$(BUILD_DIR)/geomint gate $(GATES) $(addsuffix /quick,$(addprefix results/,$(SCENES)))

# Mutation testing (README.md, "Mutation testing"): applies each seeded bug of
# tests/mutation/mutants.toml to a scratch copy of the tracked sources in build-mutation/ (never to
# the working tree), rebuilds incrementally, runs the affected tests and quick scenes + gates, and
# fails unless every mutant is killed. MUTATION_ONLY=id,id, MUTATION_SHARD=i/N or
# MUTATION_BUDGET_MIN=M (rotating by commit) run a subset; the default is the whole list.
mutation: deps
	@/usr/bin/python3 scripts/mutation.py --jobs $(JOBS)

# Only checks that every mutant's `find` text still occurs exactly once (seconds, no build).
mutation-check:
	@/usr/bin/python3 scripts/mutation.py --check

bench: build
	@for b in $(BUILD_DIR)/bench/bench_*; do [ -x "$$b" ] && "$$b" --benchmark_min_time=0.2; done

format:
	@clang-format -i $$(git ls-files '*.cpp' '*.hpp')

clean:
	@rm -rf $(BUILD_DIR)
