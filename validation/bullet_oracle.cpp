// The Bullet oracle: scene -> Bullet world, the step, and the states read
// back in cairn's terms. Shapes are built in bullet_shapes.cpp, joints in
// bullet_joints.cpp; docs/validation.md is the mapping table.
//
// One step of cairn (world/world_step.cpp) against one step here:
//
//   cairn                                  Bullet 3.24 (per internal step)
//   springs -> forces, held for the step   the same forces, applied before
//                                          each stepSimulation(h, 0)
//   v += h (g + F/m), gyroscopic, damping  damping (predictUnconstraintMotion),
//                                          then gravity, forces and the
//                                          gyroscopic impulse inside the solver
//   rows, PGS                              contacts + joints, PGS
//   x += h v, q <- exp(h w) q              the same (btTransformUtil), with
//                                          split-impulse push/turn velocities
//
// Kinematic bodies keep their scripted velocity: the pre-tick callback sets
// it (Bullet would otherwise derive it from the change of transform), and
// after the step the pose is advanced exactly as cairn advances it.
#include "validation/bullet_oracle.hpp"

#include "cairn/error.hpp"
#include "validation/bullet_internal.hpp"
#include "world/world_access.hpp"

#include <Eigen/Eigenvalues>

#include <chrono>
#include <cmath>
#include <mutex>
#include <sstream>

namespace cairn::validation {

using namespace detail;

namespace {

// ------------------------------------------------- friction and restitution
//
// cairn combines friction as sqrt(mu_a mu_b) and restitution as
// max(e_a, e_b); Bullet multiplies both. btManifoldResult asks the global
// gCalculateCombined{Friction,Restitution}Callback for every new or
// refreshed contact point; bodies the oracle tags get cairn's rule, any
// other collision object keeps the callback that was installed before.
constexpr int kCairnMaterial = 0x63616972;  // "cair", in btCollisionObject::m_userIndex2

CalculateCombinedCallback g_previous_friction = nullptr;
CalculateCombinedCallback g_previous_restitution = nullptr;

bool tagged(const btCollisionObject* a, const btCollisionObject* b) {
  return a->getUserIndex2() == kCairnMaterial && b->getUserIndex2() == kCairnMaterial;
}

btScalar cairnFriction(const btCollisionObject* a, const btCollisionObject* b) {
  if (tagged(a, b)) return std::sqrt(a->getFriction() * b->getFriction());
  if (g_previous_friction) return g_previous_friction(a, b);
  return btClamped(a->getFriction() * b->getFriction(), btScalar(-10), btScalar(10));  // Bullet's own
}

btScalar cairnRestitution(const btCollisionObject* a, const btCollisionObject* b) {
  if (tagged(a, b)) return std::max(a->getRestitution(), b->getRestitution());
  if (g_previous_restitution) return g_previous_restitution(a, b);
  return a->getRestitution() * b->getRestitution();
}

void installMaterialCallbacks() {
  static std::once_flag once;
  std::call_once(once, [] {
    g_previous_friction = gCalculateCombinedFrictionCallback;
    g_previous_restitution = gCalculateCombinedRestitutionCallback;
    gCalculateCombinedFrictionCallback = &cairnFriction;
    gCalculateCombinedRestitutionCallback = &cairnRestitution;
  });
}

int gyroscopicFlags(Gyroscopic g) {
  switch (g) {
    case Gyroscopic::Off: return 0;
    case Gyroscopic::Explicit: return BT_ENABLE_GYROSCOPIC_FORCE_EXPLICIT;
    case Gyroscopic::ImplicitEuler:
    case Gyroscopic::ImplicitMidpoint: return BT_ENABLE_GYROSCOPIC_FORCE_IMPLICIT_BODY;
  }
  return BT_ENABLE_GYROSCOPIC_FORCE_IMPLICIT_BODY;
}

const char* correctionName(Correction c) {
  switch (c) {
    case Correction::VelocityBias: return "baumgarte";
    case Correction::PseudoVelocity: return "split";
    case Correction::InRhs: return "single_pass";
  }
  return "unknown";
}

// gDeactivationTime's initial value (btRigidBody.cpp).
constexpr btScalar kBulletDeactivationTime = 2;

std::string fmt(Real v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

// Bullet's damping per internal step h is v *= (1 - c_b)^h; cairn's is
// v /= 1 + h c. Equal factors for c_b = 1 - (1 + h c)^(-1/h).
Real bulletDamping(Real c, Real h, bool match) {
  if (!match) return std::clamp(c, Real(0), Real(1));
  if (c <= 0) return 0;
  return 1 - std::pow(1 + h * c, -1 / h);
}

// Principal frame of a symmetric inertia tensor: I = R diag(d) R^T, R a
// rotation (det +1). Identity when the tensor is already diagonal.
void principalAxes(const Mat3& inertia, Quat& frame, Vec3& diag) {
  const Real scale = inertia.diagonal().cwiseAbs().maxCoeff();
  const Real off = std::max({std::abs(inertia(0, 1)), std::abs(inertia(0, 2)), std::abs(inertia(1, 2))});
  if (off <= Real(1e-12) * scale) {
    frame = Quat::Identity();
    diag = inertia.diagonal();
    return;
  }
  Eigen::SelfAdjointEigenSolver<Mat3> es(inertia);
  Mat3 r = es.eigenvectors();
  if (r.determinant() < 0) r.col(2) = -r.col(2);
  frame = Quat(r).normalized();
  diag = es.eigenvalues();
}

bool isIdentity(const Transform& t) {
  return t.p.norm() <= Real(1e-12) && std::abs(std::abs(t.q.w()) - 1) <= Real(1e-15);
}

}  // namespace

struct BulletOracle::Impl {
  struct BodyRecord {
    std::string name;
    BodyType type = BodyType::Dynamic;
    btRigidBody* rb = nullptr;       // the body joints attach to (a static body's first part)
    Quat principal = Quat::Identity();  // Bullet orientation = cairn orientation * principal
    Vec3 x = Vec3::Zero();           // static and kinematic pose (cairn's terms)
    Quat q = Quat::Identity();
    Vec3 v = Vec3::Zero(), w = Vec3::Zero();  // kinematic scripted velocity
    btVector3 force{0, 0, 0}, torque{0, 0, 0};    // BodyDef's constant loads
    std::vector<BodyDef::TimedImpulse> impulses;  // by time
    size_t next_impulse = 0;
  };
  struct JointRecord {
    std::string name;
    int a = -1, b = -1;  // scene body indices, -1 = world
    BuiltJoint built;
    bool added = false;
    bool clamp_reported = false;
  };
  struct SpringRecord {
    int a = -1, b = -1;
    Vec3 local_a = Vec3::Zero(), local_b = Vec3::Zero();  // Bullet body frames (world points for the world)
    Real rest = 0, stiffness = 0, damping = 0;
  };
  struct HeldForce {
    btRigidBody* rb;
    btVector3 force, torque;
  };

  OracleOptions options;
  SolverSettings solver;
  Real dt = Real(1) / 60, h = Real(1) / 60;
  int substeps = 1;

  std::unique_ptr<btDefaultCollisionConfiguration> config;
  std::unique_ptr<btCollisionDispatcher> dispatcher;
  std::unique_ptr<btDbvtBroadphase> broadphase;
  std::unique_ptr<btSequentialImpulseConstraintSolver> bt_solver;
  std::unique_ptr<btDiscreteDynamicsWorld> world;
  ShapeStore shapes;
  std::vector<std::unique_ptr<btRigidBody>> rigid_bodies;

  std::vector<BodyRecord> bodies;
  std::vector<JointRecord> joints;
  std::vector<SpringRecord> springs;
  std::vector<HeldForce> held;
  std::vector<std::string> skipped;
  double last_step_seconds = 0;
  int steps = 0;

  ~Impl() {
    if (!world) return;
    for (auto& j : joints)
      if (j.added) world->removeConstraint(j.built.constraint.get());
    for (auto& rb : rigid_bodies) world->removeRigidBody(rb.get());
  }

  btTransform transformOf(int body) const {
    if (body < 0) return btTransform::getIdentity();
    return bodies[static_cast<size_t>(body)].rb->getCenterOfMassTransform();
  }

  static void preTick(btDynamicsWorld* w, btScalar /*timeStep*/) {
    auto* self = static_cast<Impl*>(w->getWorldUserInfo());
    const Real max_w = self->solver.max_angular_velocity;
    for (const BodyRecord& b : self->bodies) {
      if (b.type == BodyType::Kinematic) {
        b.rb->setLinearVelocity(toBt(b.v));
        b.rb->setAngularVelocity(toBt(b.w));
      } else if (b.type == BodyType::Dynamic && std::isfinite(max_w)) {
        const btScalar n = b.rb->getAngularVelocity().length();
        if (n > max_w) b.rb->setAngularVelocity(b.rb->getAngularVelocity() * (max_w / n));
      }
    }
  }

  void configureSolver();
  void addBody(const Body& cb, const BodyDef& def, int index);
  btRigidBody* addRigidBody(const btRigidBody::btRigidBodyConstructionInfo& info, const BodyDef& def, int index);
  void addLoadsAndLocks(BodyRecord& rec, const Body& cb, const std::string& who);
  void applyImpulsesDue(Real now);
  void addJoint(const JointDef& def);
  void addSpring(const SpringDef& def);
  void holdSpringForces();
  void advanceKinematic(BodyRecord& b);
};

void BulletOracle::Impl::configureSolver() {
  btContactSolverInfo& info = world->getSolverInfo();
  const SolverSettings& s = solver;
  info.m_numIterations = s.iterations;
  if (s.method != SolverMethod::PGS && s.method != SolverMethod::Auto)  // auto: PGS unless an island needs more
    skipped.push_back(std::string("solver.method=") + solverMethodName(s.method) +
                      " has no Bullet equivalent: Bullet runs btSequentialImpulseConstraintSolver (PGS) with " +
                      std::to_string(s.iterations) + " iterations");
  if (s.orientation == OrientationIntegrator::Derivative)
    skipped.push_back("solver.orientation=derivative has no Bullet equivalent: Bullet integrates the orientation "
                      "with the exponential map (btTransformUtil::integrateTransform)");
  if (s.gyroscopic == Gyroscopic::ImplicitMidpoint)
    skipped.push_back("solver.gyroscopic=implicit_midpoint has no Bullet equivalent: mapped to "
                      "BT_ENABLE_GYROSCOPIC_FORCE_IMPLICIT_BODY (implicit Euler in the body frame, which loses "
                      "kinetic energy on tumbling bodies)");
  if (std::isfinite(s.max_correction_velocity))
    skipped.push_back("solver.max_correction_velocity=" + fmt(s.max_correction_velocity) +
                      " m/s not mapped: Bullet does not clamp the ERP or split-impulse push-out velocity");
  if (options.bullet_deactivation) {
    gDeactivationTime = kBulletDeactivationTime;  // process-global: undo what another oracle set
    skipped.push_back("bullet_deactivation: Bullet's own deactivation (0.8 m/s, 1 rad/s, gDeactivationTime 2 s) "
                      "whatever solver.sleeping says");
  } else if (s.sleeping) {
    gDeactivationTime = s.sleep_time;  // Bullet's is process-global
    skipped.push_back("solver.sleeping approximated: Bullet deactivates an island whose bodies all stayed below the "
                      "speed thresholds for gDeactivationTime = " + fmt(s.sleep_time) +
                      " s (a process-global) and zeroes their velocities");
  }
  skipped.push_back(std::string("solver.position_correction=") + correctionName(s.position_correction) +
                    " approximated: Bullet's joint rows carry -ERP/h C in their one pass and are never "
                    "warm-started" + (s.split_impulse ? "" : "; contacts without split impulse correct in that same pass"));
  if (s.contact_margin != Real(0.02))
    skipped.push_back("solver.contact_margin=" + fmt(s.contact_margin) +
                      " m not mapped: Bullet keeps contacts within its process-global gContactBreakingThreshold "
                      "(0.02 m) plus the shapes' collision margins");
  if (!options.match_cairn) {
    skipped.push_back("match_cairn=false: Bullet's own defaults for everything but the step and the iteration "
                      "count (docs/validation.md)");
    return;
  }
  info.m_erp = s.erp;
  info.m_erp2 = s.contact_erp;
  info.m_globalCfm = s.cfm;
  info.m_sor = s.sor;
  info.m_splitImpulse = s.split_impulse ? 1 : 0;
  info.m_splitImpulsePenetrationThreshold = 0;  // cairn splits every penetrating contact
  info.m_splitImpulseTurnErp = 1;               // and integrates the whole pseudo angular velocity
  info.m_linearSlop = s.slop;
  info.m_warmstartingFactor = s.warm_start_factor;
  info.m_restitutionVelocityThreshold = s.restitution_threshold;
  info.m_maxGyroscopicForce = BT_LARGE_FLOAT;  // cairn's explicit term is not clamped
  // Two friction rows per point, the first along the sliding direction
  // (Bullet's velocity-dependent direction, as cairn's contact rows choose t1).
  info.m_solverMode = SOLVER_SIMD | SOLVER_USE_2_FRICTION_DIRECTIONS;
  if (s.warm_start) info.m_solverMode |= SOLVER_USE_WARMSTARTING;
  if (s.randomize_order) {
    info.m_solverMode |= SOLVER_RANDMIZE_ORDER;
    bt_solver->setRandSeed(static_cast<unsigned long>(s.seed));
    skipped.push_back("solver.randomize_order approximated: Bullet shuffles its own row order with its own "
                      "generator (SOLVER_RANDMIZE_ORDER, seed " + std::to_string(s.seed) + ")");
  }
  if (s.tolerance > 0) {
    info.m_leastSquaresResidualThreshold = s.tolerance * s.tolerance;
    skipped.push_back("solver.tolerance approximated: Bullet stops when max (delta impulse x A)^2 <= tolerance^2 "
                      "(m_leastSquaresResidualThreshold), cairn when no impulse changed by more than tolerance");
  }
  if (std::isfinite(s.max_angular_velocity))
    skipped.push_back("solver.max_angular_velocity approximated: clamped at the start of each Bullet step (cairn "
                      "clamps after the velocity update)");
}

btRigidBody* BulletOracle::Impl::addRigidBody(const btRigidBody::btRigidBodyConstructionInfo& info,
                                              const BodyDef& def, int index) {
  rigid_bodies.push_back(std::make_unique<btRigidBody>(info));
  btRigidBody* rb = rigid_bodies.back().get();
  rb->setUserIndex(index);
  rb->setUserIndex2(options.match_cairn ? kCairnMaterial : -1);
  if (def.type == BodyType::Kinematic) {
    rb->setCollisionFlags((rb->getCollisionFlags() & ~btCollisionObject::CF_STATIC_OBJECT) |
                          btCollisionObject::CF_KINEMATIC_OBJECT);
  }
  // The group and mask bit patterns as Bullet's int filter fields.
  world->addRigidBody(rb, static_cast<int>(def.collision_group), static_cast<int>(def.collision_mask));
  if (def.type == BodyType::Kinematic) {
    rb->setActivationState(DISABLE_DEACTIVATION);  // the oracle drives it every step
  } else if (def.type == BodyType::Dynamic && !options.bullet_deactivation) {
    if (!solver.sleeping) rb->setActivationState(DISABLE_DEACTIVATION);  // no sleeping unless the scene sleeps
    else rb->setSleepingThresholds(solver.sleep_linear_velocity, solver.sleep_angular_velocity);
  }
  return rb;
}

void BulletOracle::Impl::addBody(const Body& cb, const BodyDef& def, int index) {
  BodyRecord rec;
  rec.name = cb.name;
  rec.type = cb.type;
  rec.x = cb.position;
  rec.q = cb.orientation;
  rec.v = cb.linear_velocity;
  rec.w = cb.angular_velocity;
  const std::string who = "body '" + cb.name + "'";
  const bool match = options.match_cairn;
  const MarginRule margins = match ? MarginRule::Thin : MarginRule::BulletDefault;

  const auto shapeName = [&](size_t k) { return who + " shapes[" + std::to_string(k) + "]"; };
  for (size_t k = 0; k < cb.shapes.size(); ++k)
    if (cb.shapes[k].type == ShapeType::Mesh)
      skipped.push_back(shapeName(k) + ": Bullet's triangle mesh is two-sided (cairn's pushes out along the "
                                       "counter-clockwise normal only)");

  if (cb.type == BodyType::Static) {
    // One Bullet body per shape (planes and meshes cannot sit in a compound
    // well); the first carries the joints.
    const btTransform t = toBt(cb.position, cb.orientation);
    const auto make = [&](btCollisionShape* shape, const btTransform& pose) {
      btRigidBody::btRigidBodyConstructionInfo info(0, nullptr, shape);
      info.m_startWorldTransform = pose;
      info.m_friction = def.friction;
      info.m_restitution = def.restitution;
      btRigidBody* rb = addRigidBody(info, def, index);
      if (!rec.rb) rec.rb = rb;
    };
    if (cb.shapes.empty()) make(shapes.make<btEmptyShape>(), t);
    for (size_t k = 0; k < cb.shapes.size(); ++k) {
      const ShapeDesc& s = cb.shapes[k];
      make(makeShape(s, shapes, skipped, shapeName(k), margins), t * toBt(s.local.p, s.local.q));
    }
    bodies.push_back(rec);
    return;
  }

  // Dynamic or kinematic: one body at the center of mass, in the principal frame.
  Vec3 diag = Vec3::Zero();
  if (cb.type == BodyType::Dynamic) principalAxes(cb.inertia_body, rec.principal, diag);
  const Quat to_bullet = rec.principal.conjugate();  // cairn body frame -> Bullet body frame
  btCollisionShape* shape = nullptr;
  if (cb.shapes.empty()) {
    shape = shapes.make<btEmptyShape>();
  } else if (cb.shapes.size() == 1 && isIdentity(Transform{to_bullet * cb.shapes[0].local.p,
                                                           to_bullet * cb.shapes[0].local.q})) {
    shape = makeShape(cb.shapes[0], shapes, skipped, shapeName(0), margins);
  } else {
    auto* compound = shapes.make<btCompoundShape>();
    for (size_t k = 0; k < cb.shapes.size(); ++k) {
      const ShapeDesc& s = cb.shapes[k];
      compound->addChildShape(toBt(to_bullet * s.local.p, (to_bullet * s.local.q).normalized()),
                              makeShape(s, shapes, skipped, shapeName(k), margins));
    }
    shape = compound;
  }
  const Real mass = cb.type == BodyType::Dynamic ? cb.mass : 0;
  btRigidBody::btRigidBodyConstructionInfo info(mass, nullptr, shape, toBt(diag));
  info.m_startWorldTransform = toBt(cb.position, (cb.orientation * rec.principal).normalized());
  info.m_friction = def.friction;
  info.m_restitution = def.restitution;
  info.m_linearDamping = bulletDamping(def.linear_damping, h, match);
  info.m_angularDamping = bulletDamping(def.angular_damping, h, match);
  btRigidBody* rb = addRigidBody(info, def, index);
  rec.rb = rb;
  rb->setFlags(match ? gyroscopicFlags(solver.gyroscopic) : BT_ENABLE_GYROSCOPIC_FORCE_IMPLICIT_BODY);
  rb->setLinearVelocity(toBt(cb.linear_velocity));
  rb->setAngularVelocity(toBt(cb.angular_velocity));

  if (cb.type == BodyType::Dynamic && (def.linear_damping > 0 || def.angular_damping > 0))
    skipped.push_back(who + ": damping approximated: the per-step factor 1/(1 + h c) is matched, but Bullet damps "
                            "before adding gravity and forces (cairn after)");
  if (cb.type == BodyType::Dynamic && def.ccd) {
    Real r = kInf;
    for (const auto& s : cb.shapes)
      if (innerRadius(s) > 0) r = std::min(r, innerRadius(s));
    if (std::isfinite(r)) {
      rb->setCcdMotionThreshold(r);
      rb->setCcdSweptSphereRadius(r);
    }
    skipped.push_back(who + ": ccd approximated by Bullet's swept-sphere CCD (motion threshold and sphere radius " +
                      fmt(std::isfinite(r) ? r : 0) + " m)");
  }
  if (cb.type == BodyType::Dynamic) addLoadsAndLocks(rec, cb, who);
  bodies.push_back(rec);
}

// Scripted loads: the constant force and torque are held like the springs'
// forces, and each timed impulse is applied before the first step that
// begins at or after its time, as cairn applies it. Locks: Bullet's linear
// factor is cairn's (world axes, exact); its angular factor scales
// J^-1 tau per world axis, which is cairn's exact constrained inverse
// inertia only while the inertia does not couple free and locked axes, and
// it cannot express a lock about an axis other than x, y or z.
void BulletOracle::Impl::addLoadsAndLocks(BodyRecord& rec, const Body& cb, const std::string& who) {
  rec.force = toBt(cb.constant_force);
  rec.torque = toBt(cb.constant_torque);
  rec.impulses = cb.impulses;
  rec.rb->setLinearFactor(toBt(cb.linear_factor));
  if (!cb.rotation_locked) return;
  const Vec3 diag = cb.rotation_projector.diagonal();
  if ((cb.rotation_projector - Mat3(diag.asDiagonal())).cwiseAbs().maxCoeff() > Real(1e-12)) {
    skipped.push_back(who + ": lock_rotation about an axis other than x, y or z has no Bullet equivalent: not locked");
    return;
  }
  rec.rb->setAngularFactor(toBt(diag));
  skipped.push_back(who + ": lock_rotation approximated by Bullet's angular factor (J^-1 tau scaled per axis; "
                          "cairn's exact constrained inertia agrees while the inertia couples no free and locked axis)");
}

void BulletOracle::Impl::applyImpulsesDue(Real now) {
  for (BodyRecord& b : bodies) {
    while (b.next_impulse < b.impulses.size() && b.impulses[b.next_impulse].time <= now) {
      const BodyDef::TimedImpulse& imp = b.impulses[b.next_impulse++];
      const btVector3 com = b.rb->getCenterOfMassPosition();
      b.rb->applyImpulse(toBt(imp.impulse), imp.point ? toBt(*imp.point) - com : btVector3(0, 0, 0));
      b.rb->activate(true);
    }
  }
}

void BulletOracle::Impl::addJoint(const JointDef& def) {
  JointRecord rec;
  rec.name = def.name;
  rec.a = def.body_a.isWorld() ? -1 : def.body_a.index;
  rec.b = def.body_b.isWorld() ? -1 : def.body_b.index;
  const auto end = [&](int i) {
    JointEnd e;
    if (i < 0) {
      e.body = &btTypedConstraint::getFixedBody();
    } else {
      e.body = bodies[static_cast<size_t>(i)].rb;
      e.dynamic = bodies[static_cast<size_t>(i)].type == BodyType::Dynamic;
    }
    return e;
  };
  JointContext ctx;
  ctx.solver = &solver;
  ctx.h = h;
  ctx.match = options.match_cairn;
  ctx.notes = &skipped;
  rec.built = buildJoint(def, end(rec.a), end(rec.b), ctx);
  if (rec.built.constraint) {
    // Bullet's fixed body is shared by every world: no constraint refs on it.
    const bool disable = !def.collide_connected && rec.a >= 0 && rec.b >= 0;
    world->addConstraint(rec.built.constraint.get(), disable);
    rec.added = true;
  }
  joints.push_back(std::move(rec));
}

void BulletOracle::Impl::addSpring(const SpringDef& def) {
  SpringRecord s;
  s.a = def.body_a.isWorld() ? -1 : def.body_a.index;
  s.b = def.body_b.isWorld() ? -1 : def.body_b.index;
  s.local_a = fromBt(transformOf(s.a).inverse() * toBt(def.anchor_a));
  s.local_b = fromBt(transformOf(s.b).inverse() * toBt(def.anchor_b));
  s.rest = def.rest_length.value_or((def.anchor_b - def.anchor_a).norm());
  s.stiffness = def.stiffness;
  s.damping = def.damping;
  springs.push_back(s);
}

// cairn's spring-damper (dynamics/forces.cpp), evaluated once per step and
// held for its substeps as cairn holds it.
void BulletOracle::Impl::holdSpringForces() {
  held.clear();
  for (const SpringRecord& s : springs) {
    const btTransform ta = transformOf(s.a), tb = transformOf(s.b);
    const btVector3 pa = ta * toBt(s.local_a), pb = tb * toBt(s.local_b);
    const btVector3 d = pb - pa;
    const btScalar len = d.length();
    if (len < btScalar(1e-12)) continue;
    const btVector3 n = d / len;
    const auto velocity = [&](int i, const btVector3& p) {
      if (i < 0) return btVector3(0, 0, 0);
      const btRigidBody* rb = bodies[static_cast<size_t>(i)].rb;
      return rb->getVelocityInLocalPoint(p - rb->getCenterOfMassPosition());
    };
    const btScalar rate = n.dot(velocity(s.b, pb) - velocity(s.a, pa));
    const btVector3 f = (s.stiffness * (len - s.rest) + s.damping * rate) * n;  // pulls a toward b
    const auto hold = [&](int i, const btVector3& force, const btVector3& p) {
      if (i < 0 || bodies[static_cast<size_t>(i)].type != BodyType::Dynamic) return;
      btRigidBody* rb = bodies[static_cast<size_t>(i)].rb;
      held.push_back({rb, force, (p - rb->getCenterOfMassPosition()).cross(force)});
    };
    hold(s.a, f, pa);
    hold(s.b, -f, pb);
  }
}

void BulletOracle::Impl::advanceKinematic(BodyRecord& b) {
  b.x += h * b.v;
  if (solver.orientation == OrientationIntegrator::ExponentialMap) {
    b.q = quatFromRotationVector(h * b.w) * b.q;
  } else {
    const Quat wq(0, b.w.x(), b.w.y(), b.w.z());
    b.q.coeffs() += Real(0.5) * h * (wq * b.q).coeffs();
  }
  b.q.normalize();
  const btTransform t = toBt(b.x, b.q);
  b.rb->setWorldTransform(t);
  b.rb->setInterpolationWorldTransform(t);
}

BulletOracle::BulletOracle(const SceneDesc& scene, const OracleOptions& options) : impl_(std::make_unique<Impl>()) {
  // cairn's own validation and mass properties: the oracle starts from
  // exactly the bodies cairn starts from.
  const World reference = buildWorld(scene);
  Impl& m = *impl_;
  m.options = options;
  m.solver = scene.solver;
  m.dt = scene.dt;
  m.substeps = scene.solver.substeps;
  m.h = scene.dt / scene.solver.substeps;
  if (options.match_cairn) installMaterialCallbacks();

  m.config = std::make_unique<btDefaultCollisionConfiguration>();
  m.dispatcher = std::make_unique<btCollisionDispatcher>(m.config.get());
  m.broadphase = std::make_unique<btDbvtBroadphase>();
  m.bt_solver = std::make_unique<btSequentialImpulseConstraintSolver>();
  m.world = std::make_unique<btDiscreteDynamicsWorld>(m.dispatcher.get(), m.broadphase.get(), m.bt_solver.get(),
                                                      m.config.get());
  m.world->setGravity(toBt(scene.gravity));  // before bodies: addRigidBody copies it
  m.configureSolver();

  for (size_t i = 0; i < scene.bodies.size(); ++i)
    m.addBody(cairn::detail::internals(reference).bodies()[i], scene.bodies[i], static_cast<int>(i));
  for (const JointDef& j : scene.joints) {
    JointDef d = j;
    if (d.name.empty()) d.name = "joint" + std::to_string(m.joints.size());
    m.addJoint(d);
  }
  for (const SpringDef& s : scene.springs) m.addSpring(s);
  m.world->setInternalTickCallback(&Impl::preTick, &m, true);
}

BulletOracle::~BulletOracle() = default;

void BulletOracle::step() {
  Impl& m = *impl_;
  const auto t0 = std::chrono::steady_clock::now();
  m.holdSpringForces();
  m.applyImpulsesDue(m.steps * m.dt + Real(1e-9) * m.dt);  // cairn's clock tolerance (world/step_integrate.cpp)
  for (int sub = 0; sub < m.substeps; ++sub) {
    for (const auto& f : m.held) {
      f.rb->applyCentralForce(f.force);
      f.rb->applyTorque(f.torque);
    }
    for (const auto& b : m.bodies) {
      if (b.type != BodyType::Dynamic || (b.force.isZero() && b.torque.isZero())) continue;
      b.rb->applyCentralForce(b.force);
      b.rb->applyTorque(b.torque);
    }
    m.world->stepSimulation(m.h, 0);  // maxSubSteps = 0: exactly one internal step of h
    for (auto& b : m.bodies)
      if (b.type == BodyType::Kinematic) m.advanceKinematic(b);
  }
  m.last_step_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ++m.steps;
  for (auto& j : m.joints) {
    if (j.clamp_reported || !j.built.plan || !j.built.plan->clamped) continue;
    j.clamp_reported = true;
    m.skipped.push_back("joint '" + j.name + "': a soft row needed a Bullet CFM above 0.5 x its effective mass "
                        "(CFM/h > 0.5 J M^-1 J^T), where Bullet's joint iteration converges slowly (and diverges "
                        "from 1 up); clamped to 0.5, so the row is stiffer in Bullet than in cairn");
  }
}

int BulletOracle::bodyCount() const { return static_cast<int>(impl_->bodies.size()); }

OracleBodyState BulletOracle::state(int body) const {
  const Impl::BodyRecord& b = impl_->bodies.at(static_cast<size_t>(body));
  OracleBodyState s;
  if (b.type != BodyType::Dynamic) {
    s.position = b.x;
    s.orientation = b.q;
    if (b.type == BodyType::Kinematic) {
      s.linear_velocity = b.v;
      s.angular_velocity = b.w;
    }
    return s;
  }
  const btTransform& t = b.rb->getCenterOfMassTransform();
  s.position = fromBt(t.getOrigin());
  s.orientation = (fromBt(t.getRotation()) * b.principal.conjugate()).normalized();
  s.linear_velocity = fromBt(b.rb->getLinearVelocity());
  s.angular_velocity = fromBt(b.rb->getAngularVelocity());
  return s;
}

const std::vector<std::string>& BulletOracle::skipped() const { return impl_->skipped; }

Vec3 BulletOracle::jointAnchorSeparation(int joint) const {
  const Impl::JointRecord& j = impl_->joints.at(static_cast<size_t>(joint));
  const btTransform ta = impl_->transformOf(j.a), tb = impl_->transformOf(j.b);
  const Vec3 pa = fromBt(ta * toBt(j.built.local_a)), pb = fromBt(tb * toBt(j.built.local_b));
  const Vec3 d = pb - pa;
  switch (j.built.measure) {
    case JointMeasure::Point: return d;
    case JointMeasure::OffAxis: {
      const Vec3 axis = fromBt(ta.getBasis() * toBt(j.built.local_axis_a));
      return d - axis * axis.dot(d);
    }
    case JointMeasure::Distance: {
      const Real len = d.norm();
      return len > 0 ? Vec3(d * ((len - j.built.length) / len)) : Vec3::Zero();
    }
    case JointMeasure::None: return Vec3::Zero();
  }
  return d;
}

bool BulletOracle::jointActive(int joint) const {
  const Impl::JointRecord& j = impl_->joints.at(static_cast<size_t>(joint));
  return j.added && j.built.constraint->isEnabled();
}

int BulletOracle::sleepingBodies() const {
  int n = 0;
  for (const Impl::BodyRecord& b : impl_->bodies)
    if (b.type == BodyType::Dynamic && b.rb->getActivationState() == ISLAND_SLEEPING) ++n;
  return n;
}

double BulletOracle::lastStepSeconds() const { return impl_->last_step_seconds; }

int BulletOracle::stepCount() const { return impl_->steps; }

}  // namespace cairn::validation
