// Geometric stiffness of the joints' rotations, for the islands solved
// directly or exactly (docs/extremes.md, "Heavy chains"), after Tournier,
// Nesme, Gilles and Faure, "Stable Constrained Dynamics", ACM TOG 34(4)
// (SIGGRAPH 2015), sections 4 and 5.
//
// A joint force f (world frame, last substep's) acting at the lever arm r
// of a body exerts the torque tau = r x f. When the body turns by dtheta
// the arm turns with it (dr = dtheta x r) while f keeps its direction
// (the point rows lie along world axes), so
//
//   d tau / d theta = [f]x [r]x = r f^T - (f . r) I,
//
// and the stiffness K = (f . r) I - r f^T. For a rod hung by its ends
// under tension T, K = T L/2 (I - u u^T) at each end: a torsion spring
// holding it in line, of rate sqrt(6 T / (m L)) for a rod of mass m and
// length L. The velocity solve treats this force explicitly (its
// Jacobian is that of the step's start), which is stable only while h
// times the rate stays below 2: 1:100 at h = 1/60 on 0.5 m links of 1 kg
// gives 1.8, 1:1000 gives 5.7, and the light links' swing grows every
// step until the chain tears. Tournier et al. move K into the implicit
// solve: the rows see the body's inertia as I + h^2 K, the backward-Euler
// treatment of the spring, stable at any h (it damps the stiff mode, as
// implicit Euler damps any spring it steps past). K is made symmetric and
// its negative eigenvalues are dropped (their section 5: a compressed
// joint's K is indefinite, and only the positive part is kept so the
// augmented inertia stays positive definite).
//
// Where it applies: every joint of every island solved directly or
// exactly, not only where the explicit step is unstable (h times the rate
// above 2). Restricting it to those bodies (the rate from the generalized
// eigenproblem K e = w^2 I e, per body) was measured and does not pay: the
// 40-link chains at 1:100 to 1:10,000 hold either way, and the whipping
// chains lose the same energy with or without it (chain-20, 1 kg spheres
// on 1 m links released horizontally, h = 1/60: 681 J lost with it
// everywhere, 680 to 691 J with it only above h w = 1, 2 or 4, 711 J
// without it, and the joints open wider the less of it there is: 0.5,
// 0.5, 1.2, 1.4 and 17 mm). Their energy goes to the velocity step itself,
// a projection at the step's start that is only first-order accurate
// (direct without the position pass: 743 J at h = 1/60, 49 J at 64
// substeps) and to the position pass's velocity update (with it: 634 J at
// 16 substeps, 365 J at 64); docs/extremes.md, "Whipping chains".
//
// The augmented inverse inertia replaces the body's in the rows of this
// substep (stiffenRotations, before the rows are built) and the true one
// comes back after the solve (restoreRotations): the integrators, the
// energy and the position pass all see the body's real inertia.
#include "world/geometric_stiffness.hpp"

#include "dynamics/positive_part.hpp"

namespace cairn::detail {

namespace {

bool stiffened(const StepContext& ctx, std::int32_t isl) {
  return isl >= 0 && ctx.island_method[static_cast<size_t>(isl)] != SolverMethod::PGS &&
         !(ctx.any_frozen && ctx.frozen_island[static_cast<size_t>(isl)]);
}

}  // namespace

void stiffenRotations(WorldImpl& w, StepContext& ctx) {
  ctx.any_stiffness = false;
  ctx.stiffened.clear();
  ctx.true_inv_inertia.clear();
  if (!w.settings_.geometric_stiffness) return;
  const auto add = [&](BodyId id, const Vec3& local, const Vec3& f) {
    if (id.isWorld() || !stiffened(ctx, ctx.body_island[static_cast<size_t>(id.index)])) return;
    const auto i = static_cast<size_t>(id.index);
    const Body& b = w.bodies_[i];
    if (b.rotation_locked) return;
    // Zeroed at the first joint that adds to it (a scene without joints
    // does not clear 72 bytes per body every substep); a slot is listed
    // the first time it is reached.
    if (!ctx.any_stiffness) {
      ctx.stiffness.assign(w.bodies_.size(), Mat3::Zero());
      ctx.stiffness_listed.assign(w.bodies_.size(), 0);
    }
    ctx.any_stiffness = true;
    if (!ctx.stiffness_listed[i]) {
      ctx.stiffness_listed[i] = 1;
      ctx.stiffened.push_back(id.index);
    }
    // K += (f . r) 1 - r f^T, entry by entry: the same sums as adding the
    // matrix, without a temporary that is stored eight bytes at a time and
    // read back sixteen (a stalled store forwarding at every joint end).
    const Vec3 r = b.rotation * local;
    const Real fr = f.dot(r);
    Mat3& k = ctx.stiffness[i];
    for (int c = 0; c < 3; ++c)
      for (int row = 0; row < 3; ++row) {
        if (row == c) k(row, c) += fr - r[row] * f[c];
        else k(row, c) -= r[row] * f[c];
      }
  };
  for (const Joint& j : w.joints_) {
    if (!j.alive || j.broken || j.def.softness.isSet()) continue;
    add(j.def.body_a, j.local_anchor_a, j.feedback.force_a);
    add(j.def.body_b, j.local_anchor_b, j.feedback.force_b);
  }
  if (!ctx.any_stiffness) return;
  const Real h2 = ctx.hs * ctx.hs;
  for (const std::int32_t i : ctx.stiffened) {
    const Mat3& k = ctx.stiffness[static_cast<size_t>(i)];
    if (k.isZero(0)) continue;  // forces that cancelled (or none yet)
    // A stretched joint's K (the common case, a chain under tension) is
    // semidefinite; a link pulled at both ends off its line has one small
    // negative eigenvalue (dynamics/positive_part.cpp takes both without
    // an eigendecomposition).
    const Mat3 kept = positivePart(Real(0.5) * (k + k.transpose()));
    if (!(kept.trace() > 0)) continue;
    Body& b = w.bodies_[static_cast<size_t>(i)];
    ctx.true_inv_inertia.emplace_back(i, b.inv_inertia_world);
    // R (c 1) R^T = c 1: a sphere's or a cube's world inertia is its own.
    const Mat3 inertia = isIsotropic(b.inertia_body) ? b.inertia_body : Mat3(b.rotation * b.inertia_body * b.rotation.transpose());
    b.inv_inertia_world = (inertia + h2 * kept).inverse();
  }
}

// The bodies have not turned since stiffenRotations (the solve moves no
// pose), so the saved inverse inertias are what updateDerived would compute.
void restoreRotations(WorldImpl& w, StepContext& ctx) {
  if (!ctx.any_stiffness) return;
  for (const auto& [i, inv] : ctx.true_inv_inertia) w.bodies_[static_cast<size_t>(i)].inv_inertia_world = inv;
  ctx.true_inv_inertia.clear();
  ctx.any_stiffness = false;
}

}  // namespace cairn::detail
