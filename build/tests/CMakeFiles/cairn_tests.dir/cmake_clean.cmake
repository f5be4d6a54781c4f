file(REMOVE_RECURSE
  "CMakeFiles/cairn_tests.dir/unit/integration_test.cpp.o"
  "CMakeFiles/cairn_tests.dir/unit/integration_test.cpp.o.d"
  "cairn_tests"
  "cairn_tests.pdb"
  "cairn_tests[1]_tests.cmake"
)

# Per-language clean rules from dependency scanning.
foreach(lang CXX)
  include(CMakeFiles/cairn_tests.dir/cmake_clean_${lang}.cmake OPTIONAL)
endforeach()
