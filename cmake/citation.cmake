# The one source of how to cite geomint: CITATION.cff (written by `make citation`, checked by
# ctest citation.committed) and the BibTeX of the site's "Cite this table" blocks (the generated
# citation_info.hpp of harness/CMakeLists.txt) are both made from these values. Edit here.
# The version is project(VERSION) in CMakeLists.txt; the repository URL is the cache variable
# GEOMINT_REPOSITORY_URL (empty: no URL is written anywhere).

set(GEOMINT_CITATION_TITLE
    "geomint: a verification and benchmark suite for geometric time integrators")
# One entry per author: "Family, Given" for a person, any other text for an organisation.
set(GEOMINT_CITATION_AUTHORS "The geomint maintainers")
set(GEOMINT_CITATION_LICENSE "GPL-3.0-or-later")
set(GEOMINT_CITATION_MESSAGE [=[
If you use geomint or the numbers it publishes, please cite it as below, with the version and
git SHA that the CSV provenance lines of your results name.]=])
set(GEOMINT_CITATION_ABSTRACT [=[
geomint implements the variational and Hamilton–Pontryagin integrators of Kharevych et al.
(SCA 2006) next to classic and library integrators (RK4, Newmark, SUNDIALS, GSL,
Boost.Odeint), runs them over a catalogue of mechanical problems, and publishes measured,
gated tables and figures of energy and momentum behaviour, convergence order, cost and
stability.]=])
set(GEOMINT_CITATION_KEYWORDS "geometric integration" "variational integrators"
    "symplectic integrators" "Hamilton–Pontryagin" "benchmark" "verification")
# CFF `references:` entries, as YAML (copied as they are).
set(GEOMINT_CITATION_REFERENCES [=[
  - type: conference-paper
    title: "Geometric, Variational Integrators for Computer Animation"
    authors:
      - family-names: Kharevych
        given-names: Liliya
      - family-names: Yang
        given-names: Weiwei
      - family-names: Tong
        given-names: Yiying
      - family-names: Kanso
        given-names: Eva
      - family-names: Marsden
        given-names: Jerrold E.
      - family-names: Schröder
        given-names: Peter
      - family-names: Desbrun
        given-names: Mathieu
    collection-title: "Proceedings of the 2006 ACM SIGGRAPH/Eurographics Symposium on Computer Animation (SCA 2006)"
    year: 2006]=])

# A URL is written into YAML and BibTeX as it is: refuse one that could break either.
function(geomint_check_repository_url url)
  if(url AND NOT url MATCHES "^https?://[^ \t\"'{}\\\\]+$")
    message(FATAL_ERROR "GEOMINT_REPOSITORY_URL='${url}' is not an http(s) URL without spaces, "
                        "quotes, braces or backslashes")
  endif()
endfunction()

# `text` as a YAML double-quoted scalar.
function(_geomint_yaml_quoted out text)
  string(REPLACE "\\" "\\\\" text "${text}")
  string(REPLACE "\"" "\\\"" text "${text}")
  set(${out} "\"${text}\"" PARENT_SCOPE)
endfunction()

# `text` (lines) as an indented YAML folded block body.
function(_geomint_yaml_block out text)
  string(REPLACE "\n" "\n  " text "${text}")
  set(${out} "  ${text}" PARENT_SCOPE)
endfunction()

# The text of CITATION.cff for `version` and `url` ("" leaves out repository-code).
function(geomint_citation_cff out version url)
  geomint_check_repository_url("${url}")
  _geomint_yaml_block(message "${GEOMINT_CITATION_MESSAGE}")
  _geomint_yaml_block(abstract "${GEOMINT_CITATION_ABSTRACT}")
  _geomint_yaml_quoted(title "${GEOMINT_CITATION_TITLE}")
  set(text "# How to cite geomint. Generated from cmake/citation.cmake by `make citation`; edit that\n")
  string(APPEND text "# file, not this one (ctest citation.committed compares the two).\n")
  string(APPEND text "cff-version: 1.2.0\nmessage: >-\n${message}\ntitle: ${title}\n")
  string(APPEND text "type: software\nversion: \"${version}\"\n")
  string(APPEND text "license: ${GEOMINT_CITATION_LICENSE}\n")
  if(url)
    string(APPEND text "repository-code: \"${url}\"\n")
  endif()
  string(APPEND text "authors:\n")
  foreach(author IN LISTS GEOMINT_CITATION_AUTHORS)
    if(author MATCHES "^([^,]+), (.+)$")
      _geomint_yaml_quoted(family "${CMAKE_MATCH_1}")
      _geomint_yaml_quoted(given "${CMAKE_MATCH_2}")
      string(APPEND text "  - family-names: ${family}\n    given-names: ${given}\n")
    else()
      _geomint_yaml_quoted(name "${author}")
      string(APPEND text "  - name: ${name}\n")
    endif()
  endforeach()
  string(APPEND text "abstract: >-\n${abstract}\nkeywords:\n")
  foreach(keyword IN LISTS GEOMINT_CITATION_KEYWORDS)
    string(APPEND text "  - ${keyword}\n")
  endforeach()
  string(APPEND text "references:\n${GEOMINT_CITATION_REFERENCES}\n")
  set(${out} "${text}" PARENT_SCOPE)
endfunction()

# `text` as a C++ string literal.
function(_geomint_cxx_quoted out text)
  string(REPLACE "\\" "\\\\" text "${text}")
  string(REPLACE "\"" "\\\"" text "${text}")
  set(${out} "\"${text}\"" PARENT_SCOPE)
endfunction()

# The text of the generated citation_info.hpp (what the site's BibTeX cites) for `url`.
function(geomint_citation_header out url)
  geomint_check_repository_url("${url}")
  _geomint_cxx_quoted(title "${GEOMINT_CITATION_TITLE}")
  _geomint_cxx_quoted(repository "${url}")
  set(authors "")
  foreach(author IN LISTS GEOMINT_CITATION_AUTHORS)
    _geomint_cxx_quoted(quoted "${author}")
    string(APPEND authors "${quoted}, ")
  endforeach()
  set(${out} "// Generated from cmake/citation.cmake at configure time; do not edit.
#pragma once

namespace geomint::citation {
inline constexpr const char* kTitle = ${title};
// \"Family, Given\" for a person, any other text for an organisation.
inline constexpr const char* kAuthors[] = {${authors}};
// GEOMINT_REPOSITORY_URL; \"\" when none is configured.
inline constexpr const char* kRepositoryUrl = ${repository};
}  // namespace geomint::citation
" PARENT_SCOPE)
endfunction()
