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

# gtest_discover_tests for one test executable, twice: its slow tests (GEOMINT_SLOW_TESTS) with
# the label `slow`, the others without. Takes gtest_discover_tests' DISCOVERY_TIMEOUT and
# PROPERTIES.
# Tests write scratch files under std::filesystem::temp_directory_path(); TMPDIR points it into
# this build tree so that two builds testing at the same time (clones, CI and a developer) never
# share /tmp/geomint_* folders.
file(MAKE_DIRECTORY ${CMAKE_BINARY_DIR}/test-tmp)

function(geomint_discover_tests target)
  cmake_parse_arguments(PARSE_ARGV 1 ARG "" "DISCOVERY_TIMEOUT" "PROPERTIES")
  list(APPEND ARG_PROPERTIES ENVIRONMENT "TMPDIR=${CMAKE_BINARY_DIR}/test-tmp")
  set(common ${target})
  if(ARG_DISCOVERY_TIMEOUT)
    list(APPEND common DISCOVERY_TIMEOUT ${ARG_DISCOVERY_TIMEOUT})
  endif()
  if(NOT GEOMINT_SLOW_TESTS)
    gtest_discover_tests(${common} PROPERTIES ${ARG_PROPERTIES} LABELS fast)
    return()
  endif()
  list(JOIN GEOMINT_SLOW_TESTS ":" slow_filter)
  gtest_discover_tests(${common} TEST_FILTER "-${slow_filter}"
                       PROPERTIES ${ARG_PROPERTIES} LABELS fast)
  gtest_discover_tests(${common} TEST_FILTER "${slow_filter}"
                       PROPERTIES ${ARG_PROPERTIES} LABELS slow)
endfunction()
