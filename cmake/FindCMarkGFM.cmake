# Finds Debian's cmark-gfm (libcmark-gfm-dev, libcmark-gfm-extensions-dev): the CommonMark renderer
# with GitHub's table, strikethrough and autolink extensions behind `geomint report`'s Markdown
# (docs/REPORT.md). The extensions ship no pkg-config file, so both are found by name; installed
# next to geomintConfig.cmake so an installed geomint finds them again. Target CMarkGFM::CMarkGFM.
include(FindPackageHandleStandardArgs)
find_path(CMARKGFM_INCLUDE_DIR cmark-gfm.h)
find_path(CMARKGFM_EXTENSIONS_INCLUDE_DIR cmark-gfm-core-extensions.h)
find_library(CMARKGFM_LIBRARY cmark-gfm)
find_library(CMARKGFM_EXTENSIONS_LIBRARY cmark-gfm-extensions)
find_package_handle_standard_args(CMarkGFM REQUIRED_VARS CMARKGFM_LIBRARY CMARKGFM_INCLUDE_DIR
                                  CMARKGFM_EXTENSIONS_LIBRARY CMARKGFM_EXTENSIONS_INCLUDE_DIR)
if(CMarkGFM_FOUND AND NOT TARGET CMarkGFM::CMarkGFM)
  add_library(CMarkGFM::CMarkGFM INTERFACE IMPORTED)
  set_target_properties(CMarkGFM::CMarkGFM PROPERTIES
    INTERFACE_INCLUDE_DIRECTORIES "${CMARKGFM_INCLUDE_DIR};${CMARKGFM_EXTENSIONS_INCLUDE_DIR}"
    INTERFACE_LINK_LIBRARIES "${CMARKGFM_EXTENSIONS_LIBRARY};${CMARKGFM_LIBRARY}")
endif()
mark_as_advanced(CMARKGFM_INCLUDE_DIR CMARKGFM_EXTENSIONS_INCLUDE_DIR CMARKGFM_LIBRARY
                 CMARKGFM_EXTENSIONS_LIBRARY)
