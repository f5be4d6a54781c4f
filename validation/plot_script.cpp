#include "validation/plot_script.hpp"

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <sys/wait.h>
#include <unistd.h>
#include <vector>

namespace cairn::validation {

namespace fs = std::filesystem;

namespace {

// Runs argv[0] with its output and errors into `log`; its exit status, or
// -1 when it could not be started or did not exit normally.
int runLogged(const std::vector<std::string>& argv, const std::string& log) {
  const pid_t pid = fork();
  if (pid < 0) return -1;
  if (pid == 0) {
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd >= 0) {
      ::dup2(fd, 1);
      ::dup2(fd, 2);
      ::close(fd);
    }
    std::vector<char*> args;
    for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    ::execv(args[0], args.data());
    std::fprintf(stderr, "cannot run %s\n", args[0]);
    ::_exit(127);
  }
  int raw = 0;
  while (::waitpid(pid, &raw, 0) < 0)
    if (errno != EINTR) return -1;
  return WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
}

}  // namespace

std::string findPlotScript(const std::string& name) {
  const char* env_name = name == "plot_sweep.py"   ? "CAIRN_SWEEP_PLOT_SCRIPT"
                         : name == "plot_bench.py" ? "CAIRN_BENCH_PLOT_SCRIPT"
                                                   : "CAIRN_PLOT_SCRIPT";
  if (const char* env = std::getenv(env_name)) return env;
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  std::vector<fs::path> candidates;
  if (!ec)
    for (fs::path d = exe.parent_path(); !d.empty() && d != d.root_path(); d = d.parent_path())
      candidates.push_back(d / "validation" / name);
  candidates.push_back(fs::current_path(ec) / "validation" / name);
  for (const auto& c : candidates)
    if (fs::exists(c, ec)) return c.string();
  return "";
}

std::string runPlotScript(const std::string& python, const std::string& script, const std::string& dir) {
  const fs::path root(dir);
  const int status = runLogged({python, script, root.string()}, (root / "plots.log").string());
  if (status != 0) {
    std::ifstream log(root / "plots.log");
    std::string line, last_line;
    while (std::getline(log, line))
      if (!line.empty()) last_line = line;
    return "plots not drawn (" + python + " " + script + " exited with " + std::to_string(status) +
           (last_line.empty() ? "" : ": " + last_line) + "); see " + (root / "plots.log").string();
  }
  std::error_code ec;
  fs::remove(root / "plots.log", ec);
  return "";
}

}  // namespace cairn::validation
