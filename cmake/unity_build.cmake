# Unity builds of the GoogleTest executables for the cold build (docs/TESTING.md "Fresh clone"):
# CMake compiles a target's sources in batches, each batch one translation unit, so the headers,
# GoogleTest's and Eigen's templates are parsed and instantiated once per batch, not once per file.
#
#   geomint_unity_build(<target>...)   the multi-file test executables
#
# Each test file keeps its helpers in a namespace named after the file (geomint::<file stem>), so
# that files of one batch never clash. Option GEOMINT_UNITY_BUILD (on by default);
# GEOMINT_UNITY_BATCH_SIZE files per batch, chosen by measurement on 2 cores (docs/TESTING.md).
option(GEOMINT_UNITY_BUILD "Compile the test executables' sources in batches (unity build)" ON)
set(GEOMINT_UNITY_BATCH_SIZE 8 CACHE STRING "Test sources per unity batch")

function(geomint_unity_build)
  if(NOT GEOMINT_UNITY_BUILD)
    return()
  endif()
  foreach(target IN LISTS ARGN)
    if(TARGET ${target})
      set_target_properties(${target} PROPERTIES UNITY_BUILD ON
                                                 UNITY_BUILD_BATCH_SIZE ${GEOMINT_UNITY_BATCH_SIZE})
    endif()
  endforeach()
endfunction()

#   geomint_unity_group(<target> <group> <source>...)   library sources compiled as one unit
#
# For a library's files that share one expensive header and nothing else (the command-line verbs
# of harness/cli/, each of which parses CLI11, header-only: 3.7 s of its 4.5 s of CPU); the
# target's other sources stay one translation unit each. Their file-local helpers must not clash.
function(geomint_unity_group target group)
  if(NOT GEOMINT_UNITY_BUILD)
    return()
  endif()
  set_target_properties(${target} PROPERTIES UNITY_BUILD ON UNITY_BUILD_MODE GROUP)
  set_source_files_properties(${ARGN} TARGET_DIRECTORY ${target} PROPERTIES UNITY_GROUP ${group})
endfunction()
