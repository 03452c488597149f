# Install mlcp::core (headers, library, CMake package) so that another project can
#   find_package(mlcp CONFIG REQUIRED)
#   target_link_libraries(app PRIVATE mlcp::core)
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

install(TARGETS mlcp_core mlcp_warnings EXPORT mlcpTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/core/include/mlcp DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(EXPORT mlcpTargets NAMESPACE mlcp:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/mlcp)
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/mlcpConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/mlcpConfig.cmake
                              INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/mlcp)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/mlcpConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/mlcpConfig.cmake ${PROJECT_BINARY_DIR}/mlcpConfigVersion.cmake
        DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/mlcp)
if(TARGET mlcp)
  install(TARGETS mlcp RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
endif()
