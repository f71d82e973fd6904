# find_package(spar) for C++ users: `cmake --install` puts the module libraries, their headers
# (include/spar/<module>/...) and this package's config into the prefix; the config finds the
# libraries' own dependencies and imports spar::common, spar::symbolic, ..., spar::reports
# (whichever modules the build configured). tests/package/ builds a consumer against an install.
#
#   cmake --install build --prefix /opt/spar
#   # consumer's CMakeLists.txt:  find_package(spar REQUIRED)
#   #                             target_link_libraries(app PRIVATE spar::planner)
#   cmake -S app -B app/build -DCMAKE_PREFIX_PATH=/opt/spar
include(CMakePackageConfigHelpers)
set(SPAR_CMAKE_INSTALL_DIR lib/cmake/spar)
install(EXPORT spar-targets NAMESPACE spar:: DESTINATION ${SPAR_CMAKE_INSTALL_DIR}
        FILE spar-targets.cmake)
configure_package_config_file(${CMAKE_CURRENT_LIST_DIR}/sparConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/sparConfig.cmake
                              INSTALL_DESTINATION ${SPAR_CMAKE_INSTALL_DIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/sparConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/sparConfig.cmake ${PROJECT_BINARY_DIR}/sparConfigVersion.cmake
        DESTINATION ${SPAR_CMAKE_INSTALL_DIR})
