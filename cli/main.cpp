// cairn: the command-line front end. `cairn --help` lists the subcommands.
//
// Exit statuses (docs/reliability.md), the same for every subcommand and
// every input: 0 ran, 1 a validation check outside its tolerance, 2 bad
// input (or an output place that cannot be written, or an error cairn did
// not foresee), 3 a numerical failure (a non-finite state was caught). No
// other status and no signal: every exception ends here at the latest.
#include "cli/commands.hpp"
#include "cairn/error.hpp"

#include <csignal>
#include <iostream>
#include <new>

int main(int argc, char** argv) {
  // Output to a closed pipe (`cairn run ... | head -1`) is a failed write,
  // not a SIGPIPE that kills the process.
  std::signal(SIGPIPE, SIG_IGN);
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
  } catch (const cairn::InputError& e) {
    std::cerr << "cairn: " << e.what() << "\n";
    return 2;
  } catch (const cairn::NumericalError& e) {
    std::cerr << "cairn: " << e.what() << "\n";
    return 3;
  } catch (const std::bad_alloc&) {
    std::cerr << "cairn: out of memory: the input needs more memory than this machine has; lower the input limits "
                 "(--limit, docs/reliability.md) to refuse such input up front\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "cairn: internal error: " << e.what() << " (please report it with the input that caused it)\n";
    return 2;
  } catch (...) {
    std::cerr << "cairn: internal error: unknown exception (please report it with the input that caused it)\n";
    return 2;
  }
  return status;
}
