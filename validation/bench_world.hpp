// Everything `cairn bench` reads from a cairn World beyond what the
// validation runners record (compare.hpp): the step's own statistics
// (include/cairn/stats.hpp) after each World::step. Kept in this one place
// so that a change of the World's API is ported here and nowhere else.
#pragma once

#include "cairn/stats.hpp"

#include <array>

namespace cairn {
class World;
}

namespace cairn::validation {

struct StepReading {
  std::array<double, kStageCount> stage_seconds{};  // wall time per stage of the last step (s)
  int rows = 0;            // rows solved (last substep)
  int contacts = 0;        // touching manifolds
  int contact_points = 0;
  int sleeping_bodies = 0;
  int threads = 1;         // threads the step ran on (StepStats::threads)
  AloneReason alone_because = AloneReason::None;  // why on one when asked for more (StepStats::alone_because)
};

// The last step's statistics (World::lastStepStats()).
StepReading readLastStep(const World& world);

}  // namespace cairn::validation
