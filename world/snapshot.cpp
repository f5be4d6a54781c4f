// Snapshot files: header, checksum, and the World's save and restore
// (format in world/snapshot.hpp).
#include "world/snapshot.hpp"

#include "cairn/error.hpp"

#include <zlib.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>

namespace cairn::detail {

namespace {

std::uint32_t crcOf(const std::uint8_t* data, size_t size) {
  uLong crc = crc32(0L, Z_NULL, 0);
  // zlib takes lengths as uInt: feed large payloads in pieces.
  while (size > 0) {
    const auto n = static_cast<uInt>(std::min<size_t>(size, 1u << 30));
    crc = crc32(crc, data, n);
    data += n;
    size -= n;
  }
  return static_cast<std::uint32_t>(crc);
}

template <class T>
void putLe(std::vector<std::uint8_t>& out, T v) {
  for (size_t i = 0; i < sizeof(T); ++i) out.push_back(static_cast<std::uint8_t>((v >> (8 * i)) & 0xffu));
}

template <class T>
T getLe(const std::uint8_t* p) {
  T v = 0;
  for (size_t i = 0; i < sizeof(T); ++i) v = static_cast<T>(v | (T(p[i]) << (8 * i)));
  return v;
}

}  // namespace

std::vector<std::uint8_t> encodeSnapshot(const WorldImpl& w) {
  const std::vector<std::uint8_t> payload = writeSnapshotPayload(w);
  std::vector<std::uint8_t> out(std::begin(kSnapshotMagic), std::end(kSnapshotMagic));
  putLe<std::uint32_t>(out, kSnapshotVersion);
  putLe<std::uint64_t>(out, payload.size());
  putLe<std::uint32_t>(out, crcOf(payload.data(), payload.size()));
  out.insert(out.end(), payload.begin(), payload.end());
  return out;
}

std::unique_ptr<WorldImpl> decodeSnapshot(std::span<const std::uint8_t> bytes, const std::string& object,
                                          bool check_crc) {
  if (bytes.size() < sizeof kSnapshotMagic || std::memcmp(bytes.data(), kSnapshotMagic, sizeof kSnapshotMagic) != 0)
    throw InputError(object, "magic", "not a cairn snapshot (it does not start with CAIRNSNP)");
  if (bytes.size() < kSnapshotHeaderSize)
    throw InputError(object, "header", "truncated snapshot: " + std::to_string(bytes.size()) +
                                           " bytes, shorter than the header");
  const auto version = getLe<std::uint32_t>(bytes.data() + 8);
  if (version != kSnapshotVersion)
    throw InputError(object, "version", "snapshot format version " + std::to_string(version) +
                                            "; this cairn reads version " + std::to_string(kSnapshotVersion));
  const auto size = getLe<std::uint64_t>(bytes.data() + 12);
  const size_t have = bytes.size() - kSnapshotHeaderSize;
  if (size > have)
    throw InputError(object, "payload", "truncated snapshot: the header announces " + std::to_string(size) +
                                            " bytes of state, the file holds " + std::to_string(have));
  if (size < have)
    throw InputError(object, "payload", "corrupted snapshot: " + std::to_string(have - size) +
                                            " bytes follow the announced end");
  const std::uint8_t* payload = bytes.data() + kSnapshotHeaderSize;
  if (check_crc && getLe<std::uint32_t>(bytes.data() + 20) != crcOf(payload, have))
    throw InputError(object, "checksum", "corrupted snapshot: the payload does not match its CRC-32");
  auto w = std::make_unique<WorldImpl>();
  readSnapshotPayload(payload, have, object, *w);
  return w;
}

int fuzzSnapshotInput(const std::uint8_t* data, size_t size) {
  try {
    (void)decodeSnapshot(std::span<const std::uint8_t>(data, size), "fuzz input", false);
  } catch (const InputError&) {
  }
  return 0;
}

}  // namespace cairn::detail

namespace cairn {

namespace {
// The decoded state replaces the World's; callbacks are code, not state,
// and stay with the World.
void adopt(std::unique_ptr<detail::WorldImpl>& impl, std::unique_ptr<detail::WorldImpl> fresh) {
  fresh->contact_callback_ = std::move(impl->contact_callback_);
  fresh->filter_callback_ = std::move(impl->filter_callback_);
  impl = std::move(fresh);
}
}  // namespace

std::vector<std::uint8_t> World::saveSnapshot() const { return detail::encodeSnapshot(*impl_); }

void World::saveSnapshot(const std::string& path) const {
  const std::vector<std::uint8_t> bytes = saveSnapshot();
  const std::string object = "snapshot '" + path + "'";
  // Written beside the target and renamed: a failed write leaves no half file.
  const std::string tmp = path + ".tmp";
  {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    if (!f) throw InputError(object, "", "cannot open for writing");
    f.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    if (!f) throw InputError(object, "", "cannot write");
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) throw InputError(object, "", "cannot write (rename failed)");
}

void World::restoreSnapshot(std::span<const std::uint8_t> bytes) {
  adopt(impl_, detail::decodeSnapshot(bytes, "snapshot"));
}

void World::restoreSnapshot(const std::string& path) {
  const std::string object = "snapshot '" + path + "'";
  std::ifstream f(path, std::ios::binary);
  if (!f) throw InputError(object, "", "cannot open for reading");
  const std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  if (f.bad()) throw InputError(object, "", "cannot read");
  adopt(impl_, detail::decodeSnapshot(bytes, object));
}

}  // namespace cairn
