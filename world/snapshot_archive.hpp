// The two ends of the snapshot format (world/snapshot.cpp): a writer that
// appends values to a byte buffer and a reader that takes them back out,
// with the same call `ar(value)` on both, so one function per structure
// (world/snapshot_state.cpp) says both how it is written and how it is read.
//
// Encoding: integers little-endian at their declared width; doubles as the
// little-endian bits of their IEEE 754 binary64 (so a value reads back bit
// for bit, NaN payloads and signed zeros included); bool as one byte 0 or
// 1; enums as int32 checked against their range; strings and vectors as a
// uint64 count then the elements; optionals as a bool then the value.
//
// The reader never reads past the end (a truncated payload throws
// InputError naming the snapshot and what was being read) and never
// allocates for more elements than the data holds.
#pragma once

#include "cairn/error.hpp"
#include "cairn/math.hpp"

#include <bit>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

namespace cairn::detail {

class SnapshotWriter {
 public:
  static constexpr bool reading = false;
  std::vector<std::uint8_t> bytes;

  template <class T>
    requires std::is_integral_v<T>
  void operator()(T v) {
    using U = std::make_unsigned_t<T>;
    auto u = static_cast<U>(v);
    for (size_t i = 0; i < sizeof(T); ++i) bytes.push_back(static_cast<std::uint8_t>((u >> (8 * i)) & 0xffu));
  }
  void operator()(bool v) { bytes.push_back(v ? 1 : 0); }
  void operator()(double v) { (*this)(std::bit_cast<std::uint64_t>(v)); }
  void operator()(const std::string& s) {
    (*this)(static_cast<std::uint64_t>(s.size()));
    bytes.insert(bytes.end(), s.begin(), s.end());
  }
  // What is being written next (the reader names it in its errors).
  void at(const char*) {}
};

class SnapshotReader {
 public:
  static constexpr bool reading = true;

  SnapshotReader(const std::uint8_t* data, size_t size, std::string object)
      : p_(data), left_(size), object_(std::move(object)) {}

  template <class T>
    requires std::is_integral_v<T>
  void operator()(T& v) {
    using U = std::make_unsigned_t<T>;
    need(sizeof(T));
    U u = 0;
    for (size_t i = 0; i < sizeof(T); ++i) u = static_cast<U>(u | (U(p_[i]) << (8 * i)));
    p_ += sizeof(T);
    left_ -= sizeof(T);
    v = static_cast<T>(u);
  }
  void operator()(bool& v) {
    std::uint8_t b = 0;
    (*this)(b);
    if (b > 1) fail("a flag is neither 0 nor 1");
    v = b == 1;
  }
  void operator()(double& v) {
    std::uint64_t u = 0;
    (*this)(u);
    v = std::bit_cast<double>(u);
  }
  void operator()(std::string& s) {
    const size_t n = count(1);
    s.assign(reinterpret_cast<const char*>(p_), n);
    p_ += n;
    left_ -= n;
  }
  void at(const char* what) { what_ = what; }

  // A count of elements at least `min_bytes` long each: refused when the
  // bytes left could not hold them (a corrupted count never allocates).
  size_t count(size_t min_bytes) {
    std::uint64_t n = 0;
    (*this)(n);
    if (n > left_ / (min_bytes ? min_bytes : 1)) fail("a count runs past the end of the data");
    return static_cast<size_t>(n);
  }
  size_t left() const { return left_; }
  [[noreturn]] void fail(const std::string& message) const {
    throw InputError(object_, what_, "corrupted snapshot: " + message);
  }
  const std::string& object() const { return object_; }

 private:
  void need(size_t n) {
    if (n > left_) throw InputError(object_, what_, "truncated snapshot: the data ends early");
  }
  const std::uint8_t* p_;
  size_t left_;
  std::string object_;
  std::string what_ = "header";
};

// Values that are not integers, bools, doubles or strings, written the same
// way by both ends.
template <class Ar>
void io(Ar& ar, Vec3& v) {
  for (int k = 0; k < 3; ++k) ar(v[k]);
}
template <class Ar>
void io(Ar& ar, Quat& q) {
  for (int k = 0; k < 4; ++k) ar(q.coeffs()[k]);
}
template <class Ar>
void io(Ar& ar, Mat3& m) {
  for (int k = 0; k < 9; ++k) ar(m.data()[k]);
}
template <class Ar, class T>
  requires std::is_arithmetic_v<T>
void io(Ar& ar, T& v) {
  ar(v);
}
template <class Ar>
void io(Ar& ar, std::string& s) {
  ar(s);
}
// Enums as int32 in [0, count).
template <class Ar, class E>
  requires std::is_enum_v<E>
void io(Ar& ar, E& e, int count) {
  auto v = static_cast<std::int32_t>(e);
  ar(v);
  if constexpr (Ar::reading) {
    if (v < 0 || v >= count) ar.fail("an enumeration value is out of range");
    e = static_cast<E>(v);
  }
}
template <class Ar, class T>
void io(Ar& ar, std::optional<T>& o) {
  bool has = o.has_value();
  ar(has);
  if constexpr (Ar::reading) {
    if (has) o.emplace();
    else o.reset();
  }
  if (has) io(ar, *o);
}
// A vector, each element through `each`. Read element by element, so a
// corrupted count costs no more memory than the elements the data holds.
template <class Ar, class T, class Each>
void ioEach(Ar& ar, std::vector<T>& v, Each&& each) {
  if constexpr (Ar::reading) {
    const size_t n = ar.count(1);
    v.clear();
    for (size_t i = 0; i < n; ++i) each(v.emplace_back());
  } else {
    ar(static_cast<std::uint64_t>(v.size()));
    for (auto& x : v) each(x);
  }
}
template <class Ar, class T>
void io(Ar& ar, std::vector<T>& v) {
  ioEach(ar, v, [&ar](T& x) { io(ar, x); });
}

}  // namespace cairn::detail
