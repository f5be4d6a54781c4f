// Every input that ever crashed or hung a fuzz target, kept in
// tests/fuzz_regressions/<target>/ and replayed through the same work the
// fuzzer does (fuzz/targets.hpp), in the ordinary build: each must load or
// be refused with an InputError. An input that aborts (a broken invariant)
// or throws anything else fails here. Time is not asserted: the targets
// bound the work of any input with small limits and a fixed step count.
#include "fuzz/targets.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <vector>

namespace cairn::fuzz {
namespace {

namespace fs = std::filesystem;

std::vector<fs::path> inputs(const std::string& target) {
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(fs::path(CAIRN_SOURCE_DIR) / "tests/fuzz_regressions" / target))
    if (e.is_regular_file() && e.path().filename() != "README.md") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  return files;
}

std::vector<std::uint8_t> bytes(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

void replay(const std::string& target, Outcome (*run)(const std::uint8_t*, std::size_t)) {
  const auto files = inputs(target);
  EXPECT_FALSE(files.empty()) << "no inputs in tests/fuzz_regressions/" << target;
  for (const fs::path& p : files) {
    SCOPED_TRACE(p.filename().string());
    const auto data = bytes(p);
    EXPECT_NO_THROW((void)run(data.data(), data.size()));
  }
}

TEST(FuzzRegressions, EverySceneInputLoadsOrIsRefusedWithAnInputError) { replay("scene", sceneInput); }

TEST(FuzzRegressions, EveryObjInputLoadsOrIsRefusedWithAnInputError) { replay("obj", objInput); }

}  // namespace
}  // namespace cairn::fuzz
