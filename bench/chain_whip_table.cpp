// The chain-20 whip table of docs/constraints.md: scenarios::chain(20) (20
// spheres of 1 kg joined by ball joints, released horizontally from the
// world anchor, h = 1/60, 600 steps), largest anchor separation of any
// joint over the run and at the end, for PGS at 4, 10, 20, 50 and 100
// iterations, in cairn and in Bullet (validation/bullet_oracle.hpp, the same
// SceneDesc with cairn's settings mapped onto Bullet's).
//
// A second table spends the same sweeps as substeps (solver.substeps: the
// step split into n steps of h / n, each with its own rows and sweeps); a
// third solves the same scene with solver.method direct and lcp.
//
//   cairn_bench --table chain-whip
#include "validation/bullet_oracle.hpp"
#include "validation/scenarios.hpp"
#include "world/world_access.hpp"

#include <algorithm>
#include <cstdio>
#include <set>
#include <string>
#include <utility>

namespace cairn::bench {

namespace {

struct WhipResult {
  double worst = 0, end = 0, tip_speed = 0;
};

std::string mm(double metres) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", 1e3 * metres);
  return buf;
}

WhipResult runCairn(const SceneDesc& scene) {
  World w = buildWorld(scene);
  WhipResult r;
  for (int s = 0; s < scene.steps; ++s) {
    w.step(scene.dt);
    double now = 0;
    for (int j = 0; j < cairn::detail::internals(w).jointSlots(); ++j) now = std::max(now, double(w.jointError(JointId{j}).linear));
    r.worst = std::max(r.worst, now);
    r.end = now;
    r.tip_speed = std::max(r.tip_speed, double(cairn::detail::internals(w).bodies().back().linear_velocity.norm()));
  }
  return r;
}

WhipResult runBullet(const SceneDesc& scene, bool match_cairn, std::set<std::string>& notes) {
  WhipResult r;
  validation::OracleOptions opt;
  opt.match_cairn = match_cairn;
  validation::BulletOracle o(scene, opt);
  for (int s = 0; s < scene.steps; ++s) {
    o.step();
    double now = 0;
    for (size_t j = 0; j < scene.joints.size(); ++j)
      now = std::max(now, double(o.jointAnchorSeparation(static_cast<int>(j)).norm()));
    r.worst = std::max(r.worst, now);
    r.end = now;
    r.tip_speed = std::max(r.tip_speed, double(o.state(o.bodyCount() - 1).linear_velocity.norm()));
  }
  notes.insert(o.skipped().begin(), o.skipped().end());
  return r;
}

}  // namespace

int chainWhipTable() {
  std::set<std::string> notes;
  std::printf("| iterations | cairn worst (mm) | cairn end (mm) | Bullet worst (mm) | Bullet end (mm) "
              "| Bullet as shipped worst (mm) | Bullet as shipped end (mm) | tip speed cairn / Bullet (m/s) |\n");
  std::printf("|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  for (int it : {4, 10, 20, 50, 100}) {
    SceneDesc scene = scenarios::chain(20);
    scene.solver.iterations = it;
    scene.solver.sleeping = false;
    const WhipResult c = runCairn(scene);
    const WhipResult b = runBullet(scene, true, notes);
    const WhipResult s = runBullet(scene, false, notes);
    std::printf("| %d | %s | %s | %s | %s | %s | %s | %.1f / %.1f |\n", it, mm(c.worst).c_str(),
                mm(c.end).c_str(), mm(b.worst).c_str(), mm(b.end).c_str(), mm(s.worst).c_str(),
                mm(s.end).c_str(), c.tip_speed, b.tip_speed);
  }
  std::printf("\nThe same sweeps per step spent on substeps\n\n");
  std::printf("| iterations x substeps | cairn worst (mm) | cairn end (mm) | Bullet worst (mm) | Bullet end (mm) |\n");
  std::printf("|---:|---:|---:|---:|---:|\n");
  for (const auto& [it, sub] : {std::pair{40, 1}, {10, 4}, {100, 1}, {10, 10}, {4, 25}}) {
    SceneDesc scene = scenarios::chain(20);
    scene.solver.iterations = it;
    scene.solver.sleeping = false;
    scene.solver.substeps = sub;
    const WhipResult c = runCairn(scene);
    const WhipResult b = runBullet(scene, true, notes);
    std::printf("| %d x %d | %s | %s | %s | %s |\n", it, sub, mm(c.worst).c_str(), mm(c.end).c_str(),
                mm(b.worst).c_str(), mm(b.end).c_str());
  }
  std::printf("\nThe same scene with the direct and exact solvers\n\n");
  std::printf("| solver.method (iterations) | cairn worst (mm) | cairn end (mm) |\n|---|---:|---:|\n");
  for (const auto& [method, it] : {std::pair{SolverMethod::PGS, 10}, {SolverMethod::Direct, 10}, {SolverMethod::LCP, 10}}) {
    SceneDesc scene = scenarios::chain(20);
    scene.solver.method = method;
    scene.solver.iterations = it;
    scene.solver.sleeping = false;
    const WhipResult c = runCairn(scene);
    std::printf("| %s (%d) | %s | %s |\n", solverMethodName(method), it, mm(c.worst).c_str(), mm(c.end).c_str());
  }
  for (const std::string& n : notes) std::printf("\nBullet oracle note: %s\n", n.c_str());
  return 0;
}

}  // namespace cairn::bench
