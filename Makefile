# Thin wrapper around CMake/CTest (docs/DESIGN.md §1). `make reproduce-figures` and `make test` each
# work as the very first command on a fresh Debian 12 machine: they install missing packages
# through scripts/install-deps.sh when run as root, and otherwise stop with the command to run.
BUILD_DIR ?= build
JOBS ?= $(shell nproc 2>/dev/null || echo 2)
SCENES ?= $(notdir $(patsubst %/,%,$(dir $(wildcard results/*/scene.toml))))

.PHONY: all deps configure build test test-all reproduce-figures reproduce-quick gates gate-quick bench \
        format clean mutation mutation-check sanitize-build test-sanitize fuzz readme-tables \
        report report-quick \
        test-cluster test-external

all: build

deps:
	@bash scripts/install-deps.sh --quiet

configure: deps
	@mkdir -p $(BUILD_DIR) && cmake -S . -B $(BUILD_DIR) -DCMAKE_BUILD_TYPE=Release > $(BUILD_DIR)/configure.log 2>&1 \
	  || (cat $(BUILD_DIR)/configure.log; exit 1)

build: configure
	@cmake --build $(BUILD_DIR) -j $(JOBS)

# Fast suites (< 10 minutes on 2 cores; long runs carry the CTest label "slow"), then what a
# user's CI does: the CI-sized scenes, gated; then geomint installed into a temporary prefix and
# examples/external_method built and tested against it (docs/VERIFY.md "Verify your own integrator").
test: build
	@cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS) -LE slow
	@$(MAKE) --no-print-directory gate-quick
	@$(MAKE) --no-print-directory report-quick SITE=$(BUILD_DIR)/site-quick
	@$(MAKE) --no-print-directory test-external

test-external: build
	@JOBS=$(JOBS) bash scripts/test-external.sh $(BUILD_DIR)

# Sweeps on a real Slurm (docs/CLUSTER.md "Running on a cluster"): as root, installs slurmctld, slurmd and
# munge, starts them on this machine, runs a scene through `geomint slurm --submit` in 8 shards,
# merges, times, injects a failing shard and resubmits it; stops every daemon it started.
test-cluster: build
	@bash scripts/test-cluster.sh $(BUILD_DIR)/geomint

# Everything: slow tests too, the sanitizer suite, the fuzzers (FUZZ_SECONDS each) and the whole
# mutation list.
test-all: build
	@cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS)
	@$(MAKE) --no-print-directory test-sanitize
	@$(MAKE) --no-print-directory fuzz
	@$(MAKE) --no-print-directory mutation

# Sanitizer build (docs/TESTING.md "Sanitizers and fuzzing"): clang, -fsanitize=address,undefined with
# UB fatal, in its own directory; it also builds the libFuzzer targets of fuzz/. No benchmarks.
SAN_DIR ?= build-asan
SAN_CXX ?= clang++
SAN_ENV = ASAN_OPTIONS=detect_leaks=1:strict_string_checks=1:check_initialization_order=1 \
          UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
sanitize-build: deps
	@mkdir -p $(SAN_DIR) && cmake -S . -B $(SAN_DIR) -DCMAKE_BUILD_TYPE=Release \
	  -DCMAKE_CXX_COMPILER=$(SAN_CXX) -DGEOMINT_BUILD_BENCH=OFF -DGEOMINT_BUILD_FUZZ=ON \
	  > $(SAN_DIR)/configure.log 2>&1 || (cat $(SAN_DIR)/configure.log; exit 1)
	@$(SAN_ENV) cmake --build $(SAN_DIR) -j $(JOBS)

# The fast suite under ASan + UBSan (what `.ci/run` runs after `make test`): any report fails.
# Left out (SAN_EXCLUDE): long-horizon repetitions that take 1-6 minutes each under the
# sanitizers and run no code that the other tests of the same method, problem or scene do not
# run: 10^4 spring-net steps of lobatto3ab:s=4 and gauss:s=3 (their order, energy,
# reversibility and Kepler tests stay), the committed work_precision rows (every method is
# re-run by the other scenes' rows), kepler:e=0.99 against an RK4 reference (the other Kepler
# eccentricities stay) and the energy-drift runs of the 6th-order compositions over the
# constrained steps (9 KKT or RATTLE solves a step, 460 s summed under the sanitizers; the same
# check runs for the 4th-order compositions, and the 6th-order ones keep their constraint and
# reversibility checks), and the compositions over the constrained HP midpoint on car_axis
# (0.2-0.6 s each in Release; hp and del keep their car_axis checks), and the compositions over
# RATTLE and the constrained HP midpoint on rigid_body (30 more tests, 195 s summed under the
# sanitizers; rattle, hp and del keep their rigid_body checks). The committed
# stiff_first_order rows are left out because clang's build moves gsl_rk4imp's error on stiff
# VDPOL in the 4th digit (the gcc suite re-runs them). Three of them also carry the label `slow`
# (tests/slow_tests.cmake), which -LE slow leaves out in any case; `make test-sanitize
# SAN_EXCLUDE=` runs everything else. The report site's checks (tidy, headless Chromium) and the
# docs checks run Python and a browser, not sanitised code (harness/report_test.cpp runs the report
# writer under the sanitizers). A parameterised test's ctest name goes on with
# "  # GetParam() = ...", so a pattern ends with "( |$$)", never with a bare "$$".
SAN_EXCLUDE ?= KeepsSpringNetMomentaOver10000Steps/(lobatto3ab_s_4|gauss_s_3)( |$$)|CheapRowsReproduce/(work_precision|stiff_first_order)( |$$)|ExactMatchesIndependentRk4/kepler_e_0p99( |$$)|ConstrainedPair[.]SymplecticMeansNoEnergyDrift/composition_base_(hp_midpoint|rattle)_scheme_kahan_li6__|ConstrainedPair[.].*/composition_base_hp_midpoint.*__car_axis|ConstrainedPair[.].*/composition_base_.*__(rigid_body|heavy_top)|^ReportSite[.]|^docs[.]
test-sanitize: sanitize-build
	@cd $(SAN_DIR) && $(SAN_ENV) ctest --output-on-failure -j $(JOBS) -LE slow \
	  $(if $(SAN_EXCLUDE),-E '$(SAN_EXCLUDE)')

# Each fuzzer for FUZZ_SECONDS on its committed corpus (fuzz/corpus/<target>/); fails on a finding.
FUZZ_SECONDS ?= 60
fuzz: sanitize-build
	@$(SAN_ENV) bash scripts/fuzz.sh $(SAN_DIR) $(FUZZ_SECONDS)

# Regenerates every committed scene: tables (CSV + Markdown) and gnuplot figures; then the
# scaling figure from the benchmarks' reduced sizes (results/scaling/, scripts/scaling.sh).
reproduce-figures: build
	@bash scripts/reproduce.sh $(BUILD_DIR)/geomint $(SCENES)
	@bash scripts/scaling.sh $(BUILD_DIR)
	@$(MAKE) --no-print-directory report

# The results site (docs/REPORT.md): site/index.html and one page per scene, from the committed
# tables and results/gates.toml; opens from file://. report-quick: the CI-sized tables of
# results/<scene>/quick/ (after gate-quick; `make test` writes it to $(BUILD_DIR)/site-quick).
SITE ?= site
report: build
	@$(BUILD_DIR)/geomint report --results results --gates $(GATES) --out $(SITE)

report-quick: build
	@$(BUILD_DIR)/geomint report --quick --results results --gates $(GATES) --out $(SITE)

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

# Mutation testing (docs/TESTING.md, "Mutation testing"): applies each seeded bug of
# tests/mutation/mutants.toml to a scratch copy of the tracked sources in build-mutation/ (never to
# the working tree), rebuilds incrementally, runs the affected tests and quick scenes + gates, and
# fails unless every mutant is killed and, on the whole list, the gates alone kill at least 80% of
# the gate-visible mutants (docs/TESTING.md "The gates' own figure"). MUTATION_ONLY=id,id,
# MUTATION_SHARD=i/N or MUTATION_BUDGET_MIN=M (rotating by commit) run a subset; the default is
# the whole list. MUTATION_GATES_ONLY=1 measures only the gates' figure (no tests, minutes).
mutation: deps
	@/usr/bin/python3 scripts/mutation.py --jobs $(JOBS)

# Only checks that every mutant's `find` text still occurs exactly once (seconds, no build).
mutation-check:
	@/usr/bin/python3 scripts/mutation.py --check

# Rewrites the method table of docs/METHODS.md and the problem table of docs/PROBLEMS.md (between
# the <!-- methods:begin/end --> and <!-- problems:begin/end --> markers) with
# `geomint list --markdown`; the test Readme.TablesAreTheOutputOfListMarkdown fails until they agree.
readme-tables: build
	@/usr/bin/python3 scripts/readme_tables.py $(BUILD_DIR)/geomint docs/METHODS.md docs/PROBLEMS.md

bench: build
	@for b in $(BUILD_DIR)/bench/bench_*; do [ -x "$$b" ] && "$$b" --benchmark_min_time=0.2; done

format:
	@clang-format -i $$(git ls-files '*.cpp' '*.hpp')

clean:
	@rm -rf $(BUILD_DIR)
