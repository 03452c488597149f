# The optional peer benchmark's dependency: Siconos numerics (Debian's libsiconos-numerics-dev,
# which ships no CMake config for the numerics library alone). Defines the imported target
# siconos::numerics when its headers and library are found, and MLCP_HAVE_SICONOS. Nothing else in
# the build needs it: only tests/bench/siconos_bench is built with it.
option(MLCP_WITH_SICONOS "Build the Siconos numerics peer benchmark when the library is found" ON)
set(MLCP_HAVE_SICONOS OFF)
if(MLCP_WITH_SICONOS)
  find_path(SICONOS_NUMERICS_INCLUDE_DIR LinearComplementarityProblem.h
            PATH_SUFFIXES siconos/numerics)
  find_path(SICONOS_CONFIG_INCLUDE_DIR SiconosConfig.h PATH_SUFFIXES siconos)
  find_library(SICONOS_NUMERICS_LIBRARY NAMES siconos_numerics)
  if(SICONOS_NUMERICS_INCLUDE_DIR AND SICONOS_CONFIG_INCLUDE_DIR AND SICONOS_NUMERICS_LIBRARY)
    add_library(siconos::numerics UNKNOWN IMPORTED)
    set_target_properties(siconos::numerics PROPERTIES
      IMPORTED_LOCATION "${SICONOS_NUMERICS_LIBRARY}"
      INTERFACE_INCLUDE_DIRECTORIES "${SICONOS_NUMERICS_INCLUDE_DIR};${SICONOS_CONFIG_INCLUDE_DIR}")
    set(MLCP_HAVE_SICONOS ON)
    message(STATUS "Siconos numerics: ${SICONOS_NUMERICS_LIBRARY} (peer benchmark siconos_bench)")
  else()
    message(STATUS "Siconos numerics not found (libsiconos-numerics-dev): no siconos_bench")
  endif()
endif()
