# mlcp_ode_engine_target(<version> <error-var>): the imported target mlcp::ode_engine (ODE's
# public headers and libode) for the installed ODE, which must be exactly <version>: the
# adapter calls ODE's internal island-stepper functions, whose layout is only checked against
# that release (Debian 12's libode-dev 0.16.2, double precision). Found through `pkg-config
# ode`, else `ode-config`. Runs when mlcp is built and when an installed mlcp is found
# (mlcpConfig.cmake). On failure <error-var> holds a one-line reason and no target is made.
function(mlcp_ode_engine_target required error_var)
  set(${error_var} "" PARENT_SCOPE)
  if(TARGET mlcp::ode_engine)
    return()
  endif()
  set(version "")
  find_package(PkgConfig QUIET)
  if(PKG_CONFIG_FOUND)
    pkg_check_modules(MLCP_ODE_PC QUIET ode)
    if(MLCP_ODE_PC_FOUND)
      set(version "${MLCP_ODE_PC_VERSION}")
    endif()
  endif()
  if(version STREQUAL "")
    find_program(MLCP_ODE_CONFIG ode-config)
    if(MLCP_ODE_CONFIG)
      execute_process(COMMAND ${MLCP_ODE_CONFIG} --version OUTPUT_VARIABLE version
                      OUTPUT_STRIP_TRAILING_WHITESPACE)
    endif()
  endif()
  if(version STREQUAL "")
    string(CONCAT msg "ODE not found (neither `pkg-config ode` nor `ode-config`): install "
           "Debian's libode-dev ${required}")
    set(${error_var} "${msg}" PARENT_SCOPE)
    return()
  endif()
  if(NOT version VERSION_EQUAL required)
    string(CONCAT msg "the installed ODE is ${version}, but mlcp::ode uses ODE's internal "
           "stepper interface, which is only checked against ${required}: install libode-dev "
           "${required}")
    set(${error_var} "${msg}" PARENT_SCOPE)
    return()
  endif()
  find_library(MLCP_ODE_LIBRARY NAMES ode HINTS ${MLCP_ODE_PC_LIBRARY_DIRS})
  find_path(MLCP_ODE_INCLUDE_DIR ode/ode.h HINTS ${MLCP_ODE_PC_INCLUDE_DIRS})
  if(NOT MLCP_ODE_LIBRARY OR NOT MLCP_ODE_INCLUDE_DIR)
    set(${error_var} "libode or <ode/ode.h> not found (install libode-dev ${required})"
        PARENT_SCOPE)
    return()
  endif()
  add_library(mlcp::ode_engine INTERFACE IMPORTED GLOBAL)
  set_target_properties(mlcp::ode_engine PROPERTIES
    INTERFACE_INCLUDE_DIRECTORIES "${MLCP_ODE_INCLUDE_DIR}"
    INTERFACE_LINK_LIBRARIES "${MLCP_ODE_LIBRARY}")
endfunction()
