// Snapshots of the whole World (World::saveSnapshot, restoreSnapshot): a
// versioned binary file that a fresh World restores from and then steps on
// bit-identically to the World that was saved (docs/snapshots.md).
//
// File layout (little-endian):
//   offset 0   8 bytes  magic "CAIRNSNP"
//          8   uint32   format version (kSnapshotVersion)
//         12   uint64   payload size in bytes
//         20   uint32   CRC-32 of the payload (zlib's crc32, ISO 3309)
//         24   payload  the World's state (world/snapshot_state.cpp)
//
// Reading checks the header, the size and the checksum, then parses and
// checks the whole payload into a fresh WorldImpl (world/snapshot_check.cpp:
// every index, handle, free list and count); only a WorldImpl that passed
// everything replaces the World's, so a bad snapshot changes nothing.
#pragma once

#include "world/world_impl.hpp"

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace cairn::detail {

inline constexpr char kSnapshotMagic[8] = {'C', 'A', 'I', 'R', 'N', 'S', 'N', 'P'};
inline constexpr std::uint32_t kSnapshotVersion = 7;
inline constexpr size_t kSnapshotHeaderSize = 24;

// The whole file for `w`.
std::vector<std::uint8_t> encodeSnapshot(const WorldImpl& w);

// A World's state from a whole file; throws InputError naming `object`
// (e.g. "snapshot 'run.snap'") and what was wrong. check_crc false skips
// the checksum only (a fuzzer's mutations then reach the payload checks).
std::unique_ptr<WorldImpl> decodeSnapshot(std::span<const std::uint8_t> bytes, const std::string& object,
                                          bool check_crc = true);

// For a libFuzzer target (LLVMFuzzerTestOneInput): decodes arbitrary bytes
// with the checksum skipped, expecting either a World or an InputError and
// nothing else (no crash, no other exception, no sanitizer report). Returns
// 0 as libFuzzer wants.
int fuzzSnapshotInput(const std::uint8_t* data, size_t size);

// Payload and its checks (world/snapshot_state.cpp, snapshot_check.cpp).
std::vector<std::uint8_t> writeSnapshotPayload(const WorldImpl& w);
void readSnapshotPayload(const std::uint8_t* data, size_t size, const std::string& object, WorldImpl& w);
void checkBroadPhaseState(const WorldImpl& w, const std::vector<BroadPhase::ProxyState>& proxies, int free_head,
                          const std::string& object);
void checkSnapshotState(const WorldImpl& w, const std::string& object);

}  // namespace cairn::detail
