// Output files that appear complete or not at all.
//
// An OutputFile is a temporary file in the target's own directory (so the
// final rename is atomic: POSIX rename() replaces the target in one step,
// on the same file system) that is written as the run goes, buffered, and
// renamed onto the target by commit(). Until then the target is untouched,
// and if the run fails (an exception, a numerical failure, an early
// return) the destructor removes the temporary file: nothing is left
// behind. Only a process killed outright (SIGKILL, power loss) can leave a
// ".NAME.cairn-XXXXXX" file next to the target.
//
// checkOutputPaths() is called before a run starts, so that a directory, a
// path given twice or a path that is also an input is refused before any
// work is done.
#pragma once

#include <cstdio>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace cairn::validation {

class OutputFile {
 public:
  // Creates the temporary file next to `path`. Throws InputError(path, "",
  // why) when `path` is a directory or its directory is missing or not
  // writable.
  explicit OutputFile(std::string path);
  ~OutputFile();
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;

  // Appends; throws InputError when the file system refuses (disk full).
  void write(std::string_view text);
  // Flushes and closes the temporary file and gives it the permissions a
  // new file would have (0666 less the umask). Throws InputError on a write
  // error; the target is still untouched.
  void finish();
  // Renames the finished file onto the target (finish() first if needed).
  void commit();

  const std::string& path() const { return path_; }

 private:
  std::string path_, tmp_;
  std::FILE* file_ = nullptr;
  bool committed_ = false;
};

// Refuses, with InputError naming the option, any output path that is a
// directory, is the same file as another output (also through a different
// spelling or a link), or is the same file as one of `inputs`. Each output
// is (option, path); empty paths are skipped.
void checkOutputPaths(const std::vector<std::pair<std::string, std::string>>& outputs,
                      const std::vector<std::string>& inputs);

// Writes `content` to `path` through an OutputFile.
void writeFileAtomically(const std::string& path, std::string_view content);

}  // namespace cairn::validation
