// The World behind the public face (include/cairn/world.hpp): the
// persistent state (bodies, shapes, joints, springs, the broadphase, the
// contact cache, settings, events) and the per-step working state
// (StepContext) that the stages of world/world_step.cpp hand to each other.
//
// Storage: bodies, shapes, joints and springs live in slot arrays addressed
// by the handles' indices; a destroyed object leaves a free slot (alive =
// false) that the next creation reuses with the next generation, so handles
// stay small integers and old ones are recognised as stale. Loops over a
// slot array skip dead slots.
//
// Internal: cairn's own tools (validation/, the command line, tests and
// benchmarks) reach this through WorldAccess (world/world_access.hpp);
// nothing here is installed.
#pragma once

#include "cairn/world.hpp"
#include "collision/broadphase.hpp"
#include "collision/manifold.hpp"
#include "constraints/contact.hpp"
#include "constraints/joint.hpp"
#include "constraints/row.hpp"
#include "dynamics/body.hpp"
#include "solver/direct_solver.hpp"
#include "solver/graph_solver.hpp"
#include "solver/lcp_exact.hpp"
#include "solver/pgs.hpp"
#include "solver/solver_body.hpp"
#include "solver/worker_pool.hpp"
#include "world/cost_split.hpp"
#include "world/diagnostic_index.hpp"
#include "world/pool_watch.hpp"

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace cairn {

struct Spring {
  SpringDef def;
  Vec3 local_a, local_b;  // anchors in the body frames (world points for the world)
  Real rest_length = 0;
  bool alive = true;
  std::uint32_t generation = 0;
};

// A shape in the World: which body and which of its shapes, and its
// broadphase proxy.
struct ShapeRef {
  BodyId body;
  std::int32_t index = 0;  // into the body's shapes
  std::int32_t proxy = -1;
  bool alive = true;
  std::uint32_t generation = 0;
};

namespace detail {

// A constraint of the PGS graph before it is laid out (world/step_prepare.cpp).
struct GraphItem {
  enum Kind : std::uint8_t { JointGroup, ContactGroup, Manifold } kind;
  std::int32_t index;  // joint or contact
  std::int32_t a, b;   // solver body indices
  std::int32_t island;
  bool operator==(const GraphItem&) const = default;
};

// What solver.method = "auto" learns of an island before choosing its
// solver (world/method_choice.cpp).
struct IslandFacts {
  Real min_mass = kInf, max_mass = 0;
  int joints = 0, contact_points = 0;
  bool drifted = false;   // a body of it was marked by an earlier joint_drift
  bool drifting = false;  // a joint of it has not closed for kDriftSteps steps
};

// What one step's stages hand each other (docs/architecture.md). Sized
// once and reused: after the first steps of a scene nothing here allocates.
struct StepContext {
  Real h = 0;   // the step
  Real hs = 0;  // the substep
  int substep = 0;

  // Islands (world/islands.cpp): per body slot the island of an awake
  // dynamic body, -1 otherwise.
  std::vector<std::int32_t> body_island;
  std::vector<std::int32_t> uf_parent;
  int island_count = 0;
  std::vector<SolverMethod> island_method;  // how each island is solved this step
  std::vector<MethodReason> island_reason;  // and why (world/method_choice.cpp)
  std::vector<char> body_drifted;           // per body slot: its island once left PGS for joint drift
  std::vector<IslandFacts> island_facts;    // scratch of the choice, per island
  std::vector<Real> joint_error_last;       // per joint slot: its anchor separation at the last step's start
  std::vector<std::uint8_t> joint_drift_run;  // per joint slot: steps in a row it was open and not closing

  // Solver order (world/step_prepare.cpp): index 0 for the world and every
  // static body, then the awake dynamic bodies island by island (1 to
  // dynamic_count), then the kinematic bodies.
  std::vector<std::int32_t> solver_of_body;  // per body slot
  std::vector<std::int32_t> body_of_solver;  // per solver index (-1 for 0)
  std::vector<std::int32_t> island_first_body;  // per island: its first solver index; then dynamic_count
  int dynamic_count = 0;
  int solver_count = 1;  // solver bodies in all
  static constexpr int static_index = 0;
  // Whether a body slot can move in this step: awake dynamic or kinematic,
  // the bodies with a solver index of their own. The others (static,
  // asleep through the step, destroyed) keep the state saveStepStart saved,
  // so the stages after the islands skip them on this compact array instead
  // of reading each Body (a sleeping pile's step was mostly such walks).
  bool moves(size_t body) const { return solver_of_body[body] != static_index; }
  std::vector<std::int32_t> kinematic_bodies;  // alive kinematic body slots, in order (world/islands.cpp)
  std::vector<std::uint8_t> body_flags;        // per body slot: the islands stage's view of it (world/islands.cpp)
  int asleep_bodies = 0;                       // alive bodies asleep after the islands stage
  std::vector<SolverBody> velocities;  // v, w per solver body
  std::vector<SolverBody> pseudo;      // split-impulse pseudo-velocities
  bool has_pseudo = false;
  std::vector<Vec3> orientation_offset;  // per body slot (implicit-midpoint gyroscopic term)
  std::vector<char> body_flag;           // per body slot: a stage's mark, reported after its threads

  // Constraints by island: per contact (in contacts_) and per joint.
  std::vector<std::int32_t> contact_island;
  std::vector<std::int32_t> joint_island;

  // The PGS islands' constraint graph and where its lanes and groups came from.
  GraphProblem graph;
  std::vector<std::int32_t> lane_contact;  // per batch lane (batch * 8 + lane): contact index, -1 padding
  std::vector<std::int32_t> group_joint;   // per row group: joint index, or -1 - contact index
  std::vector<char> island_pushing;        // per island: some contact deeper than the slop (being pushed out)
  std::vector<std::int32_t> lane_pushing;  // per batch lane: the island its contact pushes out, else -1
  std::vector<std::vector<Contact>> pair_contacts;  // collide's threads: per thread, the contacts of its pairs
  std::vector<std::vector<Manifold>> pair_manifolds;  // per thread, narrowphase scratch ([0]: the calling thread)
  // Per thread, what its pairs' contacts were: recycled manifolds, contacts
  // that began (no touching contact of their key last step) and contacts
  // that continue one of last step's (the same key).
  struct PairCounts {
    int recycled = 0, began = 0, continued = 0;
  };
  std::vector<PairCounts> pair_counts;
  // What collide found for the events (world/world_contacts.cpp): whether
  // some contact began, and whether each of last step's contacts has one
  // of its key this step (then none ended). Where unknown, both true and
  // false, and the events walk the lists.
  bool some_began = true;
  bool all_continued = false;
  std::vector<std::uint8_t> pair_sorted;  // per thread: whether its contacts came in key order
  CostSplit pair_split;                   // collide's threads: their ranges of pairs, by last step's time
  // Scratch of the colouring.
  std::vector<GraphItem> items, sorted_items;
  // What the graph's layout was last made from (layoutGraph): the items
  // and the few counts it reads besides. While they are the same, so is
  // the layout, and it is kept (GraphProblem::laid_out says it still is).
  struct LayoutInputs {
    std::vector<GraphItem> items;
    std::int32_t dynamic_count = -1, island_count = -1;
    int threads = 0;
    bool randomize_order = false;
    std::int64_t made = 0;  // layouts made (not kept) so far
  } layout_inputs;
  std::vector<std::int32_t> colour_of, adj_start, adj, level, queue, level_start;
  std::vector<std::int32_t> island_part, island_work;  // per island: its part of the graph, its constraints
  std::vector<std::int32_t> groups_in, manifolds_in, group_fill, lane_fill;
  std::vector<std::uint64_t> colour_used;  // per dynamic body: the current level's colours it is in

  // The other islands (direct, exact LCP): generic rows, island by island.
  std::vector<ConstraintRow> rows;
  std::vector<std::pair<std::int32_t, std::int32_t>> island_rows;  // row range per island (empty for PGS islands)
  std::vector<Real> correction_lambda;  // their correction passes' impulses

  // The joint position pass (world/joint_position_pass.cpp).
  std::vector<std::int32_t> position_joints;
  std::vector<Real> joint_error_start;  // per joint: anchor separation as the substep began
  std::vector<ConstraintRow> position_rows;
  std::vector<SolverBody> position_bodies;
  // Geometric stiffness per body slot (world/geometric_stiffness.cpp), the
  // slots it reached this substep, and the true world inverse inertias of
  // those whose rows see the augmented one (put back after the solve).
  std::vector<Mat3> stiffness;
  std::vector<std::uint8_t> stiffness_listed;
  std::vector<std::int32_t> stiffened;
  std::vector<std::pair<std::int32_t, Mat3>> true_inv_inertia;
  bool any_stiffness = false;

  // The non-finite guard (world/step_guard.cpp).
  struct SavedState {
    Vec3 x;
    Quat q;
    Vec3 v;
    Vec3 w;
    bool asleep = false;  // asleep when the step began (the watchers skip what cannot have moved)
  };
  std::vector<SavedState> step_start;  // per body slot: the last good state
  // Per body slot: T + V when the step began (0 for a body that is not
  // dynamic or not alive), as Body::kineticEnergy and -m g.x give it. A
  // body that does not move keeps it to the bit, so the watchers sum it
  // from here instead of reading the body again.
  std::vector<Real> start_energy;
  // Per body slot, the energy watcher's walk (world/step_diagnostics.cpp):
  // whether the body is summed at both ends, its T + V after the step, and
  // its share of the energy scale.
  std::vector<char> energy_counted;
  std::vector<Real> end_energy, energy_scale;
  std::vector<char> frozen_island;
  bool any_frozen = false;
  // The contact lanes hold impulses the contact cache does not have yet
  // (refreshed substeps: storeImpulses leaves them in the lanes).
  bool lanes_unstored = false;

  // Scratch.
  std::vector<std::int32_t> island_start, island_fill, island_root, wake_list, sleep_first;
  std::vector<Real> island_min;
  // Per island: its rows as estimated for the exact LCP's limit (world/islands.cpp).
  std::vector<std::int64_t> island_rows_estimate;
  // The stack watcher (world/step_diagnostics.cpp): the resting contacts
  // that hold one body up on another (lower -1: on a static or kinematic
  // body), and per body slot how far the stack under it has sunk and
  // whether a sunk body rests on it.
  struct Support {
    std::int32_t lower, upper;
    Real depth;
  };
  std::vector<Support> supports;
  // The penetration watcher's threads: per thread, what its range of the
  // contacts found (joined in range order: the contacts' order).
  struct ContactWatch {
    std::vector<Support> supports;
    std::vector<std::int32_t> too_deep;  // contacts deeper than the tolerance
    std::int64_t contacts = 0, points = 0;
    Real deepest = 0;
  };
  std::vector<ContactWatch> contact_watch;
  // The contact events' threads (world/world_contacts.cpp): per thread,
  // the Begin events of its range of the contacts and the End events of
  // its range of last step's.
  std::vector<std::vector<ContactEvent>> begin_events, end_events;
  // The proxies' refit on the pool's threads (world/world_proxies.cpp):
  // per thread, the shape slots whose proxies change, with their boxes.
  struct ProxyMove {
    std::int32_t slot;
    Aabb box;
  };
  std::vector<std::vector<ProxyMove>> proxy_moves;
  std::vector<Real> sunk;
  std::vector<char> sunk_below;
  // Body pairs a joint keeps from colliding, sorted (collide, shouldCollide).
  std::vector<std::uint64_t> jointed_pairs;
  // Last step's contacts' keys, in their (sorted) order: the pairs' binary
  // searches run over these 8 bytes a contact instead of touching a
  // 704-byte contact at every probe.
  std::vector<std::uint64_t> old_keys;
};

class WorldImpl {
 public:
  WorldImpl() = default;
  explicit WorldImpl(const Vec3& gravity) : gravity_(gravity) {}

  // --- Creation and destruction (world/world_bodies.cpp, world_joints.cpp)
  BodyId createBody(const BodyDef& def);
  void destroyBody(BodyId id);
  ShapeId addShape(BodyId id, const ShapeDesc& shape);
  void removeShape(ShapeId id);
  void setType(BodyId id, BodyType type);
  JointId createJoint(const JointDef& def);
  void destroyJoint(JointId id);
  SpringId createSpring(const SpringDef& def);
  void destroySpring(SpringId id);

  // Handle checks: throw HandleError for a stale or foreign handle.
  void check(BodyId id) const;
  void check(JointId id) const;
  void check(SpringId id) const;
  void check(ShapeId id) const;
  bool valid(BodyId id) const;
  bool valid(JointId id) const;
  bool valid(SpringId id) const;
  bool valid(ShapeId id) const;

  // --- Access for cairn's own tools (no generation check: indices).
  int bodySlots() const { return static_cast<int>(bodies_.size()); }
  int aliveBodies() const { return alive_bodies_; }
  const Body& body(BodyId id) const { return bodies_[static_cast<size_t>(id.index)]; }
  Body& body(BodyId id) { return bodies_[static_cast<size_t>(id.index)]; }
  const Body& body(int index) const { return bodies_[static_cast<size_t>(index)]; }
  Body& body(int index) { return bodies_[static_cast<size_t>(index)]; }
  const std::vector<Body>& bodies() const { return bodies_; }
  BodyId bodyId(int index) const { return BodyId{index, bodies_[static_cast<size_t>(index)].generation}; }
  BodyId findBody(const std::string& name) const;
  const std::vector<Spring>& springs() const { return springs_; }
  int jointSlots() const { return static_cast<int>(joints_.size()); }
  const Joint& joint(JointId id) const { return joints_[static_cast<size_t>(id.index)]; }
  Joint& joint(JointId id) { return joints_[static_cast<size_t>(id.index)]; }
  JointId jointId(int index) const { return JointId{index, joints_[static_cast<size_t>(index)].generation}; }
  JointId findJoint(const std::string& name) const;
  JointError jointError(JointId id) const;
  const JointFeedback& jointFeedback(JointId id) const { return joint(id).feedback; }
  void removeJoint(JointId id);  // breaks it: stops acting, handle valid
  // The generic rows of the last (sub)step's direct and exact islands.
  const std::vector<ConstraintRow>& rows() const { return ctx_.rows; }
  // Every row of the last (sub)step, the PGS islands' contacts expanded
  // to generic rows (for inspection and the exact solvers; allocates).
  std::vector<ConstraintRow> expandedRows() const;
  const std::vector<Contact>& contacts() const { return contacts_; }
  const std::vector<ShapeRef>& shapes() const { return shapes_; }
  const BroadPhase& broadPhase() const { return broadphase_; }
  BroadPhase& broadPhase() { return broadphase_; }
  // Deepest overlap of a contact's points at the bodies' present poses (0 if none overlaps).
  Real contactDepth(const Contact& c) const;
  BodyView view(BodyId id) const;
  BodyView view(int index) const;
  const StepContext& stepContext() const { return ctx_; }

  // --- Forces
  void applyForce(BodyId id, const Vec3& force, const Vec3& world_point);
  void applyCentralForce(BodyId id, const Vec3& force);
  void applyTorque(BodyId id, const Vec3& torque);
  void applyImpulse(BodyId id, const Vec3& impulse, const Vec3& world_point);
  void setKinematicVelocity(BodyId id, const Vec3& linear, const Vec3& angular);

  // --- Contacts
  const std::vector<ContactEvent>& contactEvents() const { return contact_events_; }
  void setContactCallback(ContactCallback cb) { contact_callback_ = std::move(cb); }
  void setCollisionFilterCallback(World::CollisionFilter f) { filter_callback_ = std::move(f); }
  void setPairMaterial(BodyId a, BodyId b, Real friction, Real restitution);
  bool shouldCollide(const Body& a, const Body& b, BodyId ia, BodyId ib) const;

  // --- Sleeping
  void wakeBody(BodyId id);
  void wakeIsland(std::int32_t island);
  void putIslandToSleep(BodyId id);
  bool isAsleep(BodyId id) const { return body(id).asleep; }

  // --- Settings
  const Vec3& gravity() const { return gravity_; }
  void setGravity(const Vec3& g);
  SolverSettings& settings() { return settings_; }
  const SolverSettings& settings() const { return settings_; }
  void setSettings(const SolverSettings& s);

  // --- Stepping (world/world_step.cpp)
  void step(Real h);
  int stepCount() const { return step_count_; }
  Real time() const { return time_; }
  const StepStats& lastStepStats() const { return stats_; }
  const std::vector<NumericalEvent>& numericalEvents() const { return numerical_events_; }
  const std::vector<Diagnostic>& diagnostics() const { return diagnostics_; }
  const std::vector<JointBreakEvent>& jointBreakEvents() const { return break_events_; }

  Real kineticEnergy() const;
  Real potentialEnergy() const;
  Vec3 linearMomentum() const;

  // --- Queries (world/world_queries.cpp)
  std::optional<RayHit> castRay(const Vec3& origin, const Vec3& translation, const QueryFilter& f) const;
  std::vector<RayHit> castRayAll(const Vec3& origin, const Vec3& translation, const QueryFilter& f) const;
  std::optional<ShapeCastHit> castShape(const ShapeDesc& shape, const Transform& pose, const Vec3& translation,
                                        const QueryFilter& f) const;
  std::vector<ShapeId> overlap(const ShapeDesc& shape, const Transform& pose, const QueryFilter& f) const;
  // Moves the proxies of the body's shapes (or, for kWorldBody, of every
  // awake body that can move) so their fat boxes hold the shapes where they
  // are now, stretched along v h (world/world_proxies.cpp).
  void moveProxies(BodyId only, Real h);
  void moveAwakeProxies(Real h);  // the step's end: only the bodies that moved (StepContext::moves)
  void refitProxy(std::size_t slot, Real h);  // the shape's fat box where its body now is
  // refitProxy's first half: false if the slot's fit is unchanged, else
  // the fit recorded and the shape's box (its tight box and reach) in `box`.
  bool fitProxy(std::size_t slot, Real h, Aabb& box);
  void forgetProxyFits();  // every proxy refitted at its next move (proxy_fits_)

  // ----------------------------------------------------------------------
  // The state itself. The step's stages (world/*.cpp) work on these.
  Vec3 gravity_ = Vec3(0, Real(-9.81), 0);
  SolverSettings settings_;
  std::vector<Body> bodies_;
  std::vector<std::int32_t> free_bodies_;
  int alive_bodies_ = 0;
  std::vector<Spring> springs_;
  std::vector<std::int32_t> free_springs_;
  std::vector<Joint> joints_;
  std::vector<std::int32_t> free_joints_;
  std::vector<ShapeRef> shapes_;
  std::vector<std::int32_t> free_shapes_;
  BroadPhase broadphase_;
  // Per shape slot, what its proxy was last fitted to: the body's pose,
  // velocity and CCD flag, the step and the margin. A refit from the same
  // inputs finds the same box (BroadPhase::moveProxy is idempotent), so it
  // is skipped: the step's start would otherwise refit every awake body
  // the previous step's end has just refitted. A cache, not state, one
  // entry per shape slot (registerShape adds them): snapshots leave it out
  // and a restore forgets it.
  struct ProxyFit {
    Vec3 x, v;
    Quat q;
    Real h = -1, margin = -1;  // h < 0: never fitted (or forgotten)
    bool ccd = false;          // reach() stretches a CCD body's box by v h
  };
  std::vector<ProxyFit> proxy_fits_;
  std::vector<Contact> contacts_;      // sorted by key
  std::vector<Contact> old_contacts_;  // scratch: last step's, for matching
  std::vector<Contact> ended_contacts_;  // touching contacts removed with a body or shape between steps
  std::vector<std::pair<int, int>> pairs_;
  std::vector<ContactEvent> contact_events_;
  ContactCallback contact_callback_;
  World::CollisionFilter filter_callback_;
  struct PairMaterial {
    std::uint64_t key;
    Real friction, restitution;
  };
  std::vector<PairMaterial> pair_materials_;  // sorted by key
  std::vector<std::int32_t> sleep_island_;   // per body slot: the island it fell asleep with

  StepContext ctx_;
  DirectSolver direct_solver_;  // keeps the structure's analysis (tree order or CHOLMOD's) while it holds
  DirectSolver position_solver_;  // the joint position pass's own (its rows' pattern differs)
  ExactLcpSolver exact_solver_;   // keeps its workspace: a steady exact island allocates nothing
  std::unique_ptr<WorkerPool> pool_;  // the step's threads; null: the calling thread alone
  // The pool set aside while its threads were found sharing their cores
  // with other work (world/pool_watch.hpp: for how many steps).
  std::unique_ptr<WorkerPool> parked_pool_;
  PoolWatch pool_watch_;
  // Whether the last step handed the pool a loop: only then is the pool
  // kept warm through the next (world/world_step.cpp), so a scene too
  // small to split (a lone body, a chain, an asleep pile) does not wake
  // a worker each step for nothing.
  bool warm_pool_ = false;
  // Which of the pool watch's rules apply (world/pool_watch.hpp): all by
  // default; the tests that must run every step on their threads whatever
  // else the machine runs apply none, and the test of the lost cores'
  // rule under the real scheduler that rule alone.
  PoolRules pool_rules_ = PoolRules::All;
  std::uint64_t rng_state_ = 0;
  bool rng_seeded_ = false;

  int step_count_ = 0;
  Real time_ = 0;
  StepStats stats_;
  std::vector<NumericalEvent> numerical_events_;
  std::vector<Diagnostic> diagnostics_;
  std::vector<int> diagnostic_last_step_;  // per diagnostic: the last step it was counted in
  DiagnosticIndex diagnostic_index_;       // where diagnose finds a body's record of a kind
  std::vector<JointBreakEvent> break_events_;

  // Forgets a body's diagnostics (it is being destroyed).
  void dropDiagnosticsOf(BodyId id);
  // Records a diagnostic on a body (index; -1: the world as a whole),
  // counted once per call, or once per step.
  void diagnose(std::int32_t body, const char* kind, const std::string& detail, bool once_per_step = false);
  // The step's watchers (world/step_diagnostics.cpp).
  Real energy_rise_ = 0;          // energy gained since the low point of the current stretch without external work
  bool external_forces_ = false;  // a force or torque applied through the API for the coming step
  std::vector<std::int32_t> forced_bodies_;  // body slots given a force or torque outside the step (cleared after it)
  void registerShape(BodyId id, std::int32_t index_in_body);
  void recomputeMass(Body& b, const std::string& object);
  void dropContactsOf(BodyId body, std::int32_t shape);  // shape -1: every shape of the body
  int createSpringIndex(const SpringDef& def, const std::string& object);
};

}  // namespace detail

void validateSettings(const SolverSettings& s);
// A shape definition of a body of `type` (throws InputError naming `obj`
// and `field`; world/world_bodies.cpp).
void validateShape(const std::string& obj, const std::string& field, const ShapeDesc& s, BodyType type);

}  // namespace cairn
