# Writes or checks CITATION.cff from cmake/citation.cmake (cmake -P): the `citation` target
# writes the committed file, ctest citation.committed checks it, the citation tests write one
# with a URL into a scratch folder. Inputs: VERSION, REPOSITORY_URL (may be empty), and OUTPUT
# (write it) or CHECK (fail, naming the fix, unless that file holds exactly the generated text).
include(${CMAKE_CURRENT_LIST_DIR}/../cmake/citation.cmake)
geomint_citation_cff(cff "${VERSION}" "${REPOSITORY_URL}")
if(OUTPUT)
  file(WRITE ${OUTPUT} "${cff}")
elseif(CHECK)
  file(READ ${CHECK} committed)
  if(NOT committed STREQUAL cff)
    message(FATAL_ERROR "${CHECK} is not what cmake/citation.cmake generates (version "
                        "${VERSION}, repository URL '${REPOSITORY_URL}'): after editing "
                        "cmake/citation.cmake or the version, run `make citation` and commit it")
  endif()
else()
  message(FATAL_ERROR "scripts/citation.cmake: give -DOUTPUT=<file> or -DCHECK=<file>")
endif()
