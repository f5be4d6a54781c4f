// Restitution never adds energy (docs/contacts.md, restitution): the
// bounce target comes from the approach speed before the step's solve and
// is applied once per impact, after the last substep, so no substep count
// and no spin can make a body leave a bounce with more energy than it
// brought.
//
// The drops: a sphere, and a unit box landing on a face, an edge and a
// corner; with and without spin and horizontal speed (an oblique spinning
// impact), with friction 0 and 0.5, restitution 0, 0.5 and 1, at 1, 2 and 4
// substeps, with the contacts prepared at every substep and prepared once
// and refreshed (SolverSettings::prepare_contacts_each_substep); 3 s at
// h = 1/60 on a static plane.
#include "test_helpers.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace cairn {
namespace {

enum class Shape { Sphere, BoxFace, BoxEdge, BoxCorner };

const char* shapeName(Shape s) {
  switch (s) {
    case Shape::Sphere: return "sphere";
    case Shape::BoxFace: return "box on face";
    case Shape::BoxEdge: return "box on edge";
    case Shape::BoxCorner: return "box on corner";
  }
  return "?";
}

struct Drop {
  Shape shape = Shape::Sphere;
  bool spin = false;
  Real friction = 0;
  Real restitution = 0;
  int substeps = 1;
  bool prepare_each = true;

  std::string label() const {
    return std::string(shapeName(shape)) + (spin ? ", spinning" : "") + ", mu " + std::to_string(friction) + ", e " +
           std::to_string(restitution) + ", " + std::to_string(substeps) + " substeps" +
           (prepare_each ? "" : ", contacts refreshed");
  }
};

World dropWorld(const Drop& d, BodyId& id) {
  World w;
  SolverSettings s;
  s.sleeping = false;
  s.substeps = d.substeps;
  s.prepare_contacts_each_substep = d.prepare_each;
  w.setSettings(s);
  BodyDef g;
  g.name = "ground";
  g.type = BodyType::Static;
  g.friction = d.friction;
  g.restitution = d.restitution;
  g.shapes.push_back(ShapeDesc::plane(Vec3::UnitY(), 0));
  w.createBody(g);
  BodyDef b = d.shape == Shape::Sphere ? test::sphereDef("body", Vec3::Zero(), 1, 0.5) : test::boxDef("body", Vec3::Zero());
  b.friction = d.friction;
  b.restitution = d.restitution;
  Real lowest = 0.5;  // center above the lowest point
  if (d.shape == Shape::BoxEdge) {
    b.orientation = Quat(Eigen::AngleAxis<Real>(kPi / 4, Vec3::UnitZ()));
    lowest = 0.5 * std::sqrt(2.0);
  } else if (d.shape == Shape::BoxCorner) {
    b.orientation = Quat(Eigen::AngleAxis<Real>(std::atan(1 / std::sqrt(2.0)), Vec3::UnitX())) *
                    Quat(Eigen::AngleAxis<Real>(kPi / 4, Vec3::UnitZ()));
    lowest = 0.5 * std::sqrt(3.0);
  }
  b.position = Vec3(0, 1 + lowest, 0);  // the lowest point 1 m up
  if (d.spin) {
    b.linear_velocity = Vec3(1, 0, 0);
    b.angular_velocity = Vec3(0.5, 1, 5);
  }
  id = w.createBody(b);
  return w;
}

std::vector<Drop> allDrops() {
  std::vector<Drop> out;
  for (Shape shape : {Shape::Sphere, Shape::BoxFace, Shape::BoxEdge, Shape::BoxCorner})
    for (bool spin : {false, true})
      for (Real mu : {Real(0), Real(0.5)})
        for (Real e : {Real(0), Real(0.5), Real(1)})
          for (int sub : {1, 2, 4})
            for (bool each : {true, false})
              if (each || sub > 1) out.push_back({shape, spin, mu, e, sub, each});
  return out;
}

// E = kinetic + m g y (the plane at y = 0). Free flight under the
// velocity-first Euler step loses g^2 h^2 / 2 per step and never gains; a
// contact's push-out may lift a body by at most the depth past the slop;
// so any rise above 0.1% of E(0) (1.5 mm of height for the sphere, the
// requirement's bound) is energy a bounce made.
TEST(RestitutionEnergy, NoDropGainsEnergyWithAnyShapeSpinFrictionOrSubsteps) {
  for (const Drop& d : allDrops()) {
    BodyId id;
    World w = dropWorld(d, id);
    auto& in = cairn::detail::internals(w);
    const Real e0 = in.kineticEnergy() + in.potentialEnergy();
    Real worst = -kInf;
    for (int k = 0; k < 180; ++k) {
      w.step(Real(1) / 60);
      worst = std::max(worst, in.kineticEnergy() + in.potentialEnergy() - e0);
    }
    EXPECT_LE(worst, 1e-3 * e0) << d.label() << ": rose by " << worst / e0 * 100 << "%";
  }
}

// Head-on (no spin, no horizontal speed): the first bounce leaves at
// exactly e times the approach speed the step began with (Newton's law,
// section 12.4.2). The restitution pass drives the normal velocity to its
// target until the error is under 1e-6 of the target, so 1e-5 relative.
TEST(RestitutionEnergy, HeadOnBouncesKeepTheExactCoefficient) {
  int checked = 0;
  for (const Drop& base : allDrops()) {
    if (base.spin || base.restitution == 0 || (base.shape != Shape::Sphere && base.shape != Shape::BoxFace)) continue;
    BodyId id;
    World w = dropWorld(base, id);
    auto& in = cairn::detail::internals(w);
    bool bounced = false;
    for (int k = 0; k < 120 && !bounced; ++k) {
      const Real before = in.body(id).linear_velocity.y();
      w.step(Real(1) / 60);
      const Real after = in.body(id).linear_velocity.y();
      if (before < 0 && after > 0) {
        bounced = true;
        ++checked;
        EXPECT_NEAR(after, -base.restitution * before, 1e-5 * std::abs(before)) << base.label();
      }
    }
    EXPECT_TRUE(bounced) << base.label();
  }
  // Sphere and box face, mu 0 and 0.5, e 0.5 and 1: at 1, 2 and 4 substeps
  // with the contacts prepared every substep (24), and at 2 and 4 with them
  // refreshed (16).
  EXPECT_EQ(checked, 40);
}

}  // namespace
}  // namespace cairn
