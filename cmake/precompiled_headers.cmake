# Precompiled headers for the cold build (docs/TESTING.md "Fresh clone"): one header per family of
# targets with the same compile flags, compiled once and reused by the family's other targets.
# Only third-party and standard headers go in, so editing a geomint header never rebuilds a PCH.
#
#   geomint_use_pch(<target> LIBRARY)  the static libraries (position-independent, no GoogleTest)
#   geomint_use_pch(<target> TESTS)    the GoogleTest executables and geomint_test_main
#
# The first target of a family compiles the header, later ones reuse it (REUSE_FROM), which needs
# the same flags: targets whose flags differ (odeint.cpp's -std=c++17, the ThreadSanitizer test,
# the Python module) stay out. Off (GEOMINT_PCH=OFF, and always in the clang sanitizer and
# fuzzing builds, whose libraries differ in their -fsanitize flags): every target compiles as before.
option(GEOMINT_PCH "Precompile Eigen, fmt, GoogleTest and standard headers (gcc builds)" ON)
if(GEOMINT_PCH AND CMAKE_CXX_COMPILER_ID STREQUAL "GNU" AND NOT GEOMINT_SANITIZE)
  set(GEOMINT_PCH_ACTIVE ON)
else()
  set(GEOMINT_PCH_ACTIVE OFF)
endif()

set(GEOMINT_PCH_LIBRARY_HEADERS
    <algorithm> <array> <cmath> <cstddef> <cstdint> <filesystem> <fstream> <functional> <limits>
    <map> <memory> <numbers> <optional> <set> <sstream> <stdexcept> <string> <string_view>
    <utility> <vector> <Eigen/Dense> <Eigen/SparseCore> <fmt/format.h>)
set(GEOMINT_PCH_TESTS_HEADERS ${GEOMINT_PCH_LIBRARY_HEADERS} <gtest/gtest.h>)

# ccache caches a compile that uses a PCH only with this sloppiness (`man ccache`, "Precompiled
# headers"): it cannot see #defines or __TIME__ through the PCH, and the .gch is always a freshly
# written file. Without it every such compile is a miss, and a second build recompiles everything.
# No source uses __DATE__/__TIME__. ccache 4.7 (Debian 12) takes no settings on its command line,
# hence `env` in front of it.
if(GEOMINT_PCH_ACTIVE AND CMAKE_CXX_COMPILER_LAUNCHER)
  list(GET CMAKE_CXX_COMPILER_LAUNCHER 0 geomint_launcher)
  get_filename_component(geomint_launcher "${geomint_launcher}" NAME)
  if(geomint_launcher STREQUAL "ccache")
    set(geomint_sloppiness pch_defines,time_macros,include_file_mtime,include_file_ctime)
    if(DEFINED ENV{CCACHE_SLOPPINESS} AND NOT "$ENV{CCACHE_SLOPPINESS}" STREQUAL "")
      string(PREPEND geomint_sloppiness "$ENV{CCACHE_SLOPPINESS},")
    endif()
    set(CMAKE_CXX_COMPILER_LAUNCHER env CCACHE_SLOPPINESS=${geomint_sloppiness}
                                    ${CMAKE_CXX_COMPILER_LAUNCHER})
  endif()
endif()

function(geomint_use_pch target family)
  if(NOT GEOMINT_PCH_ACTIVE)
    return()
  endif()
  if(NOT family MATCHES "^(LIBRARY|TESTS)$")
    message(FATAL_ERROR "geomint_use_pch(${target} ${family}): the family is LIBRARY or TESTS")
  endif()
  get_property(host GLOBAL PROPERTY GEOMINT_PCH_HOST_${family})
  if(host)
    target_precompile_headers(${target} REUSE_FROM ${host})
  else()
    set_property(GLOBAL PROPERTY GEOMINT_PCH_HOST_${family} ${target})
    target_precompile_headers(${target} PRIVATE ${GEOMINT_PCH_${family}_HEADERS})
    # The header's own include paths and definitions, for a host that does not use them itself.
    target_link_libraries(${target} PRIVATE Eigen3::Eigen fmt::fmt)
  endif()
endfunction()

# Every GoogleTest executable defined in <directories> (those linking geomint_test_main), after
# geomint_test_main itself: new test executables get the PCH without a line of their own. Skips
# targets with compile options of their own (pool_tsan_test's -fsanitize=thread -O1), which a PCH
# compiled without them would not fit.
function(geomint_use_pch_for_tests)
  if(NOT GEOMINT_PCH_ACTIVE OR NOT TARGET geomint_test_main)
    return()
  endif()
  geomint_use_pch(geomint_test_main TESTS)
  get_target_property(host_options geomint_test_main COMPILE_OPTIONS)
  foreach(directory IN LISTS ARGN)
    get_property(targets DIRECTORY ${directory} PROPERTY BUILDSYSTEM_TARGETS)
    foreach(target IN LISTS targets)
      get_target_property(type ${target} TYPE)
      get_target_property(libraries ${target} LINK_LIBRARIES)
      get_target_property(options ${target} COMPILE_OPTIONS)
      if(type STREQUAL "EXECUTABLE" AND "geomint_test_main" IN_LIST libraries AND
       options STREQUAL host_options)
        geomint_use_pch(${target} TESTS)
      endif()
    endforeach()
  endforeach()
endfunction()
