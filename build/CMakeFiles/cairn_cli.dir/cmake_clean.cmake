file(REMOVE_RECURSE
  "CMakeFiles/cairn_cli.dir/cli/main.cpp.o"
  "CMakeFiles/cairn_cli.dir/cli/main.cpp.o.d"
  "CMakeFiles/cairn_cli.dir/cli/run_command.cpp.o"
  "CMakeFiles/cairn_cli.dir/cli/run_command.cpp.o.d"
  "cairn"
  "cairn.pdb"
)

# Per-language clean rules from dependency scanning.
foreach(lang CXX)
  include(CMakeFiles/cairn_cli.dir/cmake_clean_${lang}.cmake OPTIONAL)
endforeach()
