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

const char* methodReasonName(MethodReason r) {
  switch (r) {
    case MethodReason::Setting: return "setting";
    case MethodReason::WellConditioned: return "well_conditioned";
    case MethodReason::MassRatio: return "mass_ratio";
    case MethodReason::LongChain: return "long_chain";
    case MethodReason::JointDrift: return "joint_drift";
    case MethodReason::Count: break;
  }
  return "unknown";
}

const char* aloneReasonName(AloneReason r) {
  switch (r) {
    case AloneReason::None: return "none";
    case AloneReason::LostCores: return "lost_cores";
    case AloneReason::Probe: return "probe";
    case AloneReason::NoGain: return "no_gain";
    case AloneReason::Count: break;
  }
  return "unknown";
}

}  // namespace cairn
