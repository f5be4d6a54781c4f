file(REMOVE_RECURSE
  "CMakeFiles/cairn.dir/collision/hull.cpp.o"
  "CMakeFiles/cairn.dir/collision/hull.cpp.o.d"
  "CMakeFiles/cairn.dir/collision/obj_mesh.cpp.o"
  "CMakeFiles/cairn.dir/collision/obj_mesh.cpp.o.d"
  "CMakeFiles/cairn.dir/dynamics/forces.cpp.o"
  "CMakeFiles/cairn.dir/dynamics/forces.cpp.o.d"
  "CMakeFiles/cairn.dir/dynamics/integrate.cpp.o"
  "CMakeFiles/cairn.dir/dynamics/integrate.cpp.o.d"
  "CMakeFiles/cairn.dir/dynamics/mass_properties.cpp.o"
  "CMakeFiles/cairn.dir/dynamics/mass_properties.cpp.o.d"
  "CMakeFiles/cairn.dir/world/scene_build.cpp.o"
  "CMakeFiles/cairn.dir/world/scene_build.cpp.o.d"
  "CMakeFiles/cairn.dir/world/scene_json.cpp.o"
  "CMakeFiles/cairn.dir/world/scene_json.cpp.o.d"
  "CMakeFiles/cairn.dir/world/world.cpp.o"
  "CMakeFiles/cairn.dir/world/world.cpp.o.d"
  "CMakeFiles/cairn.dir/world/world_step.cpp.o"
  "CMakeFiles/cairn.dir/world/world_step.cpp.o.d"
  "libcairn.a"
  "libcairn.pdb"
)

# Per-language clean rules from dependency scanning.
foreach(lang CXX)
  include(CMakeFiles/cairn.dir/cmake_clean_${lang}.cmake OPTIONAL)
endforeach()
