# Installs the CMake package `mlcp` so that another project can
#   find_package(mlcp 0.1 CONFIG REQUIRED COMPONENTS bullet ode)
#   target_link_libraries(app PRIVATE mlcp::bullet mlcp::ode)   # mlcp::core comes with them
# Components (each an exported target): core (always), bullet, ode, as built here. What is
# installed:
#   include/mlcp/*.hpp, include/mlcp/bullet/, include/mlcp/ode/ (with the C header stepper.h)
#   lib/libmlcp_core.a, libmlcp_bullet.a, libmlcp_ode.a
#   lib/cmake/mlcp/ mlcpConfig.cmake, mlcpConfigVersion.cmake, mlcpTargets.cmake, and the
#                   engine-finding modules the config shares with this build
#   lib/pkgconfig/mlcp-ode.pc   (the C API: cc app.c $(pkg-config --cflags --libs mlcp-ode))
#   bin/mlcp
#   lib/python3.X/site-packages/mlcp   (the Python package, when built: python/CMakeLists.txt)
# The scene loaders (mlcp::scene, the engines' scene_loader.hpp) are not installed: they serve
# the mlcp program and the tests.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

# What the adapters required of the engines (set by adapters/*/CMakeLists.txt).
get_property(MLCP_PACKAGE_BULLET_PRECISION GLOBAL PROPERTY MLCP_BULLET_PRECISION)
get_property(MLCP_ODE_VERSION_REQUIRED GLOBAL PROPERTY MLCP_ODE_VERSION_REQUIRED)
set(_mlcp_cmake_dir ${CMAKE_INSTALL_LIBDIR}/cmake/mlcp)
set(MLCP_COMPONENTS core)
set(_mlcp_targets mlcp_core)
if(TARGET mlcp_bullet)
  list(APPEND MLCP_COMPONENTS bullet)
  list(APPEND _mlcp_targets mlcp_bullet)
endif()
if(TARGET mlcp_ode)
  list(APPEND MLCP_COMPONENTS ode)
  list(APPEND _mlcp_targets mlcp_ode)
endif()

install(TARGETS ${_mlcp_targets} mlcp_warnings EXPORT mlcpTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/core/include/mlcp DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
foreach(engine bullet ode)
  if(TARGET mlcp_${engine})
    install(DIRECTORY ${PROJECT_SOURCE_DIR}/adapters/${engine}/include/mlcp
            DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} PATTERN scene_loader.hpp EXCLUDE)
  endif()
endforeach()

install(EXPORT mlcpTargets NAMESPACE mlcp:: DESTINATION ${_mlcp_cmake_dir})
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/mlcpConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/mlcpConfig.cmake
                              INSTALL_DESTINATION ${_mlcp_cmake_dir})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/mlcpConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/mlcpConfig.cmake ${PROJECT_BINARY_DIR}/mlcpConfigVersion.cmake
              ${PROJECT_SOURCE_DIR}/cmake/mlcpBulletTarget.cmake
              ${PROJECT_SOURCE_DIR}/cmake/mlcpOdeTarget.cmake
        DESTINATION ${_mlcp_cmake_dir})

if(TARGET mlcp_ode)
  # Static libraries: a C program links ours, ODE and the C++ runtime. The prefix is found from
  # the file's own place, so `cmake --install --prefix P` gives a working file.
  file(RELATIVE_PATH MLCP_PC_TO_PREFIX "/p/${CMAKE_INSTALL_LIBDIR}/pkgconfig" "/p")
  string(REGEX REPLACE "/$" "" MLCP_PC_TO_PREFIX "${MLCP_PC_TO_PREFIX}")
  configure_file(${PROJECT_SOURCE_DIR}/cmake/mlcp-ode.pc.in ${PROJECT_BINARY_DIR}/mlcp-ode.pc @ONLY)
  install(FILES ${PROJECT_BINARY_DIR}/mlcp-ode.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
endif()
if(TARGET mlcp)
  install(TARGETS mlcp RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
endif()
