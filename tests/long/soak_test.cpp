// Soak: one World runs a mixed scene for 100,000 steps (about 28 minutes of
// simulated time at 60 Hz) through the public API (cairn/world.hpp): a pile
// of 27 boxes, a ragdoll, a hanging chain of 10 links, a plate spun by a
// motorised hinge, and an area where a box is added and the oldest removed
// every second. Over the whole run:
//   - finite: no NumericalEvent, and every body's state finite at each check;
//   - memory flat: resident memory at the end within 1% of its value after
//     the warm-up, the first half of the run. The step's buffers grow to the
//     most contacts the run sees, and the spawned boxes reach that late:
//     resident memory (8.6 MB) rose once by 108 KB at step 36,531, when the
//     contacts first reached 55, and not again. 1% of 8.7 MB over 50,000
//     steps catches a leak of 2 bytes a step; one contact or one
//     diagnostic a step would add megabytes;
//   - energy bounded: the energy of the parts that stay (pile, ragdoll,
//     chain, plate) never exceeds their energy at the start plus the most
//     kinetic energy the motor can give the plate (1/2 I w^2 at its target
//     speed), plus 5% of their energy scale (the work to lift each body by
//     its own size, the extremes suite's margin): nothing else does work on
//     them, so more than that is energy the solver made up.
#include "cairn/world.hpp"
#include "validation/scenarios.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <deque>
#include <vector>

namespace cairn {
namespace {

// Resident set size in bytes (Linux: /proc/self/statm, second field in pages).
long residentBytes() {
  long pages = 0, resident = 0;
  if (FILE* f = std::fopen("/proc/self/statm", "r")) {
    if (std::fscanf(f, "%ld %ld", &pages, &resident) != 2) resident = 0;
    std::fclose(f);
  }
  return resident * 4096;
}

// Adds the scene's dynamic bodies and joints, shifted by `offset`; its
// static bodies are left out (the soak World has one ground) and joints to
// them go to the world.
std::vector<BodyId> addScene(World& w, const SceneDesc& s, const Vec3& offset, const std::string& prefix) {
  std::vector<BodyId> ids(s.bodies.size(), kWorldBody), added;
  for (size_t i = 0; i < s.bodies.size(); ++i) {
    if (s.bodies[i].type == BodyType::Static) continue;
    BodyDef b = s.bodies[i];
    b.name = prefix + b.name;
    b.position += offset;
    ids[i] = w.createBody(b);
    added.push_back(ids[i]);
  }
  for (JointDef j : s.joints) {
    j.name = prefix + j.name;
    j.anchor += offset;
    j.body_a = j.body_a.isWorld() ? kWorldBody : ids[static_cast<size_t>(j.body_a.index)];
    j.body_b = j.body_b.isWorld() ? kWorldBody : ids[static_cast<size_t>(j.body_b.index)];
    w.createJoint(j);
  }
  return added;
}

bool finiteState(const World& w, BodyId id) {
  const Transform t = w.transform(id);
  return t.p.allFinite() && t.q.coeffs().allFinite() && w.linearVelocity(id).allFinite() &&
         w.angularVelocity(id).allFinite();
}

TEST(Soak, MixedSceneHundredThousandStepsStaysFiniteFlatAndBounded) {
  World w;
  w.createBody(scenarios::ground());
  std::vector<BodyId> kept = addScene(w, scenarios::pile(3), Vec3(0, 0, 0), "pile/");
  for (BodyId id : addScene(w, scenarios::ragdoll(), Vec3(6, 0, 0), "ragdoll/")) kept.push_back(id);
  for (BodyId id : addScene(w, scenarios::hangingChain(10), Vec3(-6, 6, 0), "chain/")) kept.push_back(id);

  // The plate: 0.5 x 0.5 x 0.1 m half extents, 5 kg, on a hinge about z
  // through its center, driven to 2 rad/s by at most 20 N m.
  BodyDef plate;
  plate.name = "plate";
  plate.mass = 5;
  plate.position = Vec3(0, 3, 6);
  plate.shapes.push_back(ShapeDesc::box(Vec3(0.5, 0.5, 0.1)));
  const BodyId plate_id = w.createBody(plate);
  kept.push_back(plate_id);
  JointDef hinge;
  hinge.name = "plate_hinge";
  hinge.type = JointType::Hinge;
  hinge.body_b = plate_id;
  hinge.anchor = plate.position;
  hinge.axis = Vec3::UnitZ();
  hinge.motor.enabled = true;
  hinge.motor.target_velocity = 2;
  hinge.motor.max_force = 20;
  w.createJoint(hinge);
  const Real plate_izz = *plate.mass * (0.5 * 0.5 + 0.5 * 0.5) / 3;  // box about its axis: m (a^2 + b^2) / 3
  const Real motor_energy = 0.5 * plate_izz * 2 * 2;

  const auto keptEnergy = [&] {
    Real e = 0;
    for (BodyId id : kept) {
      const Real m = w.mass(id);
      const Vec3 v = w.linearVelocity(id), om = w.angularVelocity(id);
      e += 0.5 * m * v.squaredNorm() + 0.5 * om.dot(w.inertia(id) * om) - m * w.gravity().dot(w.centerOfMass(id));
    }
    return e;
  };
  Real scale = 0;
  for (BodyId id : kept) {
    const Real m = w.mass(id);
    scale += m * w.gravity().norm() * std::sqrt(w.inertia(id).trace() / (2 * m));  // m g L, L the radius of gyration
  }
  const Real bound = keptEnergy() + motor_energy + 0.05 * scale;

  // The spawning area at x = -6, z = -6: a 0.2 m box every second from 3 m,
  // at a place from a fixed linear congruential sequence; the oldest goes
  // once ten are there.
  std::deque<BodyId> spawned;
  std::uint64_t lcg = 1;
  const auto uniform = [&] {
    lcg = lcg * 6364136223846793005ull + 1442695040888963407ull;
    return Real(lcg >> 11) / Real(1ull << 53);
  };
  const Real dt = Real(1) / 60;
  const int steps = 100000, warm_up = 50000, per_second = 60;
  long rss_warm = 0;
  Real worst = -kInf;
  for (int s = 1; s <= steps; ++s) {
    if (s % per_second == 0) {
      if (spawned.size() == 10) {
        w.destroyBody(spawned.front());
        spawned.pop_front();
      }
      BodyDef b;
      b.name = "spawn_" + std::to_string(s / per_second);
      b.mass = 1;
      b.position = Vec3(-6 + 2 * (uniform() - 0.5), 3, -6 + 2 * (uniform() - 0.5));
      b.shapes.push_back(ShapeDesc::box(Vec3::Constant(0.2)));
      spawned.push_back(w.createBody(b));
    }
    w.step(dt);
    ASSERT_TRUE(w.numericalEvents().empty()) << "step " << s << ": " << w.numericalEvents().front().detail;
    if (s % 100 == 0) {
      for (BodyId id : w.bodies()) ASSERT_TRUE(finiteState(w, id)) << w.name(id) << " at step " << s;
      const Real e = keptEnergy();
      worst = std::max(worst, e);
      ASSERT_LE(e, bound) << "step " << s;
    }
    if (s == warm_up) rss_warm = residentBytes();
  }
  const long rss_end = residentBytes();
  ASSERT_GT(rss_warm, 0);
  EXPECT_LE(double(rss_end), 1.01 * double(rss_warm)) << "resident " << rss_warm << " B after warm-up, " << rss_end
                                                       << " B at the end";
  std::printf("soak: resident %ld B after %d steps, %ld B after %d; kept energy max %.6g J, bound %.6g J\n",
              rss_warm, warm_up, rss_end, steps, worst, bound);
}

}  // namespace
}  // namespace cairn
