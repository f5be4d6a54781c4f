// libFuzzer entry point: scene files (fuzz/targets.hpp).
#include "fuzz/targets.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  (void)cairn::fuzz::sceneInput(data, size);
  return 0;
}
