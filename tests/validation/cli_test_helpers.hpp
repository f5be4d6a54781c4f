// Running the `cairn` command from the validation tests: a scratch
// directory, the binary run from the source directory (so relative scene
// paths such as scenes/column-10.json resolve) with stdout and stderr
// captured, and the exit status. CAIRN_CLI and CAIRN_SOURCE_DIR come from
// tests/CMakeLists.txt.
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <system_error>

namespace cairn::test {

inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

// A fresh directory under the system temp dir, removed at the end.
struct TempDir {
  std::filesystem::path path;
  explicit TempDir(const std::string& prefix = "cairn_test") {
    static int counter = 0;
    path = std::filesystem::temp_directory_path() /
           (prefix + "_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    std::filesystem::remove_all(path);
    std::filesystem::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  std::string operator/(const std::string& name) const { return (path / name).string(); }
};

struct CliResult {
  int status = -1;
  std::string out, err;
};

// `cairn ARGS`, its output kept in `tmp`.
inline CliResult runCairn(const std::string& args, const TempDir& tmp) {
  const std::filesystem::path out = tmp.path / "stdout.txt", err = tmp.path / "stderr.txt";
  const std::string cmd = "cd " + std::string(CAIRN_SOURCE_DIR) + " && " + std::string(CAIRN_CLI) + " " + args + " >" +
                          out.string() + " 2>" + err.string();
  const int raw = std::system(cmd.c_str());
  CliResult r;
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  r.out = slurp(out);
  r.err = slurp(err);
  return r;
}

}  // namespace cairn::test
