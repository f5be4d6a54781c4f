// What a snapshot holds, field by field: the one place that lists the
// World's state (world/world_impl.hpp) for world/snapshot.cpp. Each
// function below is used both to write and to read (world/snapshot_archive.hpp),
// so the two cannot drift apart.
//
// Held: settings and gravity; every body, shape, joint and spring slot,
// dead slots included (their generations), with the free lists, so handles
// stay valid and new ones are handed out as they would have been; the
// broadphase's proxies (handles, fat boxes, free list); the contact cache
// with its warm-start impulses and the contacts waiting to report End; pair
// materials; islands and sleep (timers, sleeping islands, the last step's
// island of each body); the guard's last good states; the solver's random
// state; the clock, step counter and last step size; the events and
// diagnostics. Not held: callbacks (they stay with the World), worker
// threads and CHOLMOD's cached analysis (rebuilt on use; neither changes a
// result), per-step scratch and timings.
//
// Changing any structure listed here: update its function, bump
// kSnapshotVersion (world/snapshot.hpp) and the size check beside it,
// which is there to make a new field impossible to forget.
#include "world/snapshot.hpp"

#include "collision/mesh_bvh.hpp"
#include "world/snapshot_archive.hpp"

#include <map>
#include <memory>

namespace cairn::detail {

// (The io overloads are in cairn::detail itself, not an unnamed namespace:
// the archive's vector and optional templates find them by argument-
// dependent lookup.)
namespace {

// A new field changes these sizes (x86-64, libstdc++): the compiler then
// points here, to add it below and bump kSnapshotVersion.
static_assert(sizeof(SolverSettings) == 272, "SolverSettings changed: update snapshot_state.cpp");
static_assert(sizeof(Body) == 960, "Body changed: update snapshot_state.cpp");
static_assert(sizeof(ShapeDesc) == 208, "ShapeDesc changed: update snapshot_state.cpp");
static_assert(sizeof(Joint) == 3456, "Joint changed: update snapshot_state.cpp");
static_assert(sizeof(Spring) == 192, "Spring changed: update snapshot_state.cpp");
static_assert(sizeof(ShapeRef) == 24, "ShapeRef changed: update snapshot_state.cpp");
static_assert(sizeof(Contact) == 704, "Contact changed: update snapshot_state.cpp");
static_assert(sizeof(ContactPointState) == 120, "ContactPointState changed: update snapshot_state.cpp");

// Hulls and meshes are shared between shapes; each is written once and the
// shapes refer to it by index (-1: none).
struct SharedGeometry {
  std::vector<std::shared_ptr<const ConvexHullData>> hulls;
  std::vector<std::shared_ptr<const TriangleMeshData>> meshes;
  std::map<const void*, std::int32_t> index;  // writing: pointer -> index
};

}  // namespace

template <class Ar>
void io(Ar& ar, BodyId& id) {
  ar(id.index);
  ar(id.generation);
}
template <class Ar>
void io(Ar& ar, JointId& id) {
  ar(id.index);
  ar(id.generation);
}
template <class Ar>
void io(Ar& ar, Transform& t) {
  io(ar, t.p);
  io(ar, t.q);
}
template <class Ar>
void io(Ar& ar, Aabb& b) {
  io(ar, b.lo);
  io(ar, b.hi);
}

template <class Ar>
void io(Ar& ar, SolverSettings& s) {
  io(ar, s.method, 4);
  ar(s.iterations);
  ar(s.position_iterations);
  ar(s.geometric_stiffness);
  ar(s.tolerance);
  ar(s.sor);
  ar(s.warm_start);
  ar(s.warm_start_factor);
  ar(s.randomize_order);
  ar(s.nncg);
  ar(s.seed);
  ar(s.substeps);
  ar(s.prepare_contacts_each_substep);
  ar(s.threads);
  io(ar, s.simd, 4);
  ar(s.compute_residual);
  ar(s.erp);
  ar(s.cfm);
  io(ar, s.position_correction, 3);
  ar(s.contact_erp);
  ar(s.slop);
  ar(s.restitution_threshold);
  ar(s.split_impulse);
  ar(s.max_correction_velocity);
  ar(s.friction_directions);
  ar(s.patch_friction);
  ar(s.contact_margin);
  ar(s.recycle_distance);
  ar(s.recycle_angle);
  ar(s.sleeping);
  ar(s.sleep_linear_velocity);
  ar(s.sleep_angular_velocity);
  ar(s.sleep_time);
  ar(s.max_angular_velocity);
  io(ar, s.gyroscopic, 4);
  io(ar, s.orientation, 2);
  ar(s.max_pairs_per_shape);
  ar(s.max_exact_rows);
  ar(s.energy_rise);
  ar(s.joint_drift);
  ar(s.joint_drift_angle);
  ar(s.penetration_drift);
}

// --- Geometry ---------------------------------------------------------------

template <class Ar>
void io(Ar& ar, std::array<int, 2>& e) {
  ar(e[0]);
  ar(e[1]);
}
template <class Ar>
void io(Ar& ar, std::array<int, 3>& t) {
  ar(t[0]);
  ar(t[1]);
  ar(t[2]);
}

template <class Ar>
void io(Ar& ar, ConvexHullData& h) {
  io(ar, h.vertices);
  io(ar, h.faces);
  io(ar, h.face_normals);
  io(ar, h.face_offsets);
  io(ar, h.edges);
  if constexpr (Ar::reading) {
    const auto n = static_cast<int>(h.vertices.size());
    const auto inRange = [n](int v) { return v >= 0 && v < n; };
    if (h.face_normals.size() != h.faces.size() || h.face_offsets.size() != h.faces.size())
      ar.fail("a hull's faces, normals and offsets differ in number");
    for (const auto& f : h.faces) {
      if (f.size() < 3) ar.fail("a hull face has fewer than 3 vertices");
      for (int v : f)
        if (!inRange(v)) ar.fail("a hull face names a vertex it does not have");
    }
    for (const Vec3& v : h.vertices)
      if (!v.allFinite()) ar.fail("a hull vertex is not finite");
    for (const auto& e : h.edges)
      if (!inRange(e[0]) || !inRange(e[1])) ar.fail("a hull edge names a vertex it does not have");
  }
}

// A mesh keeps its vertices and triangles; its BVH is rebuilt on reading
// (the build is deterministic, so it comes back the same).
template <class Ar>
void io(Ar& ar, TriangleMeshData& m) {
  io(ar, m.vertices);
  io(ar, m.triangles);
  if constexpr (Ar::reading) {
    const auto n = static_cast<int>(m.vertices.size());
    for (const auto& t : m.triangles)
      for (int v : t)
        if (v < 0 || v >= n) ar.fail("a mesh triangle names a vertex it does not have");
    for (const Vec3& v : m.vertices)
      if (!v.allFinite()) ar.fail("a mesh vertex is not finite");
    if (m.triangles.empty()) ar.fail("a mesh has no triangles");
    buildMeshBvh(m);
  }
}

template <class Ar, class Data>
void ioTable(Ar& ar, std::vector<std::shared_ptr<const Data>>& table) {
  ioEach(ar, table, [&ar](std::shared_ptr<const Data>& entry) {
    if constexpr (Ar::reading) {
      auto data = std::make_shared<Data>();
      io(ar, *data);
      entry = std::move(data);
    } else {
      io(ar, const_cast<Data&>(*entry));  // the writer only reads
    }
  });
}

template <class Ar, class Data>
void ioShared(Ar& ar, std::shared_ptr<const Data>& ptr, const std::vector<std::shared_ptr<const Data>>& table,
              const SharedGeometry& g) {
  std::int32_t i = -1;
  if constexpr (!Ar::reading) {
    if (ptr) i = g.index.at(ptr.get());
  }
  ar(i);
  if constexpr (Ar::reading) {
    if (i < -1 || i >= static_cast<std::int32_t>(table.size())) ar.fail("a shape names a hull or mesh that is not there");
    ptr = i < 0 ? nullptr : table[static_cast<size_t>(i)];
  }
}

template <class Ar>
void io(Ar& ar, ShapeDesc& s, const SharedGeometry& g) {
  io(ar, s.type, 7);
  ar(s.radius);
  ar(s.half_height);
  io(ar, s.half_extents);
  io(ar, s.normal);
  ar(s.offset);
  ioShared(ar, s.hull, g.hulls, g);
  ioShared(ar, s.mesh, g.meshes, g);
  ar(s.source);
  io(ar, s.local);
  if constexpr (Ar::reading) {
    if (s.type == ShapeType::ConvexHull && !s.hull) ar.fail("a convex hull shape has no hull");
    if (s.type == ShapeType::Mesh && !s.mesh) ar.fail("a mesh shape has no mesh");
  }
}

void collectGeometry(const WorldImpl& w, SharedGeometry& g) {
  for (const Body& b : w.bodies_)
    for (const ShapeDesc& s : b.shapes) {
      if (s.hull && g.index.emplace(s.hull.get(), static_cast<std::int32_t>(g.hulls.size())).second)
        g.hulls.push_back(s.hull);
      if (s.mesh && g.index.emplace(s.mesh.get(), static_cast<std::int32_t>(g.meshes.size())).second)
        g.meshes.push_back(s.mesh);
    }
}

// --- Bodies, shapes, joints, springs ----------------------------------------

template <class Ar>
void io(Ar& ar, BodyDef::TimedImpulse& t) {
  ar(t.time);
  io(ar, t.impulse);
  io(ar, t.point);
}

template <class Ar>
void io(Ar& ar, Body& b, const SharedGeometry& g) {
  ar(b.name);
  io(ar, b.type, 3);
  ar(b.alive);
  ar(b.generation);
  io(ar, b.position);
  io(ar, b.orientation);
  io(ar, b.linear_velocity);
  io(ar, b.angular_velocity);
  ar(b.mass);
  ar(b.inv_mass);
  io(ar, b.inertia_body);
  io(ar, b.inv_inertia_body);
  io(ar, b.com_local);
  io(ar, b.linear_factor);
  io(ar, b.rotation_projector);
  ar(b.rotation_locked);
  io(ar, b.rotation);
  io(ar, b.inv_inertia_world);
  io(ar, b.force);
  io(ar, b.torque);
  io(ar, b.constant_force);
  io(ar, b.constant_torque);
  io(ar, b.impulses);
  auto next = static_cast<std::uint64_t>(b.next_impulse);
  ar(next);
  b.next_impulse = static_cast<size_t>(next);
  ar(b.friction);
  ar(b.restitution);
  ar(b.linear_damping);
  ar(b.angular_damping);
  ar(b.rolling_friction);
  ar(b.torsional_friction);
  ar(b.ccd);
  ar(b.collision_group);
  ar(b.collision_mask);
  ar(b.asleep);
  ar(b.sleeping_allowed);
  ar(b.sleep_timer);
  ioEach(ar, b.shapes, [&](ShapeDesc& s) { io(ar, s, g); });
  io(ar, b.shape_ids);
  io(ar, b.def_mass);
  io(ar, b.def_density);
  io(ar, b.def_inertia);
}

template <class Ar>
void io(Ar& ar, ShapeRef& r) {
  io(ar, r.body);
  ar(r.index);
  ar(r.proxy);
  ar(r.alive);
  ar(r.generation);
}

template <class Ar>
void io(Ar& ar, Softness& s) {
  io(ar, s.erp);
  io(ar, s.cfm);
  io(ar, s.stiffness);
  io(ar, s.damping);
  io(ar, s.frequency);
  io(ar, s.damping_ratio);
}

template <class Ar>
void io(Ar& ar, LimitDef& l) {
  ar(l.enabled);
  ar(l.lower);
  ar(l.upper);
  ar(l.restitution);
  io(ar, l.softness);
}

template <class Ar>
void io(Ar& ar, MotorDef& m) {
  ar(m.enabled);
  ar(m.target_velocity);
  io(ar, m.max_force);
  io(ar, m.target_position);
  io(ar, m.softness);
}

template <class Ar>
void io(Ar& ar, JointDef& d) {
  ar(d.name);
  io(ar, d.type, static_cast<int>(JointType::SixDof) + 1);
  io(ar, d.body_a);
  io(ar, d.body_b);
  io(ar, d.anchor);
  io(ar, d.axis);
  io(ar, d.axis2);
  io(ar, d.anchor_a);
  io(ar, d.anchor_b);
  io(ar, d.length);
  io(ar, d.limit);
  ar(d.swing_span1);
  ar(d.swing_span2);
  io(ar, d.motor);
  for (DofDef& dof : d.dofs) {
    io(ar, dof.mode, 3);
    io(ar, dof.limit);
    ar(dof.spring.enabled);
    ar(dof.spring.rest);
    io(ar, dof.spring.softness);
    io(ar, dof.motor);
  }
  io(ar, d.motor_axes);
  io(ar, d.motor_targets);
  io(ar, d.motor_max_torques);
  io(ar, d.softness);
  ar(d.break_force);
  ar(d.break_torque);
  ar(d.collide_connected);
}

template <class Ar>
void io(Ar& ar, Joint& j) {
  io(ar, j.def);
  ar(j.broken);
  ar(j.alive);
  ar(j.generation);
  io(ar, j.local_anchor_a);
  io(ar, j.local_anchor_b);
  io(ar, j.local_axis_a);
  io(ar, j.local_axis_b);
  io(ar, j.local_ref_a);
  io(ar, j.local_ref_b);
  io(ar, j.local_axis2_b);
  io(ar, j.local_frame_a);
  io(ar, j.local_frame_b);
  io(ar, j.rel_orientation0);
  ar(j.length);
  io(ar, j.local_motor_axes);
  io(ar, j.warm);
  io(ar, j.feedback.force_a);
  io(ar, j.feedback.torque_a);
  io(ar, j.feedback.force_b);
  io(ar, j.feedback.torque_b);
}

template <class Ar>
void io(Ar& ar, Spring& s) {
  ar(s.def.name);
  io(ar, s.def.body_a);
  io(ar, s.def.body_b);
  io(ar, s.def.anchor_a);
  io(ar, s.def.anchor_b);
  io(ar, s.def.rest_length);
  ar(s.def.stiffness);
  ar(s.def.damping);
  io(ar, s.local_a);
  io(ar, s.local_b);
  ar(s.rest_length);
  ar(s.alive);
  ar(s.generation);
}

// --- Contacts -------------------------------------------------------------------

template <class Ar>
void io(Ar& ar, ContactPointState& p) {
  ar(p.feature_id);
  io(ar, p.local_a);
  io(ar, p.local_b);
  ar(p.depth);
  ar(p.approach_speed);
  ar(p.normal_impulse);
  ar(p.max_impulse);
  io(ar, p.friction_impulse);
  ar(p.normal_row);
  ar(p.friction_row);
}

template <class Ar>
void io(Ar& ar, Contact& c) {
  ar(c.shape_a);
  ar(c.shape_b);
  ar(c.triangle);
  io(ar, c.body_a);
  io(ar, c.body_b);
  io(ar, c.normal);
  ar(c.count);
  if constexpr (Ar::reading) {
    if (c.count < 0 || c.count > 4) ar.fail("a contact has " + std::to_string(c.count) + " points (0 to 4)");
  }
  for (ContactPointState& p : c.points) io(ar, p);
  ar(c.friction);
  ar(c.restitution);
  ar(c.rolling_friction);
  ar(c.torsional_friction);
  io(ar, c.rolling_impulse);
  ar(c.rolling_row);
  ar(c.enabled);
  ar(c.touching);
  ar(c.began);
  ar(c.depth_after);
  io(ar, c.made_offset);
  io(ar, c.made_rotation);
  io(ar, c.made_normal);
}

template <class Ar>
void io(Ar& ar, WorldImpl::PairMaterial& m) {
  ar(m.key);
  ar(m.friction);
  ar(m.restitution);
}

// --- Events and the guard -------------------------------------------------------------

template <class Ar>
void io(Ar& ar, ContactEvent& e) {
  io(ar, e.type, 2);
  ar(e.step);
  io(ar, e.body_a);
  io(ar, e.body_b);
  ar(e.shape_a);
  ar(e.shape_b);
  io(ar, e.point);
  io(ar, e.normal);
  ar(e.impulse);
}

template <class Ar>
void io(Ar& ar, JointBreakEvent& e) {
  ar(e.step);
  io(ar, e.joint);
  ar(e.name);
  ar(e.force);
  ar(e.torque);
}

template <class Ar>
void io(Ar& ar, NumericalEvent& e) {
  ar(e.step);
  io(ar, e.body);
  ar(e.body_name);
  ar(e.stage);
  ar(e.island);
  ar(e.bodies_restored);
  ar(e.detail);
}

template <class Ar>
void io(Ar& ar, Diagnostic& d) {
  io(ar, d.body);
  ar(d.body_name);
  ar(d.kind);
  ar(d.detail);
  ar(d.first_step);
  ar(d.count);
}

template <class Ar>
void io(Ar& ar, StepContext::SavedState& s) {
  io(ar, s.x);
  io(ar, s.q);
  io(ar, s.v);
  io(ar, s.w);
  ar(s.asleep);
}

template <class Ar>
void io(Ar& ar, BroadPhase::ProxyState& p) {
  io(ar, p.fat);
  ar(p.user);
  ar(p.owner);
  ar(p.next_free);
  ar(p.alive);
}

// --- The world ------------------------------------------------------------------------

namespace {

template <class Ar>
void ioWorld(Ar& ar, WorldImpl& w) {
  SharedGeometry g;
  if constexpr (!Ar::reading) collectGeometry(w, g);
  ar.at("settings");
  io(ar, w.gravity_);
  io(ar, w.settings_);
  ar.at("hulls");
  ioTable(ar, g.hulls);
  ar.at("meshes");
  ioTable(ar, g.meshes);
  ar.at("bodies");
  ioEach(ar, w.bodies_, [&](Body& b) { io(ar, b, g); });
  io(ar, w.free_bodies_);
  ar(w.alive_bodies_);
  ar.at("springs");
  io(ar, w.springs_);
  io(ar, w.free_springs_);
  ar.at("joints");
  io(ar, w.joints_);
  io(ar, w.free_joints_);
  ar.at("shapes");
  io(ar, w.shapes_);
  io(ar, w.free_shapes_);
  ar.at("broadphase");
  std::vector<BroadPhase::ProxyState> proxies;
  int free_proxy = -1;
  if constexpr (!Ar::reading) {
    proxies = w.broadphase_.proxyStates();
    free_proxy = w.broadphase_.freeHead();
  }
  io(ar, proxies);
  ar(free_proxy);
  if constexpr (Ar::reading) {
    checkBroadPhaseState(w, proxies, free_proxy, ar.object());
    w.broadphase_.restore(proxies, free_proxy);
    w.forgetProxyFits();
    // The filter bits are the bodies' (not stored twice).
    for (const ShapeRef& ref : w.shapes_)
      if (ref.alive) {
        const Body& b = w.body(ref.body);
        w.broadphase_.setFilter(ref.proxy, b.collision_group, b.collision_mask);
      }
  }
  ar.at("contacts");
  io(ar, w.contacts_);
  io(ar, w.ended_contacts_);
  io(ar, w.pair_materials_);
  ar.at("sleep");
  io(ar, w.sleep_island_);
  io(ar, w.ctx_.body_island);
  io(ar, w.ctx_.step_start);
  ar.at("clock");
  ar(w.rng_state_);
  ar(w.rng_seeded_);
  ar(w.step_count_);
  ar(w.time_);
  ar(w.ctx_.h);
  ar.at("events");
  io(ar, w.contact_events_);
  io(ar, w.break_events_);
  io(ar, w.numerical_events_);
  io(ar, w.diagnostics_);
  // The watchers' running state, so a restored world reports as the
  // original would (world/step_diagnostics.cpp), and auto's memory of
  // islands that left PGS for joint drift (world/method_choice.cpp).
  ar.at("watchers");
  ioEach(ar, w.diagnostic_last_step_, [&ar](int& x) { ar(x); });
  ar(w.energy_rise_);
  ar(w.external_forces_);
  ioEach(ar, w.ctx_.body_drifted, [&ar](char& x) {
    auto v = static_cast<std::uint8_t>(x);
    ar(v);
    x = static_cast<char>(v);
  });
  io(ar, w.ctx_.joint_error_last);
  ioEach(ar, w.ctx_.joint_drift_run, [&ar](std::uint8_t& x) { ar(x); });
  if constexpr (Ar::reading) {
    // Forces restored for the coming step are cleared after it, as the
    // API's are (world/world_step.cpp).
    w.forced_bodies_.clear();
    for (size_t i = 0; i < w.bodies_.size(); ++i)
      if (w.bodies_[i].force != Vec3::Zero() || w.bodies_[i].torque != Vec3::Zero())
        w.forced_bodies_.push_back(static_cast<std::int32_t>(i));
  }
}

}  // namespace

std::vector<std::uint8_t> writeSnapshotPayload(const WorldImpl& w) {
  SnapshotWriter out;
  ioWorld(out, const_cast<WorldImpl&>(w));  // the writer only reads
  return std::move(out.bytes);
}

void readSnapshotPayload(const std::uint8_t* data, size_t size, const std::string& object, WorldImpl& w) {
  SnapshotReader in(data, size, object);
  ioWorld(in, w);
  in.at("end");
  if (in.left() != 0) in.fail(std::to_string(in.left()) + " bytes follow the world's state");
  checkSnapshotState(w, object);
}

}  // namespace cairn::detail
