// Prints the table of docs/dynamics.md: what each gyroscopic treatment does
// to a torque-free tumbling body. Run: ./build/tools/gyroscopic_table
#include "world/world_access.hpp"

#include <cmath>
#include <cstdio>

using namespace cairn;

namespace {

struct Row {
  Real energy_ratio, max_energy_err, max_l_err, max_dir_deg;
  int flips;
};

Row tumble(Gyroscopic g, const Mat3& inertia, const Vec3& w0, Real h, Real seconds) {
  World w(Vec3::Zero());
  SolverSettings s;
  s.gyroscopic = g;
  w.setSettings(s);
  BodyDef d;
  d.name = "body";
  d.mass = 1;
  d.inertia = inertia;
  d.angular_velocity = w0;
  const BodyId id = w.createBody(d);
  const Real e0 = cairn::detail::internals(w).body(id).kineticEnergy();
  const Vec3 l0 = cairn::detail::internals(w).body(id).angularMomentum();
  Row r{1, 0, 0, 0, 0};
  Real prev = 1;
  for (int k = 0; k < static_cast<int>(std::lround(seconds / h)); ++k) {
    w.step(h);
    const Body& b = cairn::detail::internals(w).body(id);
    const Vec3 l = b.angularMomentum();
    r.max_energy_err = std::max(r.max_energy_err, std::abs(b.kineticEnergy() / e0 - 1));
    r.max_l_err = std::max(r.max_l_err, std::abs(l.norm() / l0.norm() - 1));
    r.max_dir_deg = std::max(r.max_dir_deg, std::acos(std::clamp(l.normalized().dot(l0.normalized()), -1.0, 1.0)) * 180 / kPi);
    const Real y = (b.rotation * Vec3::UnitY()).dot(l0.normalized());
    if ((y > 0) != (prev > 0)) ++r.flips;
    prev = y;
  }
  r.energy_ratio = cairn::detail::internals(w).body(id).kineticEnergy() / e0;
  return r;
}

}  // namespace

int main() {
  const char* names[] = {"off", "explicit", "implicit_euler", "implicit_midpoint"};
  const Gyroscopic modes[] = {Gyroscopic::Off, Gyroscopic::Explicit, Gyroscopic::ImplicitEuler, Gyroscopic::ImplicitMidpoint};
  std::printf("Body A: principal moments 1, 2, 3; 3 rad/s, 0.01 rad off the intermediate axis; h = 1/60; 10 s\n");
  std::printf("| treatment | E(10 s)/E0 | max |E/E0-1| | max ||L|/|L0|-1| | max angle(L, L0) deg | flips |\n|---|---|---|---|---|---|\n");
  for (int i = 0; i < 4; ++i) {
    const Row r = tumble(modes[i], Vec3(1, 2, 3).asDiagonal().toDenseMatrix(), 3 * Vec3(0.01, 1, 0).normalized(), 1.0 / 60, 10);
    std::printf("| %s | %.6f | %.2e | %.2e | %.3g | %d |\n", names[i], r.energy_ratio, r.max_energy_err, r.max_l_err, r.max_dir_deg, r.flips);
  }
  // Box of half extents 0.5 x 0.25 x 0.1, mass 1: I = m/3 (b^2 + c^2), ...
  const Vec3 he(0.5, 0.25, 0.1);
  const Vec3 h2 = he.cwiseProduct(he);
  const Mat3 ib = (Vec3(h2.y() + h2.z(), h2.x() + h2.z(), h2.x() + h2.y()) / 3).asDiagonal().toDenseMatrix();
  std::printf("\nBody B: box 0.5 x 0.25 x 0.1 half extents, 1 kg, 6 rad/s near its intermediate axis; h = 1/120; 20 s\n");
  std::printf("| treatment | E(20 s)/E0 | max |E/E0-1| | max ||L|/|L0|-1| | max angle(L, L0) deg | flips |\n|---|---|---|---|---|---|\n");
  for (int i = 0; i < 4; ++i) {
    const Row r = tumble(modes[i], ib, 6 * Vec3(0.01, 1, 0.01).normalized(), 1.0 / 120, 20);
    std::printf("| %s | %.6f | %.2e | %.2e | %.3g | %d |\n", names[i], r.energy_ratio, r.max_energy_err, r.max_l_err, r.max_dir_deg, r.flips);
  }
  return 0;
}
