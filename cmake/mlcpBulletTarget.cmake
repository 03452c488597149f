# mlcp_bullet_engine_target(<precision> <error-var>): the imported target mlcp::bullet_engine
# (include directories, BT_USE_DOUBLE_PRECISION where it applies, and LinearMath,
# BulletCollision, BulletDynamics in link order) from Debian's Bullet CMake config of that
# precision ("double": BulletConfig-float64.cmake, "float": BulletConfig.cmake).
#
# Why our own target: Bullet 3.24's configs set only variables (relative include and library
# directories under BULLET_ROOT_DIR, BULLET_DEFINITIONS, library names) and no imported targets,
# and CMake's FindBullet module finds the single-precision libraries only. The same function runs
# when mlcp is built and when an installed mlcp is found (mlcpConfig.cmake), so a consumer links
# exactly the Bullet libraries the adapter was compiled against, found on the consumer's machine.
# On failure <error-var> holds a one-line reason and no target is made; otherwise it is "".
function(mlcp_bullet_engine_target precision error_var)
  set(${error_var} "" PARENT_SCOPE)
  if(TARGET mlcp::bullet_engine)
    return()
  endif()
  if(precision STREQUAL "float")
    set(config BulletConfig.cmake)
    set(suffix "")
  else()
    set(config BulletConfig-float64.cmake)
    set(suffix "-float64")
  endif()
  find_package(Bullet CONFIG QUIET CONFIGS ${config})
  if(NOT Bullet_FOUND)
    set(${error_var} "Bullet (${config}) not found: install Debian's libbullet-dev 3.24"
        PARENT_SCOPE)
    return()
  endif()

  set(includes "")
  foreach(dir IN LISTS BULLET_INCLUDE_DIRS)
    if(IS_ABSOLUTE "${dir}")
      list(APPEND includes "${dir}")
    else()
      list(APPEND includes "${BULLET_ROOT_DIR}/${dir}")
    endif()
  endforeach()
  set(libdir "${BULLET_LIBRARY_DIRS}")
  if(NOT IS_ABSOLUTE "${libdir}")
    set(libdir "${BULLET_ROOT_DIR}/${libdir}")
  endif()
  # Dependents first: BulletDynamics needs BulletCollision needs LinearMath.
  set(libs "")
  foreach(name BulletDynamics BulletCollision LinearMath)
    find_library(MLCP_BT_${name}${suffix} NAMES ${name}${suffix} HINTS "${libdir}")
    if(NOT MLCP_BT_${name}${suffix})
      set(${error_var} "Bullet's ${name}${suffix} library not found in ${libdir}" PARENT_SCOPE)
      return()
    endif()
    list(APPEND libs "${MLCP_BT_${name}${suffix}}")
  endforeach()
  string(REPLACE "-D" "" defs "${BULLET_DEFINITIONS}")
  separate_arguments(defs)

  add_library(mlcp::bullet_engine INTERFACE IMPORTED GLOBAL)
  set_target_properties(mlcp::bullet_engine PROPERTIES
    INTERFACE_INCLUDE_DIRECTORIES "${includes}"
    INTERFACE_SYSTEM_INCLUDE_DIRECTORIES "${includes}"
    INTERFACE_COMPILE_DEFINITIONS "${defs}"
    INTERFACE_LINK_LIBRARIES "${libs}")
endfunction()
