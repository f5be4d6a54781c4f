// Where each (body, kind) record of World::diagnostics is, so that a
// watcher's report finds its record in constant time.
//
// The watchers report per body (a stack sinking, a deep contact), and a
// record is kept per body and kind for the life of the body. A linear
// search over the records made every report cost their number: the
// 5,050-box pyramid at five sweeps, whose stacks sink from about its
// 140th step, holds 3,718 records at its 200th and makes some 3,000
// reports a step, and its steps 200 to 260 took 63 to 67 ms with the
// search, 54 to 55 with the index, the guards 12.5 against 4.5 ms
// (docs/performance.md, "A watcher's record found by its index").
//
// The index is derived data: the records (and their order, which is the
// order they were first made) stay in the World's vector. It is rebuilt
// from them when they changed without it (a body's records dropped, a
// snapshot restored into a new World).
#pragma once

#include "cairn/events.hpp"

#include <cstdint>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

namespace cairn::detail {

class DiagnosticIndex {
 public:
  // The position in `records` of body's record of `kind` (body -1: the
  // world), or -1.
  std::int32_t find(const std::vector<Diagnostic>& records, std::int32_t body, const char* kind) {
    if (!valid_) rebuild(records);
    const std::vector<std::int32_t>* slots = slotsOf(kind);
    const auto slot = static_cast<size_t>(body + 1);  // body >= -1
    if (!slots || slot >= slots->size()) return -1;
    return (*slots)[slot] - 1;
  }
  // Body's record of `kind` was appended at `position`.
  void add(std::int32_t body, const std::string& kind, std::int32_t position) {
    std::vector<std::int32_t>* slots = slotsOf(kind.c_str());
    if (!slots) slots = &kinds_.emplace_back(kind, std::vector<std::int32_t>{}).second;
    const auto slot = static_cast<size_t>(body + 1);  // body >= -1
    if (slot >= slots->size()) slots->resize(slot + 1, 0);
    (*slots)[slot] = position + 1;
  }
  // The records changed without the index.
  void invalidate() { valid_ = false; }

 private:
  void rebuild(const std::vector<Diagnostic>& records) {
    kinds_.clear();
    valid_ = true;
    for (size_t i = 0; i < records.size(); ++i) add(records[i].body.index, records[i].kind, static_cast<std::int32_t>(i));
  }
  // A handful of kinds: a search by name.
  std::vector<std::int32_t>* slotsOf(const char* kind) {
    for (auto& [name, slots] : kinds_)
      if (std::strcmp(name.c_str(), kind) == 0) return &slots;
    return nullptr;
  }

  // Per kind, per body slot + 1 (0: the world): the record's position + 1
  // (0: none).
  std::vector<std::pair<std::string, std::vector<std::int32_t>>> kinds_;
  bool valid_ = false;
};

}  // namespace cairn::detail
