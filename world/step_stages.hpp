// The stages of one step, in the order world/world_step.cpp runs them,
// each a free function over the World's state and the step's working state
// (StepContext): what a stage reads and writes is in its signature and its
// comment, and each is timed on its own (StepStats::stage_seconds).
#pragma once

#include "world/world_impl.hpp"

namespace cairn::detail {

// Springs, constant body forces and due timed impulses into the accumulators.
void applyForces(WorldImpl& w, StepContext& ctx);
// Broadphase, narrowphase, contact cache (warm-start impulses matched by
// feature), the pre-solve callback (world/world_contacts.cpp).
void collide(WorldImpl& w, StepContext& ctx);
// How far a shape's contacts must reach this step: the margin, and for a
// continuous-collision body the distance it can travel in the step (the
// narrowphase's margin and the broadphase's boxes alike).
inline Real contactReach(const Body& b, Real margin, Real h) {
  return b.ccd ? margin + h * b.linear_velocity.norm() : margin;
}

// Wakes what moving bodies touch, groups awake dynamic bodies into islands,
// picks each island's solver (world/islands.cpp).
void buildIslands(WorldImpl& w, StepContext& ctx);
// The solver order of the bodies for this step (world/step_prepare.cpp).
void orderSolverBodies(WorldImpl& w, StepContext& ctx);
// v* = v + h M^-1 f, the gyroscopic term, damping (world/step_integrate.cpp).
void integrateVelocities(WorldImpl& w, StepContext& ctx);
// Joint rows and contact constraints of every island for this substep:
// the coloured graph for PGS islands, generic rows for the others
// (world/step_prepare.cpp).
void prepareConstraints(WorldImpl& w, StepContext& ctx);
// The velocity solve and the position-correction passes (world/step_solve.cpp).
void solveConstraints(WorldImpl& w, StepContext& ctx);
// The contact kernels SolverSettings::simd asks for (the widest the CPU has
// for auto).
const ContactKernels& contactKernelsFor(const SolverSettings& s);
// x += h v, q <- exp(h w) q, with the split-impulse pseudo-velocities.
void integratePositions(WorldImpl& w, StepContext& ctx);
// Impulses kept for warm starting, joint feedback, joints that break. The
// contact lanes' impulses go back to the contact cache after the last
// substep; before it only where each substep prepares its contacts anew,
// since refreshed lanes carry their impulses themselves (else
// StepContext::lanes_unstored says the cache is behind them).
void storeImpulses(WorldImpl& w, StepContext& ctx);
// The contact lanes' impulses into the contact cache (the islands a guard
// stopped keep theirs); clears StepContext::lanes_unstored.
void storeLaneImpulses(WorldImpl& w, StepContext& ctx);
// Asks the cache for the contact in lane slot `slot` (none for an empty
// lane), ahead of the fill's or the store's visit to it: the lanes visit
// the contacts out of their storage order.
inline void prefetchLaneContact(const WorldImpl& w, const StepContext& ctx, size_t slot) {
  const std::int32_t ci = ctx.lane_contact[slot];
  if (ci >= 0) prefetchContact(w.contacts_[static_cast<size_t>(ci)]);
}
// Restitution, once per step after the last substep (world/step_solve.cpp).
void applyRestitution(WorldImpl& w, StepContext& ctx);
// Contact begin/end events (world/world_contacts.cpp).
void emitContactEvents(WorldImpl& w, StepContext& ctx);
// Sleeping bookkeeping (world/islands.cpp).
void updateSleep(WorldImpl& w, StepContext& ctx);
// Islands with method lcp over max_exact_rows go to PGS (world/islands.cpp).
void limitExactIslands(WorldImpl& w, StepContext& ctx);
// The watchers: energy rise, joint drift, penetration, tunnelling, limits
// reached, into World::diagnostics (world/step_diagnostics.cpp).
void watchStep(WorldImpl& w, StepContext& ctx);

// The non-finite guard (world/step_guard.cpp).
void saveStepStart(WorldImpl& w, StepContext& ctx);
void saveStepEnd(WorldImpl& w, StepContext& ctx);
void guardBodies(WorldImpl& w, StepContext& ctx, const char* stage);
// After the solve: islands whose velocities went non-finite are stopped;
// the stage named is "row building" when their rows held the non-finite
// value, else "constraint solve".
void guardSolve(WorldImpl& w, StepContext& ctx);

}  // namespace cairn::detail
