# The CTest label `slow` (docs/TESTING.md "Testing", docs/DESIGN.md §7): tests that take long and repeat
# what cheaper tests already guard. `make test` runs `ctest -LE slow`; `make test-all` runs them
# too. Each entry is a GoogleTest filter pattern, with why it is slow and what still guards the
# same code in `make test`.
# Measured with `ctest -j2 --timeout 600` on the shared 2-core machine (load ~10, 2026-12-02):
# the whole suite took 231 s wall, 446 s summed over the tests; these three took 107 s of it.
set(GEOMINT_SLOW_TESTS
  # 10^4 implicit steps of a 128-dof spring network with 3 (Gauss) and 4 (Lobatto) stages and a
  # sparse LU per Newton iteration: 83 s and 15 s. The same momentum check runs in `make test`
  # for gauss:s=1, gauss (s=2), lobatto3ab (s=3) and s=2 through the same stage code; the order,
  # energy, reversibility and Kepler tests of gauss:s=3 and lobatto3ab:s=4 stay too.
  "*KeepsSpringNetMomentaOver10000Steps/gauss_s_3"
  "*KeepsSpringNetMomentaOver10000Steps/lobatto3ab_s_4"
  # kepler:e=0.99 against an RK4 run that must resolve the perihelion: 8.7 s. The same check
  # at e = 0, 0.6 and 0.9 stays (e = 0.999 skips it).
  "*ExactMatchesIndependentRk4/kepler_e_0p99"
  # 30 000 steps of the compositions over the constrained HP midpoint (3 and 9 KKT solves a step)
  # on the spinning pinned elastic bar: 8 s and 18 s here, 200 s and ~450 s under the sanitizers.
  # The same drift check runs for hp, hp:solver=newton and del on the bar, and for both
  # compositions on every pendulum and chain; the bar's constraint and reversibility checks of
  # both compositions stay.
  "*SymplecticMeansNoEnergyDrift/composition_base_hp_midpoint*elastic_bar*"
)

# The CTest label `nosan` (docs/TESTING.md "Sanitizers and fuzzing"): tests that `make
# test-sanitize` (ctest -LE 'slow|nosan' in the ASan + UBSan build, part of .ci/run) leaves out, and
# `make test` runs like any other. Each is a long-horizon repetition that takes from seconds to
# minutes under the sanitizers and runs no code that other tests of the same method, problem or
# scene do not run under them; or a committed-row check whose numbers clang's round-off moves.
# Each entry is a GoogleTest filter pattern with why it is left out and what still sanitises the code.
set(GEOMINT_NOSAN_TESTS
  # 10^4 spring-net steps of lobatto3ab and gauss at their default stage counts (17-29 s each);
  # their order, energy, reversibility and Kepler angular-momentum tests stay.
  "*KeepsSpringNetMomentaOver10000Steps/lobatto3ab"
  "*KeepsSpringNetMomentaOver10000Steps/gauss"
  # 10^4 spring-net steps of the implicit variants at non-default parameters (gauss:s=1,
  # lobatto3ab:s=2, del's and hp's alpha and rule variants, hp:solver=newton, implicit_midpoint:
  # 9-18 s each under the sanitizers at load 8, 2026-12-04): the step code of hp and del, whose
  # 10^4-step runs stay, at other coefficients; their order, energy and reversibility tests stay.
  "*KeepsSpringNetMomentaOver10000Steps/gauss_s_1"
  "*KeepsSpringNetMomentaOver10000Steps/lobatto3ab_s_2"
  "*KeepsSpringNetMomentaOver10000Steps/del_rule_*"
  "*KeepsSpringNetMomentaOver10000Steps/hp_alpha_*"
  "*KeepsSpringNetMomentaOver10000Steps/hp_solver_newton"
  "*KeepsSpringNetMomentaOver10000Steps/implicit_midpoint"
  # The constrained energy-drift runs of hp:solver=newton (19 tests, 116 s summed): the same
  # constrained KKT step as hp's, whose drift runs stay; its constraint and reversibility checks stay.
  "*ConstrainedPair.SymplecticMeansNoEnergyDrift/hp_solver_newton__*"
  # The energy-drift runs of del and hp on the pinned elastic bar (62-69 s each, the longest
  # tests): their constraint checks on that bar and their drift checks elsewhere stay.
  "*ConstrainedPair.SymplecticMeansNoEnergyDrift/hp__elastic_bar_clamp_pin*"
  "*ConstrainedPair.SymplecticMeansNoEnergyDrift/del__elastic_bar_clamp_pin*"
  # The constrained energy-drift runs on the re-parameterised variants of spherical_pendulum,
  # rigid_body, heavy_top, cartesian_pendulum and car_axis (~30 tests, ~210 s summed): the code of
  # the same problem's default variant at other values (rod_chain's variants change n and stay).
  "*ConstrainedPair.SymplecticMeansNoEnergyDrift/*__spherical_pendulum_*"
  "*ConstrainedPair.SymplecticMeansNoEnergyDrift/*__rigid_body_*"
  "*ConstrainedPair.SymplecticMeansNoEnergyDrift/*__heavy_top_*"
  "*ConstrainedPair.SymplecticMeansNoEnergyDrift/*__cartesian_pendulum_*"
  "*ConstrainedPair.SymplecticMeansNoEnergyDrift/*__car_axis_*"
  # The long-horizon energy and momentum runs of the compositions over the implicit and
  # constrained steps (hp_midpoint, implicit_midpoint, rattle: 3-9 nonlinear solves a step, 34
  # tests, 363 s summed): the composition code is the explicit compositions', the step code their
  # bases', both sanitised by the same checks; their order, reversibility and constraint checks stay.
  "*SymplecticMeansNoEnergyDrift/composition_base_hp_midpoint*"
  "*SymplecticMeansNoEnergyDrift/composition_base_implicit_midpoint*"
  "*SymplecticMeansNoEnergyDrift/composition_base_rattle*"
  "*SymplecticMeansBoundedEnergy/composition_base_hp_midpoint*"
  "*SymplecticMeansBoundedEnergy/composition_base_implicit_midpoint*"
  "*SymplecticMeansBoundedEnergy/composition_base_rattle*"
  "*SymplecticKeepsKeplerAngularMomentum/composition_base_hp_midpoint*"
  "*SymplecticKeepsKeplerAngularMomentum/composition_base_implicit_midpoint*"
  "*SymplecticKeepsKeplerAngularMomentum/composition_base_rattle*"
  "*KeepsSpringNetMomentaOver10000Steps/composition_base_hp_midpoint*"
  "*KeepsSpringNetMomentaOver10000Steps/composition_base_implicit_midpoint*"
  "*KeepsSpringNetMomentaOver10000Steps/composition_base_rattle*"
  # Every check of the compositions over the constrained HP midpoint on car_axis, and over RATTLE
  # and the constrained HP midpoint on rigid_body and heavy_top (30 tests, 195 s summed): rattle,
  # hp and del keep their checks on those problems.
  "*ConstrainedPair.*/composition_base_hp_midpoint*__car_axis*"
  "*ConstrainedPair.*/composition_base_*__rigid_body*"
  "*ConstrainedPair.*/composition_base_*__heavy_top*"
  # The bounded-energy and Kepler angular-momentum runs of gauss and lobatto3ab at their
  # non-default stage counts (their order tests stay).
  "*SymplecticMeansBoundedEnergy/gauss_s_1"
  "*SymplecticMeansBoundedEnergy/gauss_s_3"
  "*SymplecticMeansBoundedEnergy/lobatto3ab_s_2"
  "*SymplecticMeansBoundedEnergy/lobatto3ab_s_4"
  "*SymplecticKeepsKeplerAngularMomentum/gauss_s_1"
  "*SymplecticKeepsKeplerAngularMomentum/gauss_s_3"
  "*SymplecticKeepsKeplerAngularMomentum/lobatto3ab_s_2"
  "*SymplecticKeepsKeplerAngularMomentum/lobatto3ab_s_4"
  # The two longest single tests left (38 s and 18 s): the stability search of every registered
  # method (the per-method stability tests sanitise the searches) and the midpoint force-slot
  # drift runs (the force-slot momentum tests sanitise the slot code).
  "Stability.EveryMethodPredictsItsLimitOrSaysWhyNot"
  "ForceSlots.MidpointEvaluationDriftsInMinusAndPlusAtFirstOrder"
  # Committed rows that clang's round-off moves beyond the tables' printed digits: stiff VDPOL
  # (gsl_rk4imp's error in the 4th digit), rigid_body (tennis-racket flips near the separatrix:
  # lie_poisson:order=4's error_final 1.11949350e-5 vs 1.11949627e-5), chaos (chaotic orbits),
  # structure (map defects at the finite-difference floor), inexact_solves and work_stability
  # (Newton stops decided at the rounding level); and work_precision(_full), whose every method
  # the other scenes' rows re-run. The gcc suite re-runs all of them.
  "*CheapRowsReproduce/work_precision"
  "*CheapRowsReproduce/work_precision_full"
  "*CheapRowsReproduce/stiff_first_order"
  "*CheapRowsReproduce/rigid_body"
  "*CheapRowsReproduce/chaos"
  "*CheapRowsReproduce/structure"
  "*CheapRowsReproduce/inexact_solves"
  "*CheapRowsReproduce/work_stability"
)

# gtest_discover_tests for one test executable, three times: its slow tests (GEOMINT_SLOW_TESTS)
# with the label `slow`, its sanitizer skips (GEOMINT_NOSAN_TESTS, unless slow) with the label
# `nosan`, the others with `fast`. Takes gtest_discover_tests' DISCOVERY_TIMEOUT and PROPERTIES.
# Tests write scratch files under std::filesystem::temp_directory_path(); TMPDIR points it into
# this build tree so that two builds testing at the same time (clones, CI and a developer) never
# share /tmp/geomint_* folders, and each test process makes its own folder in there
# (tests/test_main.cpp), so tests that ctest runs at the same time never share one either.
file(MAKE_DIRECTORY ${CMAKE_BINARY_DIR}/test-tmp)

# The filters of the `fast` tests (`make test-sanitize`) and of all but the `slow` ones (`make
# test`), for scripts/gtest-shards.py, which runs them a shard of an executable at a time instead
# of a process per test.
list(JOIN GEOMINT_SLOW_TESTS ":" geomint_slow_filter)
list(JOIN GEOMINT_NOSAN_TESTS ":" geomint_nosan_filter)
file(WRITE ${CMAKE_BINARY_DIR}/gtest-fast-filter.txt "-${geomint_slow_filter}:${geomint_nosan_filter}\n")
file(WRITE ${CMAKE_BINARY_DIR}/gtest-notslow-filter.txt "-${geomint_slow_filter}\n")

function(geomint_discover_tests target)
  cmake_parse_arguments(PARSE_ARGV 1 ARG "" "DISCOVERY_TIMEOUT" "PROPERTIES")
  list(APPEND ARG_PROPERTIES ENVIRONMENT "TMPDIR=${CMAKE_BINARY_DIR}/test-tmp")
  set(common ${target})
  if(ARG_DISCOVERY_TIMEOUT)
    list(APPEND common DISCOVERY_TIMEOUT ${ARG_DISCOVERY_TIMEOUT})
  endif()
  list(JOIN GEOMINT_SLOW_TESTS ":" slow_filter)
  list(JOIN GEOMINT_NOSAN_TESTS ":" nosan_filter)
  gtest_discover_tests(${common} TEST_FILTER "-${slow_filter}:${nosan_filter}"
                       PROPERTIES ${ARG_PROPERTIES} LABELS fast)
  gtest_discover_tests(${common} TEST_FILTER "${nosan_filter}-${slow_filter}"
                       PROPERTIES ${ARG_PROPERTIES} LABELS nosan)
  gtest_discover_tests(${common} TEST_FILTER "${slow_filter}"
                       PROPERTIES ${ARG_PROPERTIES} LABELS slow)
endfunction()
