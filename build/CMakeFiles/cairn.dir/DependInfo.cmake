
# Consider dependencies only in project.
set(CMAKE_DEPENDS_IN_PROJECT_ONLY OFF)

# The set of languages for which implicit dependencies are needed:
set(CMAKE_DEPENDS_LANGUAGES
  )

# The set of dependency files which are needed:
set(CMAKE_DEPENDS_DEPENDENCY_FILES
  "/work/main/collision/hull.cpp" "CMakeFiles/cairn.dir/collision/hull.cpp.o" "gcc" "CMakeFiles/cairn.dir/collision/hull.cpp.o.d"
  "/work/main/collision/obj_mesh.cpp" "CMakeFiles/cairn.dir/collision/obj_mesh.cpp.o" "gcc" "CMakeFiles/cairn.dir/collision/obj_mesh.cpp.o.d"
  "/work/main/dynamics/forces.cpp" "CMakeFiles/cairn.dir/dynamics/forces.cpp.o" "gcc" "CMakeFiles/cairn.dir/dynamics/forces.cpp.o.d"
  "/work/main/dynamics/integrate.cpp" "CMakeFiles/cairn.dir/dynamics/integrate.cpp.o" "gcc" "CMakeFiles/cairn.dir/dynamics/integrate.cpp.o.d"
  "/work/main/dynamics/mass_properties.cpp" "CMakeFiles/cairn.dir/dynamics/mass_properties.cpp.o" "gcc" "CMakeFiles/cairn.dir/dynamics/mass_properties.cpp.o.d"
  "/work/main/world/scene_build.cpp" "CMakeFiles/cairn.dir/world/scene_build.cpp.o" "gcc" "CMakeFiles/cairn.dir/world/scene_build.cpp.o.d"
  "/work/main/world/scene_json.cpp" "CMakeFiles/cairn.dir/world/scene_json.cpp.o" "gcc" "CMakeFiles/cairn.dir/world/scene_json.cpp.o.d"
  "/work/main/world/world.cpp" "CMakeFiles/cairn.dir/world/world.cpp.o" "gcc" "CMakeFiles/cairn.dir/world/world.cpp.o.d"
  "/work/main/world/world_step.cpp" "CMakeFiles/cairn.dir/world/world_step.cpp.o" "gcc" "CMakeFiles/cairn.dir/world/world_step.cpp.o.d"
  )

# Targets to which this target links.
set(CMAKE_TARGET_LINKED_INFO_FILES
  )

# Fortran module output directory.
set(CMAKE_Fortran_TARGET_MODULE_DIR "")
