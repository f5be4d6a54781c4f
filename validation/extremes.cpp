#include "validation/extremes.hpp"

#include "cairn/error.hpp"
#include "validation/bullet_oracle.hpp"
#include "validation/scenarios.hpp"
#include "world/world_access.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace cairn::validation {

namespace {

std::string fmtG(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", v);
  return b;
}

SceneDesc awake(SceneDesc s) {
  s.solver.sleeping = false;
  return s;
}

// Moves a whole scene (bodies and joint anchors) by `d`.
SceneDesc translated(SceneDesc s, const Vec3& d) {
  for (BodyDef& b : s.bodies) b.position += d;
  for (JointDef& j : s.joints) {
    j.anchor += d;
    j.anchor_a += d;
    j.anchor_b += d;
  }
  return s;
}

// A column of n cubes of half extent `he`, density 1000 kg/m^3, on the ground.
SceneDesc scaledColumn(int n, Real he) {
  SceneDesc s;
  BodyDef g = scenarios::ground();
  g.shapes[0] = ShapeDesc::box(Vec3(400 * he, he, 400 * he));
  g.position = Vec3(0, -he, 0);
  s.bodies.push_back(g);
  for (int k = 0; k < n; ++k) {
    BodyDef b;
    b.name = "box_" + std::to_string(k);
    b.density = 1000;
    b.position = Vec3(0, he * (1 + 2 * k), 0);
    b.shapes.push_back(ShapeDesc::box(Vec3::Constant(he)));
    s.bodies.push_back(b);
  }
  return s;
}

SceneDesc chainWithEndWeight(int links, Real ratio) {
  SceneDesc s = scenarios::chain(links);
  s.bodies.back().mass = ratio;  // the tip sphere: a heavy weight on a chain of 1 kg links
  return s;
}

SceneDesc withDt(SceneDesc s, int per_second, Real seconds) {
  s.dt = Real(1) / per_second;
  s.steps = static_cast<int>(std::lround(seconds * per_second));
  return s;
}

// Drift limits set by the geometry (validation/extremes.hpp).
constexpr Real kStack = Real(0.05), kHanging = Real(0.01), kSwing = Real(0.05), kHinge = Real(0.01);

ExtremeCase make(std::string name, std::string what, SceneDesc scene, DriftMeasure m, Real limit) {
  ExtremeCase c;
  c.name = std::move(name);
  c.what = std::move(what);
  c.scene = awake(std::move(scene));
  c.measure = m;
  c.drift_limit = limit;
  return c;
}

// Energy: kinetic + gravitational potential of the dynamic bodies, computed
// the same way for both engines from (mass, body inertia, state).
struct BodyMass {
  Real m;
  Mat3 inertia_body;
};

double energyOf(const std::vector<BodyMass>& mass, const Vec3& g, int i, const Vec3& x, const Quat& q, const Vec3& v,
                const Vec3& w) {
  const BodyMass& bm = mass[static_cast<size_t>(i)];
  if (bm.m <= 0) return 0;
  const Mat3 r = q.toRotationMatrix();
  const Mat3 iw = r * bm.inertia_body * r.transpose();
  return 0.5 * bm.m * v.squaredNorm() + 0.5 * w.dot(iw * w) - bm.m * g.dot(x);
}

struct Tracker {
  const ExtremeCase& c;
  std::vector<BodyMass> mass;
  std::vector<Vec3> start;
  Vec3 l0 = Vec3::Zero();
  double e0 = 0, scale = 1;
  ExtremeResult r;

  explicit Tracker(const ExtremeCase& cs) : c(cs) {
    const World w = buildWorld(c.scene);
    Real ymin = kInf, ymax = -kInf;
    double ke0 = 0, pe = 0;
    for (int i = 0; i < w.bodyCount(); ++i) {
      const Body& b = cairn::detail::internals(w).body(BodyId{i});
      mass.push_back({b.isDynamic() ? b.mass : 0, b.inertia_body});
      start.push_back(b.position);
      if (!b.isDynamic()) continue;
      ymin = std::min(ymin, b.position.y());
      ymax = std::max(ymax, b.position.y());
      const double e = energyOf(mass, c.scene.gravity, i, b.position, b.orientation, b.linear_velocity, b.angular_velocity);
      pe += -b.mass * c.scene.gravity.dot(b.position);
      ke0 += e + b.mass * c.scene.gravity.dot(b.position);
      l0 += b.position.cross(b.mass * b.linear_velocity) + b.rotation * b.inertia_body * b.rotation.transpose() * b.angular_velocity;
    }
    e0 = ke0 + pe;
    double weight = 0;
    for (const BodyMass& bm : mass) weight += bm.m * c.scene.gravity.norm();
    scale = ke0 + weight * (ymax - ymin + 1);
    if (!(scale > 0)) scale = 1;
  }

  // One step's states (and joint separations) in.
  template <class State, class Sep>
  void record(int bodies, const State& state, int joints, const Sep& separation) {
    ++r.steps_run;
    double e = 0;
    Vec3 l = Vec3::Zero();
    for (int i = 0; i < bodies; ++i) {
      Vec3 x, v, w;
      Quat q;
      state(i, x, q, v, w);
      if (!(x.allFinite() && q.coeffs().allFinite() && v.allFinite() && w.allFinite())) {
        r.finite = false;
        return;
      }
      const BodyMass& bm = mass[static_cast<size_t>(i)];
      if (bm.m <= 0) continue;
      e += energyOf(mass, c.scene.gravity, i, x, q, v, w);
      switch (c.measure) {
        case DriftMeasure::Displacement:
          r.drift = std::max(r.drift, double((x - start[static_cast<size_t>(i)]).norm()) / c.drift_scale);
          break;
        case DriftMeasure::MaxSpeed: r.drift = std::max(r.drift, double(v.norm())); break;
        case DriftMeasure::WallPenetration:
          if (i == firstDynamic()) r.drift = std::max(r.drift, double(x.x() + c.leading_radius - c.wall_x));
          break;
        case DriftMeasure::AngularMomentum: {
          const Mat3 rot = q.toRotationMatrix();
          l += x.cross(bm.m * v) + rot * bm.inertia_body * rot.transpose() * w;
          break;
        }
        case DriftMeasure::JointSeparation: break;
      }
    }
    if (c.measure == DriftMeasure::AngularMomentum) r.drift = std::max(r.drift, double((l - l0).norm() / l0.norm()));
    if (c.measure == DriftMeasure::JointSeparation)
      for (int j = 0; j < joints; ++j) r.drift = std::max(r.drift, double(separation(j)));
    r.energy_excess = std::max(r.energy_excess, (e - e0) / scale);
  }

  int firstDynamic() const {
    for (size_t i = 0; i < mass.size(); ++i)
      if (mass[i].m > 0) return static_cast<int>(i);
    return -1;
  }

  ExtremeResult finish() {
    r.bounded = !c.energy_bound || (r.finite && r.energy_excess <= kEnergyMargin);
    return r;
  }
};

}  // namespace

const char* driftMeasureName(DriftMeasure m) {
  switch (m) {
    case DriftMeasure::JointSeparation: return "largest anchor separation (m)";
    case DriftMeasure::Displacement: return "largest body displacement";
    case DriftMeasure::WallPenetration: return "depth past the wall's face (m)";
    case DriftMeasure::AngularMomentum: return "angular momentum drift, relative";
    case DriftMeasure::MaxSpeed: return "largest body speed (m/s)";
  }
  return "";
}

std::vector<SettingVariant> standardVariants() {
  return {{"pgs", [](SolverSettings& s) { s.method = SolverMethod::PGS; }},
          {"pgs 50 it",
           [](SolverSettings& s) {
             s.method = SolverMethod::PGS;
             s.iterations = 50;
           }},
          {"pgs 10 it x 4 sub",
           [](SolverSettings& s) {
             s.method = SolverMethod::PGS;
             s.substeps = 4;
           }},
          {"pgs 20 it x 8 sub",
           [](SolverSettings& s) {
             s.method = SolverMethod::PGS;
             s.iterations = 20;
             s.substeps = 8;
           }},
          {"direct", [](SolverSettings& s) { s.method = SolverMethod::Direct; }},
          {"direct x 4 sub", [](SolverSettings& s) {
             s.method = SolverMethod::Direct;
             s.substeps = 4;
           }}};
}

std::vector<ExtremeCase> extremeCases() {
  std::vector<ExtremeCase> out;
  // Mass ratios in stacks (docs/scenarios.md mass-ratio-R: a box of R kg on a 1 kg box).
  for (Real r : {10, 100, 1000, 10000})
    out.push_back(make("stack-ratio-" + fmtG(r), "box of " + fmtG(r) + " kg on a 1 kg box", scenarios::massRatio(r),
                       DriftMeasure::Displacement, kStack));
  // ... and in chains: chain-10 (1 kg spheres) whose tip sphere weighs R kg, released horizontally.
  for (Real r : {10, 100, 1000, 10000})
    out.push_back(make("chain-ratio-" + fmtG(r), "10-link ball chain, tip " + fmtG(r) + " kg, released horizontally",
                       chainWithEndWeight(10, r), DriftMeasure::JointSeparation, kSwing));
  // Heavy weights on long light chains (scenarios::heavyHangingChain: 40
  // rods of 0.5 m, 1 kg, the last R kg, nudged 5 cm/s), and a stack whose
  // boxes grow eightfold in mass upward (1:4096 top to bottom).
  for (Real r : {100, 1000, 10000})
    out.push_back(make("heavy-chain-40-" + fmtG(r), "40 hanging 0.5 m rods of 1 kg, the last " + fmtG(r) + " kg, nudged",
                       scenarios::heavyHangingChain(40, r), DriftMeasure::JointSeparation, kHanging));
  out.push_back(make("doubling-stack-5", "5 cubes, edge doubling upward from 0.25 m (1:4096)", scenarios::doublingStack(5),
                     DriftMeasure::Displacement, kStack));
  // Time steps, 3 s of simulated time each.
  for (int hz : {1000, 240, 60, 30, 15}) {
    out.push_back(make("column-10-dt-1/" + std::to_string(hz), "column-10 at h = 1/" + std::to_string(hz) + " s, 3 s",
                       withDt(scenarios::column(10), hz, 3), DriftMeasure::Displacement, kStack));
    out.push_back(make("hanging-chain-20-dt-1/" + std::to_string(hz),
                       "hanging-chain-20 at h = 1/" + std::to_string(hz) + " s, 3 s",
                       withDt(scenarios::hangingChain(20), hz, 3), DriftMeasure::JointSeparation, kHanging));
  }
  // ERP and CFM at their ends (joints: erp; contacts: contact_erp; cfm is shared).
  struct Soft { const char* label; Real erp; Real cfm; };
  for (const Soft s : {Soft{"erp-0", 0, 0}, Soft{"erp-1", 1, 0}, Soft{"cfm-1", Real(0.2), 1},
                       Soft{"cfm-1e-12", Real(0.2), Real(1e-12)}}) {
    SceneDesc col = scenarios::column(10);
    col.solver.contact_erp = s.erp;
    col.solver.cfm = s.cfm;
    const std::string col_what = "column-10, contact_erp " + fmtG(s.erp) + ", cfm " + fmtG(s.cfm);
    out.push_back(make(std::string("column-10-") + s.label, col_what, col, DriftMeasure::Displacement, kStack));
    SceneDesc ch = scenarios::hangingChain(20);
    ch.solver.erp = s.erp;
    ch.solver.cfm = s.cfm;
    out.push_back(make(std::string("hanging-chain-20-") + s.label,
                       "hanging-chain-20, erp " + fmtG(s.erp) + ", cfm " + fmtG(s.cfm), ch,
                       DriftMeasure::JointSeparation, kHanging));
  }
  // Size of the problem.
  out.push_back(make("column-50", "50 boxes in one column", scenarios::column(50), DriftMeasure::Displacement, kStack));
  out.push_back(make("hanging-chain-1000", "1000 links (500 m) hanging, nudged", scenarios::hangingChain(1000),
                     DriftMeasure::JointSeparation, kHanging));
  // A thin rod tumbling at 1000 rad/s (zero gravity): the gyroscopic term.
  {
    SceneDesc s;
    s.gravity = Vec3::Zero();
    BodyDef rod;
    rod.name = "rod";
    rod.mass = 1;
    rod.angular_velocity = Vec3(1, Real(0.2), Real(0.1)).normalized() * 1000;
    rod.shapes.push_back(ShapeDesc::box(Vec3(0.005, 0.5, 0.005)));
    s.bodies.push_back(rod);
    // Torque-free: L is conserved exactly by the implicit-midpoint step
    // once its equation is solved (to 1e-10 |L| a step, 6e-8 over the 600
    // steps at worst); 1e-6 leaves room for that and nothing more.
    ExtremeCase c = make("rod-spin-1000", "1 m x 1 cm rod tumbling at 1000 rad/s, no gravity", s,
                         DriftMeasure::AngularMomentum, Real(1e-6));
    // The implicit-midpoint gyroscopic step is solved by Newton iterations
    // that converge for h |w| < 1 (dynamics/integrate.cpp): 1000 rad/s
    // needs h < 1 ms.
    c.extra_variants.push_back({"pgs 10 it x 20 sub", [](SolverSettings& st) { st.substeps = 20; }});
    c.extra_variants.push_back({"pgs 10 it x 60 sub", [](SolverSettings& st) { st.substeps = 60; }});
    out.push_back(c);
  }
  // 1 km/s into a 10 cm wall, with and without ccd.
  for (bool ccd : {true, false}) {
    SceneDesc s;
    s.gravity = Vec3::Zero();
    s.steps = 60;
    BodyDef wall;
    wall.name = "wall";
    wall.type = BodyType::Static;
    wall.position = Vec3(10, 0, 0);
    wall.shapes.push_back(ShapeDesc::box(Vec3(0.05, 2, 2)));
    BodyDef ball;
    ball.name = "bullet";
    ball.mass = 1;
    ball.ccd = ccd;
    ball.linear_velocity = Vec3(1000, 0, 0);
    ball.shapes.push_back(ShapeDesc::sphere(Real(0.1)));
    s.bodies.push_back(ball);
    s.bodies.push_back(wall);
    // A contact may rest as deep as the slop (5 mm): no deeper.
    ExtremeCase c = make(ccd ? "ccd-sphere-1km/s" : "sphere-1km/s-no-ccd",
                         std::string("r = 0.1 m sphere at 1000 m/s into a 10 cm wall, ccd ") + (ccd ? "on" : "off"), s,
                         DriftMeasure::WallPenetration, s.solver.slop);
    c.wall_x = Real(9.95);
    c.leading_radius = Real(0.1);
    out.push_back(c);
  }
  // Far from the origin.
  out.push_back(make("far-column-10", "column-10 moved to (1e5, 1e5, 1e5) m",
                     translated(scenarios::column(10), Vec3::Constant(1e5)), DriftMeasure::Displacement, kStack));
  out.push_back(make("far-hanging-chain-20", "hanging-chain-20 moved to (1e5, 1e5, 1e5) m",
                     translated(scenarios::hangingChain(20), Vec3::Constant(1e5)), DriftMeasure::JointSeparation,
                     kHanging));
  // Small and large objects (drift in box sizes).
  {
    // Drift in box sizes: 5 cm per metre of box is 0.05 box sizes.
    ExtremeCase c = make("column-10-1mm", "column of ten 1 mm cubes (1 mg each)", scaledColumn(10, Real(0.0005)),
                         DriftMeasure::Displacement, kStack);
    c.drift_scale = Real(0.001);
    c.extra_variants.push_back({"slop, margin, max correction scaled to 1 mm", [](SolverSettings& s) {
                                  s.slop = Real(5e-6);
                                  s.contact_margin = Real(2e-5);
                                  s.max_correction_velocity = Real(0.01);
                                }});
    out.push_back(c);
    ExtremeCase big = make("column-5-100m", "column of five 100 m cubes (1e9 kg each)", scaledColumn(5, 50),
                           DriftMeasure::Displacement, kStack);
    big.drift_scale = 100;
    big.extra_variants.push_back({"slop, margin, max correction scaled to 100 m", [](SolverSettings& s) {
                                    s.slop = Real(0.5);
                                    s.contact_margin = 2;
                                    s.max_correction_velocity = 1000;
                                  }});
    out.push_back(big);
  }
  // Redundant: two identical hinges (A singular); conflicting: two distance
  // joints asking 1 m and 2 m between the same points.
  {
    SceneDesc s;
    BodyDef b;
    b.name = "bob";
    b.mass = 1;
    b.position = Vec3(1, 0, 0);
    b.shapes.push_back(ShapeDesc::box(Vec3(0.5, 0.5, 0.5)));
    s.bodies.push_back(b);
    for (int k = 0; k < 2; ++k) {
      JointDef j;
      j.name = "hinge_" + std::to_string(k);
      j.type = JointType::Hinge;
      j.body_a = kWorldBody;
      j.body_b = BodyId{0};
      j.axis = Vec3::UnitZ();
      s.joints.push_back(j);
    }
    out.push_back(make("redundant-hinges", "two identical hinges on one pendulum (cfm 0: A singular)", s,
                       DriftMeasure::JointSeparation, kHinge));
    SceneDesc d;
    BodyDef ball;
    ball.name = "ball";
    ball.mass = 1;
    ball.position = Vec3(Real(1.5), 0, 0);
    ball.shapes.push_back(ShapeDesc::sphere(Real(0.1)));
    d.bodies.push_back(ball);
    for (Real len : {Real(1), Real(2)}) {
      JointDef j;
      j.name = "rope_" + fmtG(len);
      j.type = JointType::Distance;
      j.body_a = kWorldBody;
      j.body_b = BodyId{0};
      j.anchor_a = Vec3::Zero();
      j.anchor_b = ball.position;
      j.length = len;
      d.joints.push_back(j);
    }
    // The least-squares compromise has each joint 0.5 m off: that, plus a
    // swinging joint's 5 cm.
    out.push_back(make("conflicting-distances", "two distance joints asking 1 m and 2 m (0.5 m error is forced)", d,
                       DriftMeasure::JointSeparation, Real(0.5) + kSwing));
  }
  // A kinematic slab pressing down at 0.5 m/s on a column of 3 boxes.
  {
    SceneDesc s = scenarios::column(3);
    s.steps = 240;
    BodyDef slab;
    slab.name = "press";
    slab.type = BodyType::Kinematic;
    slab.position = Vec3(0, Real(3.5), 0);
    slab.linear_velocity = Vec3(0, Real(-0.5), 0);
    slab.shapes.push_back(ShapeDesc::box(Vec3(2, 0.5, 2)));
    s.bodies.push_back(slab);
    // The boxes are squeezed out no faster than the contact push-out cap
    // (max_correction_velocity, 10 m/s).
    ExtremeCase c = make("kinematic-crush", "kinematic slab pressing a 3-box column at 0.5 m/s for 4 s", s,
                         DriftMeasure::MaxSpeed, s.solver.max_correction_velocity);
    c.energy_bound = false;
    out.push_back(c);
  }
  // A small box on a long hinge arm (docs/constraints.md section 9).
  {
    SceneDesc s;
    BodyDef b;
    b.name = "box";
    b.mass = 1;
    b.position = Vec3(5, 0, 0);
    b.shapes.push_back(ShapeDesc::box(Vec3::Constant(0.05)));
    s.bodies.push_back(b);
    JointDef j;
    j.name = "hinge";
    j.type = JointType::Hinge;
    j.body_a = kWorldBody;
    j.body_b = BodyId{0};
    j.axis = Vec3::UnitZ();
    s.joints.push_back(j);
    out.push_back(make("long-arm-hinge", "0.1 m box on a 5 m hinge arm (m L^2 / I = 15000), released horizontally", s,
                       DriftMeasure::JointSeparation, kHinge));
  }
  return out;
}

ExtremeCase extremeCase(const std::string& name) {
  for (ExtremeCase& c : extremeCases())
    if (c.name == name) return c;
  throw InputError("extremes", "case", "no case named '" + name + "'");
}

ExtremeResult runCairn(const ExtremeCase& c, const SolverSettings& settings) {
  SceneDesc scene = c.scene;
  scene.solver = settings;
  // The joint watcher is told the case's own tolerance (its limit, when
  // tighter than the default 5 cm), as a user states theirs: the watchers
  // only read the step (a World steps bit for bit the same whatever their
  // tolerances), so the run is still the one at these settings.
  if (c.measure == DriftMeasure::JointSeparation)
    scene.solver.joint_drift = std::min(scene.solver.joint_drift, c.drift_limit);
  Tracker t(c);
  World w = buildWorld(scene);
  size_t seen = 0;
  for (int s = 0; s < scene.steps; ++s) {
    w.step(scene.dt);
    if (w.numericalEvents().size() > seen) {
      if (t.r.first_event.empty()) {
        const NumericalEvent& e = w.numericalEvents()[seen];
        t.r.first_event = "step " + std::to_string(e.step) + ", body '" + e.body_name + "': " + e.stage + " (" +
                          e.detail + ")";
      }
      seen = w.numericalEvents().size();
    }
    t.record(
        w.bodyCount(),
        [&](int i, Vec3& x, Quat& q, Vec3& v, Vec3& om) {
          const Body& b = cairn::detail::internals(w).body(BodyId{i});
          x = b.position;
          q = b.orientation;
          v = b.linear_velocity;
          om = b.angular_velocity;
        },
        cairn::detail::internals(w).jointSlots(), [&](int j) { return w.jointError(JointId{j}).linear; });
    if (!t.r.finite) break;  // cannot happen while the guard works: recorded, not hidden
  }
  t.r.numerical_events = static_cast<int>(w.numericalEvents().size());
  for (const Diagnostic& d : w.diagnostics()) {
    t.r.diagnostics += d.count;
    if (std::find(t.r.diagnostic_kinds.begin(), t.r.diagnostic_kinds.end(), d.kind) == t.r.diagnostic_kinds.end())
      t.r.diagnostic_kinds.push_back(d.kind);
  }
  return t.finish();
}

ExtremeResult runBullet(const ExtremeCase& c) {
  Tracker t(c);
  BulletOracle o(c.scene);
  for (int s = 0; s < c.scene.steps; ++s) {
    o.step();
    t.record(
        o.bodyCount(),
        [&](int i, Vec3& x, Quat& q, Vec3& v, Vec3& om) {
          const OracleBodyState st = o.state(i);
          x = st.position;
          q = st.orientation;
          v = st.linear_velocity;
          om = st.angular_velocity;
        },
        static_cast<int>(c.scene.joints.size()), [&](int j) { return o.jointAnchorSeparation(j).norm(); });
    if (!t.r.finite) break;
  }
  t.r.skipped = o.skipped();
  return t.finish();
}

bool holds(const ExtremeCase& c, const ExtremeResult& r) {
  return r.finite && r.numerical_events == 0 && r.bounded && r.drift < c.drift_limit;
}

bool reported(const ExtremeResult& r) { return r.diagnostics > 0 || r.numerical_events > 0; }

BestResult runBest(const ExtremeCase& c) {
  // 2: holds; 1: finite and bounded; 0: neither.
  const auto tier = [&](const ExtremeResult& r) {
    return holds(c, r) ? 2 : (r.finite && r.numerical_events == 0 && r.bounded ? 1 : 0);
  };
  BestResult best{"default", runCairn(c, c.scene.solver)};
  std::vector<SettingVariant> variants = standardVariants();
  variants.insert(variants.end(), c.extra_variants.begin(), c.extra_variants.end());
  for (const SettingVariant& v : variants) {
    SolverSettings s = c.scene.solver;
    v.apply(s);
    const ExtremeResult r = runCairn(c, s);
    const int t = tier(r), tb = tier(best.result);
    if (t > tb || (t == tb && t > 0 && r.drift < best.result.drift)) best = {v.label, r};
  }
  return best;
}

}  // namespace cairn::validation
