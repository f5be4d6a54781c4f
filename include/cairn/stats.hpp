/// @file
/// What a step reports about itself: the solver's quality (MuJoCo-style
/// solver statistics) and where the time went, stage by stage. Read it after
/// World::step through World::lastStepStats().
#pragma once

#include <cstdint>

namespace cairn {

/// The kinds of constraint rows, for counting.
enum class RowKind : std::uint8_t {
  JointLinear,   ///< positional rows of joints (anchors coincide, slider axes)
  JointAngular,  ///< angular rows of joints (hinge axes, fixed orientation)
  Limit,         ///< joint limits (unilateral)
  Motor,         ///< velocity motors (bounded by max force)
  ContactNormal,
  ContactFriction,
  ContactRolling,
  Count
};
inline constexpr int kRowKindCount = static_cast<int>(RowKind::Count);  ///< number of row kinds
const char* rowKindName(RowKind k);  ///< lower-case name

/// The stages of a step, in the order they run (docs/architecture.md walks
/// through them). Their wall times are kept in StepStats::stage_seconds.
enum class Stage : std::uint8_t {
  Forces,     ///< springs, user and scripted forces into the accumulators
  Collide,    ///< broadphase, narrowphase, contact cache, contact callback
  Islands,    ///< waking, island building
  BuildRows,  ///< joint rows and contact constraints prepared for the solver
  Solve,      ///< the velocity solve and the position-correction pass
  Integrate,  ///< velocities and positions
  Store,      ///< impulses kept for warm starting, joint feedback and breaking
  Events,     ///< contact begin/end events
  Sleep,      ///< sleeping bookkeeping
  Guards,     ///< the non-finite guard and the step's diagnostics
  Count
};
inline constexpr int kStageCount = static_cast<int>(Stage::Count);  ///< number of stages
const char* stageName(Stage s);  ///< lower-case name

/// Why an island got its solver method (world/method_choice.cpp).
enum class MethodReason : std::uint8_t {
  Setting,          ///< solver.method names one method for every island
  WellConditioned,  ///< auto: nothing PGS cannot carry within its sweeps
  MassRatio,        ///< auto: heaviest / lightest body of the island >= 100
  LongChain,        ///< auto: more joints than 4 x the PGS sweeps
  JointDrift,       ///< auto: a rigid joint open by more than 1 cm at the step's start
  Count
};
inline constexpr int kMethodReasonCount = static_cast<int>(MethodReason::Count);  ///< number of reasons
const char* methodReasonName(MethodReason r);  ///< lower-case name
inline constexpr int kSolverMethodCount = 4;  ///< SolverMethod's PGS, Direct, LCP, Auto

/// Why a step asked to run on worker threads ran on the calling thread
/// alone (world/pool_watch.hpp; docs/performance.md, "Threads").
enum class AloneReason : std::uint8_t {
  None,       ///< it ran on its threads, or was asked for one
  LostCores,  ///< its threads were losing their cores to other work
  Probe,      ///< the World timed steps alone against steps on its threads
  NoGain,     ///< steps alone were found faster than steps on its threads
  Count
};
inline constexpr int kAloneReasonCount = static_cast<int>(AloneReason::Count);  ///< number of reasons
const char* aloneReasonName(AloneReason r);  ///< lower-case name

/// What the last step reports (World::lastStepStats).
struct StepStats {
  int iterations = 0;        ///< PGS sweeps done (summed over substeps)
  double residual = 0;       ///< natural-map LCP residual after the solve (max norm, last substep)
  int rows = 0;              ///< rows solved (last substep)
  int contacts = 0;          ///< touching manifolds
  int contact_points = 0;    ///< points of the touching manifolds
  int recycled_contacts = 0; ///< manifolds kept without a narrowphase run (SolverSettings::recycle_distance)
  int islands = 0;           ///< awake islands solved
  int threads = 1;           ///< threads the step ran on: SolverSettings::threads, or 1 while the worker threads sit out steps (alone_because)
  AloneReason alone_because = AloneReason::None;  ///< why a step asked to use threads ran on one
  int sleeping_bodies = 0;   ///< bodies asleep after the step
  double max_penetration = 0;  ///< deepest contact after the step (m)
  double energy = 0;           ///< kinetic + potential (gravity, springs) after the step (J)
  int position_iterations = 0;  ///< Newton steps of the joint position pass (summed over substeps)
  double position_error = 0;    ///< largest joint row error |C| the position pass left (m or rad)
  int islands_by_method[kSolverMethodCount] = {};  ///< islands solved by each SolverMethod (Auto never)
  int islands_by_reason[kMethodReasonCount] = {};  ///< why (MethodReason)
  int rows_by_kind[kRowKindCount] = {};  ///< rows of each RowKind (last substep; they sum to rows)
  double stage_seconds[kStageCount] = {};  ///< wall time per stage (summed over substeps)
  double wall_seconds = 0;                 ///< the whole step
};

}  // namespace cairn
