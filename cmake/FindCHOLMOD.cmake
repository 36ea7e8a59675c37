# Finds Debian's SuiteSparse CHOLMOD (libsuitesparse-dev) and METIS (libmetis-dev) for the Newton
# solver's linear_solver=cholmod|ldlt_metis (docs/METHODS.md "Scale"); installed next to geomintConfig.cmake
# so an installed geomint finds them again. Defines the imported target CHOLMOD::CHOLMOD.
include(FindPackageHandleStandardArgs)
find_path(CHOLMOD_INCLUDE_DIR cholmod.h PATH_SUFFIXES suitesparse)
find_library(CHOLMOD_LIBRARY cholmod)
find_library(SUITESPARSECONFIG_LIBRARY suitesparseconfig)
find_path(METIS_INCLUDE_DIR metis.h)
find_library(METIS_LIBRARY metis)
find_package_handle_standard_args(CHOLMOD REQUIRED_VARS CHOLMOD_LIBRARY CHOLMOD_INCLUDE_DIR
                                  SUITESPARSECONFIG_LIBRARY METIS_LIBRARY METIS_INCLUDE_DIR)
if(CHOLMOD_FOUND AND NOT TARGET CHOLMOD::CHOLMOD)
  add_library(CHOLMOD::CHOLMOD INTERFACE IMPORTED)
  set_target_properties(CHOLMOD::CHOLMOD PROPERTIES
    INTERFACE_INCLUDE_DIRECTORIES "${CHOLMOD_INCLUDE_DIR};${METIS_INCLUDE_DIR}"
    INTERFACE_LINK_LIBRARIES "${CHOLMOD_LIBRARY};${SUITESPARSECONFIG_LIBRARY};${METIS_LIBRARY}")
endif()
mark_as_advanced(CHOLMOD_INCLUDE_DIR CHOLMOD_LIBRARY SUITESPARSECONFIG_LIBRARY METIS_INCLUDE_DIR
                 METIS_LIBRARY)
