# `cmake --install`: headers under include/geomint/ (so "integrators/integrator.hpp" stays the
# include path), the static libraries, the geomint program and the CMake package geomint
# (geomintConfig.cmake, version file, targets, FindCHOLMOD.cmake): docs/VERIFY.md "Verify your own
# integrator", docs/ARCHITECTURE.md "Installed package".
include(CMakePackageConfigHelpers)
set(GEOMINT_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/geomint)

foreach(folder problems integrators engines harness verify)
  install(DIRECTORY ${CMAKE_SOURCE_DIR}/${folder}/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/geomint/${folder}
          FILES_MATCHING PATTERN "*.hpp" PATTERN "*.def")
endforeach()

install(TARGETS geomint_problems geomint_integrators geomint_engines geomint_harness geomint_verify
        EXPORT geomintTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/geomint)
install(TARGETS geomint RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(EXPORT geomintTargets NAMESPACE geomint:: DESTINATION ${GEOMINT_CMAKE_DIR})

configure_package_config_file(${CMAKE_SOURCE_DIR}/cmake/geomintConfig.cmake.in
                              ${CMAKE_BINARY_DIR}/geomintConfig.cmake
                              INSTALL_DESTINATION ${GEOMINT_CMAKE_DIR})
# 0.x: every minor version may change the API, so a user's find_package(geomint 0.1) accepts 0.1.*
# only (SameMinorVersion); from 1.0 on SameMajorVersion would be the rule.
write_basic_package_version_file(${CMAKE_BINARY_DIR}/geomintConfigVersion.cmake
                                 VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_BINARY_DIR}/geomintConfig.cmake ${CMAKE_BINARY_DIR}/geomintConfigVersion.cmake
              ${CMAKE_SOURCE_DIR}/cmake/FindCHOLMOD.cmake
              ${CMAKE_SOURCE_DIR}/cmake/FindHYPRE.cmake
              ${CMAKE_SOURCE_DIR}/cmake/FindCMarkGFM.cmake
        DESTINATION ${GEOMINT_CMAKE_DIR})
# The licence (GPL-3.0-or-later, the build links GSL) and the citation file travel with the package.
install(FILES ${CMAKE_SOURCE_DIR}/LICENSE ${CMAKE_SOURCE_DIR}/CITATION.cff
        DESTINATION ${CMAKE_INSTALL_DOCDIR})
