// How cairn's own tools (validation/, the command line, tests and
// benchmarks) reach the World's internals. Not installed: users see only
// include/cairn/.
#pragma once

#include "cairn/world.hpp"
#include "world/world_impl.hpp"

namespace cairn::detail {

struct WorldAccess {
  static WorldImpl& impl(World& w) { return *w.impl_; }
  static const WorldImpl& impl(const World& w) { return *w.impl_; }
};

inline WorldImpl& internals(World& w) { return WorldAccess::impl(w); }
inline const WorldImpl& internals(const World& w) { return WorldAccess::impl(w); }

}  // namespace cairn::detail
