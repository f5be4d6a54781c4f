# The API reference: Doxygen (Debian's doxygen, installed by scripts/setup)
# over the public headers, built with everything else when Doxygen is found
# (`cmake --build build --target docs`), into build/docs/api/html. A public
# member without documentation is a warning, and a warning fails the target.
find_package(Doxygen)
if(DOXYGEN_FOUND)
  set(CAIRN_DOXYFILE ${PROJECT_BINARY_DIR}/Doxyfile)
  configure_file(${PROJECT_SOURCE_DIR}/docs/Doxyfile.in ${CAIRN_DOXYFILE} @ONLY)
  file(GLOB CAIRN_PUBLIC_HEADERS CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/include/cairn/*.hpp)
  add_custom_command(OUTPUT ${PROJECT_BINARY_DIR}/docs/api/html/index.html
    COMMAND ${CMAKE_COMMAND} -E make_directory ${PROJECT_BINARY_DIR}/docs/api
    COMMAND ${DOXYGEN_EXECUTABLE} ${CAIRN_DOXYFILE}
    DEPENDS ${CAIRN_PUBLIC_HEADERS} ${PROJECT_SOURCE_DIR}/docs/Doxyfile.in
    COMMENT "API reference from include/cairn (Doxygen)"
    VERBATIM)
  add_custom_target(docs ALL DEPENDS ${PROJECT_BINARY_DIR}/docs/api/html/index.html)
else()
  message(STATUS "Doxygen not found: no API reference (scripts/setup installs doxygen)")
endif()
