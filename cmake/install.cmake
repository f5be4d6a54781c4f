# `cmake --install build [--prefix DIR]` installs what an embedding program
# needs and nothing else: the public headers (include/cairn/*.hpp), the
# static library, a CMake package (find_package(cairn), cairn::cairn) and a
# pkg-config file (cairn.pc). Validation, the command line, tests and
# benchmarks are not installed, and the library links none of Bullet,
# GoogleTest or CLI11 (tests/install/install_test.sh checks both).
include(CMakePackageConfigHelpers)

set(CAIRN_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/cairn)
install(TARGETS cairn EXPORT cairnTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/include/cairn DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
  FILES_MATCHING PATTERN "*.hpp")
install(EXPORT cairnTargets NAMESPACE cairn:: DESTINATION ${CAIRN_CMAKE_DIR})

configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/cairnConfig.cmake.in
  ${PROJECT_BINARY_DIR}/cairnConfig.cmake INSTALL_DESTINATION ${CAIRN_CMAKE_DIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/cairnConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/cairnConfig.cmake ${PROJECT_BINARY_DIR}/cairnConfigVersion.cmake
  ${PROJECT_SOURCE_DIR}/cmake/FindCHOLMOD.cmake
  DESTINATION ${CAIRN_CMAKE_DIR})

# pkg-config: the prefix is found from the file's own place (${pcfiledir}),
# so an installation moved or made with --prefix still works. The library
# is static, so what it links comes along in Libs and Requires (not in the
# .private fields, which plain `pkg-config --libs` leaves out).
file(RELATIVE_PATH CAIRN_PC_TO_PREFIX ${CMAKE_INSTALL_FULL_LIBDIR}/pkgconfig ${CMAKE_INSTALL_PREFIX})
get_filename_component(CAIRN_CHOLMOD_DIR ${CHOLMOD_LIBRARY} DIRECTORY)
configure_file(${PROJECT_SOURCE_DIR}/cmake/cairn.pc.in ${PROJECT_BINARY_DIR}/cairn.pc @ONLY)
install(FILES ${PROJECT_BINARY_DIR}/cairn.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
