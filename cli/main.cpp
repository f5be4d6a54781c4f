// cairn: the command-line front end. `cairn --help` lists the subcommands.
#include "cli/commands.hpp"

#include <iostream>

int main(int argc, char** argv) {
  CLI::App app{"cairn: a velocity-based LCP rigid-body physics engine"};
  app.require_subcommand(1);
  int status = 0;
  cairn::cli::addRunCommand(app, status);
  cairn::cli::addSoftnessCommand(app, status);
  cairn::cli::addScenesCommand(app, status);
  cairn::cli::addValidateCommand(app, status);
  cairn::cli::addSweepCommand(app, status);
  cairn::cli::addViewCommand(app, status);
  cairn::cli::addBenchCommand(app, status);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  }
  return status;
}
