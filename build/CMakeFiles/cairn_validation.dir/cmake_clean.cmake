file(REMOVE_RECURSE
  "CMakeFiles/cairn_validation.dir/validation/scenarios.cpp.o"
  "CMakeFiles/cairn_validation.dir/validation/scenarios.cpp.o.d"
  "libcairn_validation.a"
  "libcairn_validation.pdb"
)

# Per-language clean rules from dependency scanning.
foreach(lang CXX)
  include(CMakeFiles/cairn_validation.dir/cmake_clean_${lang}.cmake OPTIONAL)
endforeach()
