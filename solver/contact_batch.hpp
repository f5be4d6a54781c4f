// The compact contact constraint, laid out for wide solving.
//
// A contact manifold (one to four points between two bodies, one normal)
// becomes one lane of a ContactBatch: eight manifolds side by side in
// structure-of-arrays form (each field an array of kBatchLanes doubles), so
// a kernel loads a field of four or eight manifolds with one vector load.
// The layout is the same whatever the instruction set: the AVX-512 kernel
// reads eight lanes at a time, the AVX2 kernel four, the portable kernel
// two (a batch whose manifolds fit in fewer lanes is swept at the narrower
// width: contact_kernel_impl.hpp, Narrowed), and all do the same
// arithmetic per lane in the same order, so their results are
// bit-identical (docs/performance.md, "SIMD lanes").
//
// Per manifold only what the solver reads, in the spirit of Box2D v3's
// b2ContactConstraintSIMD and Bullet's btSolverConstraint: the two bodies,
// their inverse masses and world inverse inertias (constant over the step),
// the normal, and per point the angular parts of its normal row's Jacobian
// (r_a x n and r_b x n), the anchors r_a and r_b (the tangent rows' r x t
// are formed from them on the fly: on a large scene the sweeps wait on
// memory, not on arithmetic), the effective masses, targets and impulses.
// M^-1 J^T is formed on the fly from the inverse masses, which the kernel
// holds in registers for the whole manifold:
//
//   J v   = u . (v_b - v_a) + (r_b x u) . w_b - (r_a x u) . w_a
//   dv_a  = -m_a^-1 u dl,   dw_a = -I_a^-1 (r_a x u) dl   (and + for b)
//
// Normal rows of one manifold are solved together as a block (pgs.hpp
// explains why): the block's matrix A_b = J_b M^-1 J_b^T + diag(cfm) and its
// Cholesky factor L are stored per lane, padded to 4 x 4 with identity rows
// for missing points. Friction is two tangent rows per point, t and n x t,
// each bounded by mu lambda_n of its point (ODE's and Bullet's pyramid), or
// with SolverSettings::patch_friction one patch per manifold: two tangent
// rows at the points' centre and a twist row about the normal (below).
#pragma once

#include <cstdint>

namespace cairn {

inline constexpr int kBatchLanes = 8;
inline constexpr int kMaxPoints = 4;

// Every field is written by the fill kernel before a sweep reads it: the
// batches are not zeroed when their array is resized (huge_page_allocator.hpp).
struct alignas(64) ContactBatch {
  using Lanes = double[kBatchLanes];
  std::int32_t body_a[kBatchLanes];  // solver body indices
  std::int32_t body_b[kBatchLanes];
  std::int32_t island[kBatchLanes];  // island index per lane (NNCG's momentum is per island)
  std::int32_t count[kBatchLanes];   // points in use (0 for a padding lane)

  // Mass data, constant over the step. Inverse inertia is the symmetric
  // world matrix (xx, yy, zz, xy, xz, yz); inverse mass per world axis
  // (degree-of-freedom locks zero some).
  Lanes ma[3], mb[3];
  Lanes ia[6], ib[6];

  Lanes n[3];  // normal, from a to b
  Lanes mu;    // friction coefficient
  Lanes cfm;   // impulse-form CFM of every row (ODE's CFM / h)

  struct Point {
    Lanes valid;            // 1 for a point in use, 0 for padding
    Lanes ran[3], rbn[3];   // r_a x n and r_b x n (anchors from the centers of mass, world)
    Lanes t[3];             // first tangent (the second is n x t)
    // r_a and r_b, the anchors from the centers of mass (world; zeros where
    // no tangent row is solved): the tangent rows' angular parts r x t_k
    // are formed from them on the fly, six numbers per point read instead
    // of twelve (Box2D v3's b2ContactConstraintPoint keeps the anchors too).
    Lanes ra[3], rb[3];
    Lanes rhs;              // velocity target of the normal row
    Lanes normal_mass;      // 1 / (A_ii + cfm)
    Lanes tangent_mass[2];  // 1 / (A_tt + cfm) for t and n x t
    Lanes lambda;           // accumulated normal impulse (warm-started)
    Lanes lambda_t[2];      // accumulated friction impulses along t and n x t
    Lanes max_lambda;       // the largest normal impulse of the step (restitution acts only where it was > 0)
    // NNCG (solver/pgs.hpp): this sweep's change of each impulse and the
    // momentum direction.
    Lanes change_n, change_t[2];
    Lanes dir_n, dir_t[2];
    // The correction pass and restitution.
    Lanes bias;             // position-correction target (split impulse pass)
    Lanes lambda_bias;      // the correction pass's impulse, from zero each step
    Lanes bounce;           // restitution's target normal velocity (-e times the approach speed), 0: no bounce
  } p[kMaxPoints];

  // The normal block: A_b (row-major lower triangle: 00, 10, 11, 20, 21, 22,
  // 30, 31, 32, 33) and its Cholesky factor in the same order.
  Lanes block[10];
  Lanes factor[10];

  // Friction per manifold patch (SolverSettings::patch_friction, as
  // ReactPhysics3D's contact solver and bepuphysics2's TangentFriction and
  // TwistFriction do it): the manifold's friction is two tangent rows at the
  // centre c of its points and one twist row about the normal, instead of
  // rows at every point. The tangent rows live in point 0's tangent fields
  // (t, ra and rb: the anchors of c, tangent_mass, lambda_t, change_t,
  // dir_t; the other points' stay zero) and are solved as one 2 x 2 block,
  // their impulse clamped to the disc of radius mu sum_i lambda_i (the
  // Coulomb cone of the patch's total load). The twist row J = (0, -n, 0, n)
  // is bounded by mu sum_i lambda_i d_i, d_i the point's distance from c in
  // the contact plane (each point's share of the load resisting turning
  // with its lever arm).
  Lanes patch_mass[3];  // inverse of the tangent rows' 2 x 2 block (+ cfm): 00, 01, 11
  Lanes twist_mass;     // 1 / (n . (I_a^-1 + I_b^-1) n + cfm); 0: no twist row
  Lanes lambda_twist;   // accumulated twist impulse (warm-started)
  Lanes change_twist, dir_twist;  // NNCG, as the points' change_t and dir_t
  Lanes arm[kMaxPoints];          // d_i

  // Per lane, written by every sweep: the largest impulse change and the
  // largest impulse (the per-island stopping test), and for NNCG the
  // squared norm of the changes.
  Lanes sweep_delta, sweep_lambda, change2;
  // The same figures of the correction pass's sweep (its own stopping test).
  Lanes bias_delta, bias_lambda;
};

// What the fill kernel reads to make a batch's eight lanes (the step
// gathers it, lane by lane, from the manifolds and their bodies: world/
// step_prepare.cpp). Per body: the center of mass, the orientation as a
// quaternion (x, y, z, w), the inverse mass and the translation locks'
// factors, the full world inverse inertia (row-major: the product may leave
// it unsymmetric by round-off, and the rows are made with all nine
// entries), and the velocities; per manifold its normal and materials; per
// point the anchors in the bodies' frames and what it carries from the
// last step. A point past the manifold's count is all zeros.
struct alignas(64) ContactBatchInput {
  using Lanes = double[kBatchLanes];
  struct Side {
    Lanes x[3], q[4];
    Lanes inv_mass, lin_factor[3];
    Lanes inv_inertia[9];
    Lanes v[3], w[3];
  } a, b;
  Lanes n[3];
  Lanes friction, restitution;
  struct Point {
    Lanes local_a[3], local_b[3];
    Lanes approach_speed, max_impulse, normal_impulse, friction_impulse[3];
  } p[kMaxPoints];
};

// The step's constants for the fill.
struct ContactFillParams {
  double h = 0;               // the substep
  double cfm = 0;             // impulse-form CFM (ODE's CFM / h)
  double contact_erp = 0;     // push-out rate: contact_erp / h of the depth past the slop
  double slop = 0;            // depth left uncorrected
  double threshold = 0;       // restitution threshold (m/s)
  double max_correction = 0;  // cap of the push-out speed
  double warm = 0;            // warm-start factor (0: cold)
  bool in_rhs = false;        // the push-out in the velocity target (Baumgarte), not the correction pass
  bool first_substep = true;  // restitution's largest impulse starts over
  int friction_rows = 2;      // tangent rows per point
  bool patch = false;         // friction per manifold patch (friction_rows is then not read)
};

// What a kernel sweep needs besides the batches.
struct ContactSweepParams {
  double sor = 1;
  int dynamic_end = 1;  // solver bodies [1, dynamic_end) may be written; 0 (the world) and the rest are read only
  bool gather_change = false;  // NNCG: record each row's change and the lane's squared norm
  int friction_rows = 2;       // tangent rows per point (SolverSettings::friction_directions)
  bool patch = false;          // friction per manifold patch (SolverSettings::patch_friction)
  // Per island: 1 while its sweeps go on, 0 once it has stopped (its lanes
  // are left as they are). Null: every island goes on.
  const double* island_active = nullptr;
  // The split-impulse correction swept with the velocities: non-null, each
  // normal visit also visits its lanes' correction blocks on `pseudo` (as
  // ContactKernels::solve_bias does, with pseudo_active for its islands),
  // while the batch's lines are in the cache.
  double* pseudo = nullptr;
  const double* pseudo_active = nullptr;
};

}  // namespace cairn
