/// @file
/// Everything a user tunes about a step, with Bullet-like defaults where a
/// default matters when comparing (docs/scenarios.md). Scene files set
/// these under "solver" (docs/scene-format.md).
#pragma once

#include "cairn/math.hpp"

#include <cstdint>

namespace cairn {

/// Where a row's position feedback -ERP/h C goes (settings.hpp explains the
/// choice). InRhs is ODE's single pass; the other two solve it in a second
/// pass from zero impulses, so warm starting carries only the impulse that
/// holds the constraint, never last step's correction.
enum class Correction : std::uint8_t {
  InRhs,           ///< in rhs with the velocity target (ODE quickstep)
  VelocityBias,    ///< second pass, result added to the velocities (Baumgarte)
  PseudoVelocity   ///< second pass, result moves positions only (split impulse)
};

/// How the gyroscopic torque -w x (J w) enters the velocity update
/// (docs/dynamics.md compares them on a tumbling box).
enum class Gyroscopic {
  Off,             ///< ignored: w' = J^-1 tau only
  Explicit,        ///< forward Euler on the world-frame term (gains energy)
  ImplicitEuler,   ///< backward Euler in the body frame, one Newton step
                   /// (Bullet's default: stable but dissipative)
  ImplicitMidpoint ///< midpoint rule on the body-frame Euler equations with
                   /// the orientation advanced at the midpoint velocity:
                   /// conserves kinetic energy and L of a free body (default)
};

/// How the orientation quaternion follows the angular velocity.
enum class OrientationIntegrator {
  ExponentialMap,  ///< q <- exp(h w) q, exact for constant w (default)
  Derivative       ///< q <- normalize(q + h/2 w q), section 12.6.4's first method
};

/// Which vector instructions the contact solver uses. Auto: the widest this
/// CPU supports among those built in. All give bit-identical results
/// (docs/performance.md); Portable runs on any CPU.
enum class Simd { Auto, Portable, Avx2, Avx512 };

const char* simdName(Simd s);  ///< lower-case name, as in scene files

/// How an island's rows are solved: PGS sweeps over the coloured graph, the
/// direct block solve (a sparse factor of the bilateral rows: linear-time
/// for a tree of joints, CHOLMOD otherwise), the exact pivoting LCP solve
/// (docs/solvers-exact.md), or Auto: PGS unless the island is
/// ill-conditioned for it (world/method_choice.cpp).
enum class SolverMethod { PGS, Direct, LCP, Auto };

const char* solverMethodName(SolverMethod m);  ///< lower-case name, as in scene files
/// The solver settings of a World (World::setSettings).
struct SolverSettings {
  SolverMethod method = SolverMethod::Auto;  ///< the velocity solver, per island; Auto (default) picks per island (world/method_choice.cpp)
  int iterations = 10;          ///< PGS sweeps per step (Bullet: 10)
  /// Newton steps of the nonlinear joint position pass after each (sub)step,
  /// for islands solved directly or exactly (solver/position_pass.hpp); 0: off.
  int position_iterations = 4;
  /// Direct and exact islands: the joints' geometric stiffness in the
  /// inertia the velocity solve sees (world/geometric_stiffness.cpp).
  bool geometric_stiffness = true;
  Real tolerance = 0;           ///< early exit when no impulse changed by more than this in a sweep (N s); 0 = never
  Real sor = 1;                 ///< successive over-relaxation factor, (0, 2)
  bool warm_start = true;       ///< start from last step's impulses
  Real warm_start_factor = 1;   ///< scale applied to the carried impulses
  bool randomize_order = false; ///< shuffle rows each sweep (seeded, reproducible)
  bool nncg = true;             ///< PGS with NNCG momentum between sweeps (solver/pgs.cpp); false: plain PGS as Bullet
  std::uint64_t seed = 1;       ///< seed of the random row order (randomize_order): same seed, same run
  int substeps = 1;             ///< sub-steps per step
  /// With substeps: false (default), each manifold is prepared once per
  /// step and later substeps only refresh each point's separation and
  /// targets from the bodies' new poses, as Box2D v3's solver.c does (a
  /// batch with a bouncing point is prepared anew on the last substep, so
  /// that restitution adds no energy); true, every substep prepares its
  /// contacts anew at its own pose (anchors, tangents, effective masses,
  /// the normal block): dearer, and a body that turns within the step is
  /// then pushed along anchors of its present pose rather than a substep
  /// old. docs/performance.md measures both. Either way the graph's layout
  /// (order, colours, lanes) is made once per step.
  bool prepare_contacts_each_substep = false;
  int threads = 1;              ///< worker threads for the step (results are bit-identical for any count); while they lose their cores to other work the step runs on one (StepStats::threads)
  Simd simd = Simd::Auto;       ///< contact solver instruction set
  bool compute_residual = false;  ///< fill StepStats::residual (one extra pass over the rows)

  /// ODE-style softness: rows drive J v toward -ERP/h C, CFM softens them.
  Real erp = Real(0.2);
  Real cfm = 0;  ///< global CFM, ODE's units (m/(N s) for a linear row); 0: rigid rows
  /// Position correction of joint rows without a softness of their own:
  ///  VelocityBias   Baumgarte: -ERP/h C joins the velocities, solved in a
  ///                 second pass that is never warm-started (default)
  ///  PseudoVelocity split impulse: the correction moves positions only,
  ///                 adding no energy (but projecting a fast swing loses some)
  ///  InRhs          ODE's single pass: the correction is warm-started with
  ///                 the rest, which re-applies last step's correction and
  ///                 grows unstable on long chains at few iterations
  /// docs/constraints.md measures all three.
  Correction position_correction = Correction::VelocityBias;

  /// Contacts.
  Real contact_erp = Real(0.2);
  Real slop = Real(0.005);               ///< allowed penetration, m
  Real restitution_threshold = Real(0.2); ///< m/s: slower approach does not bounce
  bool split_impulse = true;              ///< contacts: push out with pseudo-velocities (Bullet's split impulse)
  Real max_correction_velocity = Real(10);  ///< m/s, clamp on ERP push-out
  /// Friction rows per contact point: 2, two tangents (a friction box,
  /// isotropic to within the box's corners); 1, one tangent along the
  /// sliding direction, or the carried friction impulse when at rest
  /// (Bullet's default, without SOLVER_USE_2_FRICTION_DIRECTIONS): a third
  /// fewer contact rows, and nothing resists a start of sliding across it
  /// until the next step turns the tangent. docs/performance.md measures it.
  int friction_directions = 2;
  /// Friction per manifold patch instead of per point, for islands solved
  /// by PGS: two tangent rows at the centre of a manifold's points, bounded
  /// together by the Coulomb cone of the manifold's total normal impulse,
  /// and one twist row about the normal (ReactPhysics3D's and
  /// bepuphysics2's contact friction): 4 + 3 rows for a four-point manifold
  /// instead of 4 + 8 (friction_directions 2) or 4 + 4 (1), isotropic.
  /// friction_directions is then not read; islands solved directly or
  /// exactly keep per-point rows. docs/contacts.md measures it.
  bool patch_friction = false;

  Real contact_margin = Real(0.02);  ///< m: contacts are made this far before touching (speculative)
  /// Contact recycling (Jolt's body pair cache): while a pair's relative
  /// pose stays within recycle_distance (m) and recycle_angle (rad) of the
  /// pose its manifold was made at, the manifold is kept (its points are
  /// fixed on the bodies; normal, depths and approach speeds follow the
  /// present poses) and the narrowphase is not run. 0 for either: the
  /// narrowphase runs every step. docs/collision.md measures the trade.
  Real recycle_distance = Real(0.001);
  Real recycle_angle = Real(0.0349);  ///< 2 degrees

  /// Sleeping: an island whose bodies all stay below both speeds for
  /// sleep_time seconds sleeps and costs nothing until woken.
  bool sleeping = true;
  Real sleep_linear_velocity = Real(0.05);   ///< m/s
  Real sleep_angular_velocity = Real(0.05);  ///< rad/s
  Real sleep_time = Real(0.5);               ///< s

  /// Safety nets for the extremes.
  Real max_angular_velocity = kInf;  ///< rad/s, per body

  // Bounds on what one step may cost (docs/reliability.md, "Bounded
  // resources"). Each is checked before the step allocates for it; going
  // past one is reported in World::diagnostics, never a std::bad_alloc.
  //  max_pairs_per_shape  other shapes one shape's broadphase query pairs
  //                       with: contacts grow linearly, not quadratically,
  //                       with coincident bodies (1,000 boxes at one spot
  //                       once made 499,500 contacts and 2.6 GB)
  //  max_exact_rows       constraint rows of an island solved by the exact
  //                       LCP (dense, cubic in its rows), estimated before
  //                       the rows are built as 3 per contact point, 3 more
  //                       per rolling contact and 6 per joint; a larger
  //                       island is solved by PGS for that step
  int max_pairs_per_shape = 64;  ///< broadphase pairs one shape may make per step (see above)
  int max_exact_rows = 300;      ///< largest island, in estimated rows, the exact LCP solves (see above)

  // Watchers (world/step_diagnostics.cpp): what goes wrong silently,
  // reported in World::diagnostics.
  //  energy_rise          energy gained without external work, as a
  //                       fraction of the energy scale (the kinetic energy
  //                       and the springs' energy, plus the work to lift
  //                       every dynamic body by its own size against gravity)
  //  joint_drift          anchor separation (m) of a joint
  //  joint_drift_angle    angle error (rad) of a joint
  //  penetration_drift    contact penetration (m) beyond the slop, and a
  //                       stack's sinking (m, its contacts' depths within
  //                       the slop summed down to the ground) beyond it
  Real energy_rise = Real(0.1);        ///< energy gained, fraction of the energy scale (see above)
  Real joint_drift = Real(0.05);       ///< joint anchor separation, m
  Real joint_drift_angle = Real(0.2);  ///< joint angle error, rad
  Real penetration_drift = Real(0.05); ///< contact penetration beyond the slop, m

  /// Integrators (section 12.6.3 and 12.6.4).
  Gyroscopic gyroscopic = Gyroscopic::ImplicitMidpoint;
  OrientationIntegrator orientation = OrientationIntegrator::ExponentialMap;  ///< how the orientation follows w
};

}  // namespace cairn
