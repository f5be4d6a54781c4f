#include "cairn/stats.hpp"

namespace cairn {

const char* stageName(Stage s) {
  switch (s) {
    case Stage::Forces: return "forces";
    case Stage::Collide: return "collide";
    case Stage::Islands: return "islands";
    case Stage::BuildRows: return "build_rows";
    case Stage::Solve: return "solve";
    case Stage::Integrate: return "integrate";
    case Stage::Store: return "store";
    case Stage::Events: return "events";
    case Stage::Sleep: return "sleep";
    case Stage::Guards: return "guards";
    case Stage::Count: break;
  }
  return "unknown";
}

}  // namespace cairn
