// The contact solver's inner loops (and the joints' lanes, joint_lanes.hpp),
// one set per instruction set: portable (two doubles, any CPU), AVX2
// (four doubles) and AVX-512 (eight).
// Each set is compiled in its own translation unit with its own target
// flags (solver/contact_kernels_*.cpp) from the one template in
// contact_kernel_impl.hpp; the engine picks a set at run time from what the
// CPU supports (SolverSettings::simd), so one binary runs everywhere and
// uses the widest set it can. All sets give bit-identical results: the
// arithmetic per lane is the same and no floating-point contraction is
// allowed (-ffp-contract=off), so a wider set only does more lanes at once.
//
// Every function works on the batches [begin, end) of one colour (no two
// lanes of a colour share a dynamic body, so lanes never race) and may run
// on several threads over disjoint ranges.
#pragma once

#include "solver/contact_batch.hpp"
#include "solver/joint_lanes.hpp"

namespace cairn {

// `bodies` points at the solver bodies' velocities: 8 doubles per body,
// v at [0, 3) and w at [3, 6) (solver/solver_body.hpp).
struct ContactKernels {
  const char* name;
  int lanes;  // doubles per vector
  // Adds M^-1 J^T lambda of the carried impulses (normal and friction).
  void (*warm_start)(ContactBatch* batches, int begin, int end, double* bodies, const ContactSweepParams& p);
  // One projected Gauss-Seidel visit of every manifold's normal block, and
  // (a second pass, after every colour's normals) of its friction rows,
  // bounded by the normal impulses of the same sweep, as Bullet's
  // btSequentialImpulseConstraintSolver orders them. Each lane records its
  // largest change and impulse in sweep_delta and sweep_lambda (and, with
  // gather_change, NNCG's changes); the friction pass adds to them. With
  // ContactSweepParams::pseudo, each normal visit also takes solve_bias's
  // visit of the same lanes.
  void (*solve_normals)(ContactBatch* batches, int begin, int end, double* bodies, const ContactSweepParams& p);
  void (*solve_friction)(ContactBatch* batches, int begin, int end, double* bodies, const ContactSweepParams& p);
  // NNCG's momentum step (pgs.hpp): lambda += beta p projected on the
  // bounds, with beta per island (beta == 0: p = this sweep's change, no
  // step; beta > 1: restart, p = 0; beta < 0: the island has stopped,
  // nothing changes).
  void (*momentum)(ContactBatch* batches, int begin, int end, double* bodies, const double* island_beta,
                   const ContactSweepParams& p);
  // The split-impulse correction pass: normal blocks toward the bias
  // targets, on the pseudo-velocities, from lambda_bias; each lane records
  // its largest change and impulse in bias_delta and bias_lambda.
  void (*solve_bias)(ContactBatch* batches, int begin, int end, double* pseudo, const ContactSweepParams& p);
  // Restitution, once per step after the solve: each manifold's points
  // that carried a normal impulse and approached faster than the threshold
  // are driven to their bounce velocity (the others to no approach), by
  // projected sweeps on the normal block.
  void (*restitution)(ContactBatch* batches, int begin, int end, double* bodies, const ContactSweepParams& p);
  // Fills a batch's lanes from what the step gathered for them (body_a,
  // body_b, island and count are already set; the Cholesky factor and the
  // inverted effective masses are the step's, after this).
  void (*fill)(ContactBatch& batch, const ContactBatchInput& in, const ContactFillParams& p);
  // A later substep of a batch `fill` made at the step's first: each
  // point's separation and targets at the bodies' present poses (in: x, q
  // and the points' local anchors), the carried impulses warm-started again
  // (ContactFillParams::warm), the sweeps' figures cleared; masses,
  // Jacobians and the factor kept.
  void (*refresh)(ContactBatch& batch, const ContactBatchInput& in, const ContactFillParams& p);
  // One projected Gauss-Seidel visit of the joints in the lanes of
  // lanes[begin, end) (joint_lanes.hpp), each joint's rows in order, with
  // the bits of each joint's scalar visit; and NNCG's momentum step on
  // them (with beta per island, as `momentum`); and a correction pass's
  // visit of their rows whose Correction is `which`, toward bias_rhs from
  // lambda_bias. Use sor, dynamic_end, gather_change and island_active of
  // `p`.
  void (*solve_joint_lanes)(JointLanes* lanes, JointLaneRow* rows, int begin, int end, double* bodies,
                            const ContactSweepParams& p);
  void (*joint_lanes_momentum)(JointLanes* lanes, JointLaneRow* rows, int begin, int end, double* bodies,
                               const double* island_beta, const ContactSweepParams& p);
  void (*joint_lanes_bias)(JointLanes* lanes, JointLaneRow* rows, int begin, int end, double* bodies, int which,
                           const ContactSweepParams& p);
};

enum class SimdLevel { Portable, Avx2, Avx512 };

// The kernels of one level; throws std::invalid_argument if the level was
// not built into this library or the CPU lacks it.
const ContactKernels& contactKernels(SimdLevel level);
// The widest level built in and supported by this CPU.
SimdLevel bestSimdLevel();
bool simdLevelAvailable(SimdLevel level);
const char* simdLevelName(SimdLevel level);

}  // namespace cairn
