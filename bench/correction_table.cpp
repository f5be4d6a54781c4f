// The position-correction table of docs/constraints.md: each Correction
// mode (world/settings.hpp) at the default 10 iterations on
//   hanging-chain-20  (scenarios::hangingChain(20): 20 boxes hanging from
//                      the world, the lowest nudged at 0.5 m/s), 600 steps
//   chain-20          (the horizontal whip), 600 steps
// Worst joint anchor separation at t = 10 s and over the run, and the
// change of total energy (kinetic + gravity) over the run. Sleeping is off.
//
//   cairn_bench --table correction
#include "validation/scenarios.hpp"
#include "world/world_access.hpp"

#include <algorithm>
#include <cstdio>

namespace cairn::bench {

namespace {

struct CorrectionResult {
  double end = 0, worst = 0, worst_after_3s = 0, energy_change = 0;
};

CorrectionResult run(SceneDesc scene, Correction c, int iterations) {
  scene.solver.position_correction = c;
  scene.solver.iterations = iterations;
  scene.solver.sleeping = false;  // measure the joints, not the sleep test
  World w = buildWorld(scene);
  const double e0 = w.kineticEnergy() + w.potentialEnergy();
  CorrectionResult r;
  for (int s = 0; s < scene.steps; ++s) {
    w.step(scene.dt);
    double now = 0;
    for (int j = 0; j < cairn::detail::internals(w).jointSlots(); ++j) now = std::max(now, double(w.jointError(JointId{j}).linear));
    r.worst = std::max(r.worst, now);
    if (w.time() >= 3) r.worst_after_3s = std::max(r.worst_after_3s, now);
    r.end = now;
  }
  r.energy_change = w.kineticEnergy() + w.potentialEnergy() - e0;
  return r;
}

const char* name(Correction c) {
  switch (c) {
    case Correction::VelocityBias: return "VelocityBias (default)";
    case Correction::PseudoVelocity: return "PseudoVelocity";
    case Correction::InRhs: return "InRhs";
  }
  return "?";
}

}  // namespace

int correctionTable() {
  for (const char* scene_name : {"hanging-chain-20", "chain-20"}) {
    std::printf("\n%s, 10 iterations, %d steps of 1/60 s\n\n", scene_name, scenarios::byName(scene_name).steps);
    std::printf("| mode | error at 10 s (m) | worst over 3-10 s (m) | worst over the run (m) | energy change (J) |\n");
    std::printf("|---|---:|---:|---:|---:|\n");
    for (Correction c : {Correction::VelocityBias, Correction::PseudoVelocity, Correction::InRhs}) {
      const CorrectionResult r = run(scenarios::byName(scene_name), c, 10);
      std::printf("| %s | %.3g | %.3g | %.3g | %+.4g |\n", name(c), r.end, r.worst_after_3s, r.worst,
                  r.energy_change);
    }
  }
  return 0;
}

}  // namespace cairn::bench
