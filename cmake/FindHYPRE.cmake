# Finds Debian's hypre (libhypre-dev) for the Newton solver's linear_solver=cg_amg (BoomerAMG,
# integrators/boomer_amg.cpp), with the MPI it is built against (Open MPI, C interface only);
# installed next to geomintConfig.cmake. Defines the imported target HYPRE::HYPRE.
include(FindPackageHandleStandardArgs)
# MPI through pkg-config's mpi-c (Debian's mpi-default-dev): FindMPI's C component would need the
# C language enabled in a C++-only project.
find_package(PkgConfig QUIET)
if(PKG_CONFIG_FOUND)
  pkg_check_modules(HYPRE_MPI QUIET IMPORTED_TARGET mpi-c)
endif()
find_path(HYPRE_INCLUDE_DIR HYPRE_parcsr_ls.h PATH_SUFFIXES hypre)
find_library(HYPRE_LIBRARY HYPRE)
find_package_handle_standard_args(HYPRE REQUIRED_VARS HYPRE_LIBRARY HYPRE_INCLUDE_DIR HYPRE_MPI_FOUND)
if(HYPRE_FOUND AND NOT TARGET HYPRE::HYPRE)
  add_library(HYPRE::HYPRE INTERFACE IMPORTED)
  set_target_properties(HYPRE::HYPRE PROPERTIES
    INTERFACE_INCLUDE_DIRECTORIES "${HYPRE_INCLUDE_DIR}"
    INTERFACE_LINK_LIBRARIES "${HYPRE_LIBRARY};PkgConfig::HYPRE_MPI")
endif()
mark_as_advanced(HYPRE_INCLUDE_DIR HYPRE_LIBRARY)
