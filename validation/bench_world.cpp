#include "validation/bench_world.hpp"

#include "cairn/world.hpp"

namespace cairn::validation {

StepReading readLastStep(const World& world) {
  const StepStats& s = world.lastStepStats();
  StepReading r;
  for (int k = 0; k < kStageCount; ++k) r.stage_seconds[size_t(k)] = s.stage_seconds[k];
  r.rows = s.rows;
  r.contacts = s.contacts;
  r.contact_points = s.contact_points;
  r.sleeping_bodies = s.sleeping_bodies;
  r.threads = s.threads;
  r.alone_because = s.alone_because;
  return r;
}

}  // namespace cairn::validation
