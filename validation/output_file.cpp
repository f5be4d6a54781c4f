#include "validation/output_file.hpp"

#include "cairn/error.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>

namespace cairn::validation {

namespace fs = std::filesystem;

namespace {

std::string errnoText() { return std::strerror(errno); }

// The file a path names, for comparing two paths: the same file when both
// exist (fs::equivalent sees hard links and symlinks), else the path with
// its existing part resolved.
bool sameFile(const std::string& a, const std::string& b) {
  std::error_code ec;
  if (fs::exists(a, ec) && fs::exists(b, ec)) return fs::equivalent(a, b, ec);
  const fs::path ca = fs::weakly_canonical(fs::absolute(a, ec), ec);
  const fs::path cb = fs::weakly_canonical(fs::absolute(b, ec), ec);
  return ca == cb;
}

}  // namespace

OutputFile::OutputFile(std::string path) : path_(std::move(path)) {
  std::error_code ec;
  if (path_.empty()) throw InputError(path_, "", "empty output path");
  if (fs::is_directory(path_, ec)) throw InputError(path_, "", "is a directory, not a file");
  const fs::path target(path_);
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  if (!fs::is_directory(dir, ec)) throw InputError(path_, "", "directory '" + dir.string() + "' does not exist");
  std::string pattern = (dir / ("." + target.filename().string() + ".cairn-XXXXXX")).string();
  const int fd = ::mkstemp(pattern.data());
  if (fd < 0) throw InputError(path_, "", "cannot write in '" + dir.string() + "': " + errnoText());
  tmp_ = pattern;
  file_ = ::fdopen(fd, "wb");
  if (!file_) {
    ::close(fd);
    ::unlink(tmp_.c_str());
    throw InputError(path_, "", "cannot write: " + errnoText());
  }
}

OutputFile::~OutputFile() {
  if (file_) std::fclose(file_);
  if (!committed_ && !tmp_.empty()) ::unlink(tmp_.c_str());
}

void OutputFile::write(std::string_view text) {
  if (!file_) throw InputError(path_, "", "written after it was finished");
  if (std::fwrite(text.data(), 1, text.size(), file_) != text.size())
    throw InputError(path_, "", "cannot write: " + errnoText());
}

void OutputFile::finish() {
  if (!file_) return;
  const mode_t mask = ::umask(0);
  ::umask(mask);
  const bool ok = std::fflush(file_) == 0 && ::fchmod(::fileno(file_), 0666 & ~mask) == 0;
  const int err = errno;
  const bool closed = std::fclose(file_) == 0;
  file_ = nullptr;
  errno = err;
  if (!ok || !closed) throw InputError(path_, "", "cannot write: " + errnoText());
}

void OutputFile::commit() {
  finish();
  if (committed_) return;
  if (std::rename(tmp_.c_str(), path_.c_str()) != 0) throw InputError(path_, "", "cannot replace: " + errnoText());
  committed_ = true;
}

void checkOutputPaths(const std::vector<std::pair<std::string, std::string>>& outputs,
                      const std::vector<std::string>& inputs) {
  std::error_code ec;
  for (size_t i = 0; i < outputs.size(); ++i) {
    const auto& [option, path] = outputs[i];
    if (path.empty()) continue;
    if (fs::is_directory(path, ec)) throw InputError(option, "", "'" + path + "' is a directory, not a file");
    for (size_t k = 0; k < i; ++k)
      if (!outputs[k].second.empty() && sameFile(path, outputs[k].second))
        throw InputError(option, "", "'" + path + "' is also given to " + outputs[k].first + ": one file cannot hold both");
    for (const std::string& in : inputs)
      if (sameFile(path, in)) throw InputError(option, "", "'" + path + "' is an input of this run; it would be overwritten");
  }
}

void writeFileAtomically(const std::string& path, std::string_view content) {
  OutputFile f(path);
  f.write(content);
  f.commit();
}

}  // namespace cairn::validation
