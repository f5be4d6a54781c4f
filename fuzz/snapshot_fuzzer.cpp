// libFuzzer entry point: snapshot files (world/snapshot.hpp), decoded with
// the checksum skipped so mutations reach the payload's checks.
#include "world/snapshot.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return cairn::detail::fuzzSnapshotInput(data, size);
}
