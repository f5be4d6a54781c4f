// A replay: what the browser viewer (viewer/, docs/viewer.md) draws. Plain
// data, independent of the World: the bodies and their shapes, one engine's
// motion frame by frame (cairn's), optionally a second one (Bullet's) with
// the instant the two part, and the overlays recorded while cairn ran
// (contacts, joints, sleep, islands).
//
// Motion and overlays are stored as float32 arrays in frame-major order,
// exactly as the page reads them (typed arrays decoded from base64), so a
// 1,000-body, 600-frame run stays a few tens of megabytes.
//
// Filled by validation/replay_record.cpp (from a running World) or
// validation/replay_csv.cpp (from `cairn run --out`'s CSV); written by
// validation/replay_page.cpp.
#pragma once

#include "cairn/defs.hpp"

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace cairn::validation {

struct ReplayBody {
  std::string name;
  BodyType type = BodyType::Dynamic;
  double mass = 0;                 // 0 for static and kinematic bodies
  std::vector<ShapeDesc> shapes;   // poses relative to the center of mass (as the World keeps them)
  Vec3 position = Vec3::Zero();    // center of mass at the start (static bodies keep it)
  Quat orientation = Quat::Identity();
};

struct ReplayJoint {
  std::string name;
  JointType type = JointType::Ball;
  int body_a = -1, body_b = -1;  // -1: the world
};

// One engine's motion: frame f, body b at [f * bodies + b].
struct ReplayTrack {
  std::vector<double> time;              // s, per frame
  std::vector<float> position;           // 3 per body: center of mass (m)
  std::vector<float> orientation;        // 4 per body: x, y, z, w (three.js order)
  std::vector<float> velocity;           // 3 per body (m/s); empty when not recorded
  std::vector<float> angular_velocity;   // 3 per body (rad/s, world); empty when not recorded
  int frames() const { return static_cast<int>(time.size()); }
};

// What only a running cairn World shows; empty when the replay came from a
// CSV (the page then says which overlays it lacks).
struct ReplayOverlays {
  bool recorded = false;
  std::vector<std::uint8_t> asleep;       // per frame and body: 1 asleep
  std::vector<std::int32_t> island;       // per frame and body: island (its lowest body index), -1 none
  // Contacts: one manifold per touching shape pair, with its points.
  // Frame f holds manifolds [manifold_begin[f], manifold_begin[f + 1]) and
  // their points from point_begin[f] on, manifold by manifold; the page
  // shows frame contact_frame[f]'s contacts (f itself unless thinned).
  std::vector<std::uint32_t> manifold_begin, point_begin;  // frames + 1 each
  std::vector<std::uint32_t> contact_frame;
  std::vector<float> manifold_normal;      // 3 per manifold: from body a to body b
  std::vector<float> manifold_friction;    // 3 per manifold: friction impulse on b, summed over its points (N s)
  std::vector<std::int32_t> manifold_body; // 2 per manifold: a, b
  std::vector<std::uint8_t> manifold_points;  // points per manifold (1..4)
  std::vector<float> point_position;       // 3 per point: midway between the two anchors (world)
  std::vector<float> point_impulse;        // normal impulse of the last (sub)step (N s)
  // Per frame and joint.
  std::vector<float> joint_anchor_a, joint_anchor_b;  // 3 each: anchors on a and on b (world)
  std::vector<float> joint_axis;          // 3: the joint axis on a (world)
  std::vector<float> joint_error;         // 2: linear (m), angular (rad)
  std::vector<float> joint_force_a, joint_force_b;    // 3 each: constraint force on a and on b (N)
};

// The first instant the two tracks part: the largest center-of-mass
// distance between the engines over all bodies exceeds the tolerance.
struct ReplayParting {
  double tolerance = 0;  // m
  int frame = -1;        // -1: never
  double time = 0;
  int body = -1;
  double distance = 0;   // m, at that frame
};

struct Replay {
  std::string title;
  std::string source;   // where the motion came from, for the page's header
  double dt = 1.0 / 60;
  int substeps = 1;     // contact impulses are the last substep's: force = impulse * substeps / dt
  Vec3 gravity = Vec3(0, -9.81, 0);
  std::vector<ReplayBody> bodies;
  std::vector<ReplayJoint> joints;
  ReplayTrack cairn;
  ReplayOverlays overlays;
  std::optional<ReplayTrack> bullet;  // same bodies and frames as cairn's
  std::optional<ReplayParting> parting;
  std::vector<std::string> notes;     // shown on the page (what is missing and why)

  int bodyCount() const { return static_cast<int>(bodies.size()); }
  int shapeCount() const;
};

// Keeps the contacts of every k-th frame only (frames in between show the
// last kept one), with the smallest k that brings the contact arrays within
// `max_bytes`: a pile of a thousand boxes has about four contact points
// per box, more bytes than its motion. Returns k.
int thinContacts(ReplayOverlays& o, std::size_t max_bytes);

// thinContacts with the page's budget (16 MB of contact arrays), noting on
// the page when frames were left out.
inline constexpr std::size_t kContactBudgetBytes = 16'000'000;
void fitContacts(Replay& replay);

// The first frame where the tracks' centers of mass are more than
// `tolerance` apart (over the frames both have).
ReplayParting findParting(const ReplayTrack& a, const ReplayTrack& b, int bodies, double tolerance);

}  // namespace cairn::validation
