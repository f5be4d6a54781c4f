// The `cairn` subcommands. Each returns the process exit status:
//   0 success, 1 a check failed (validate), 2 bad input (nothing written),
//   3 a non-finite state was caught during the run (run, bench); main() maps
//   whatever escapes a command to these (docs/reliability.md).
#pragma once

#include <CLI/CLI.hpp>

namespace cairn::cli {

void addRunCommand(CLI::App& app, int& status);
void addSoftnessCommand(CLI::App& app, int& status);
void addScenesCommand(CLI::App& app, int& status);
void addValidateCommand(CLI::App& app, int& status);
void addSweepCommand(CLI::App& app, int& status);
void addViewCommand(CLI::App& app, int& status);
void addBenchCommand(CLI::App& app, int& status);

}  // namespace cairn::cli
