// Projected Gauss-Seidel over a coloured constraint graph: the step's
// velocity solve for every island solved by PGS. Islands share the sweeps
// but not their results: each island stops on its own (at the round-off
// fixed point or the tolerance) and has its own NNCG momentum, so an island
// steps exactly as it would alone.
//
// The constraints are of two kinds: contact manifolds, in the compact
// ContactBatch form solved by the wide kernels (contact_kernels.hpp), and
// row groups, the generic rows of one joint (or of a contact with rolling
// friction) solved in order one row at a time (ODE's quickstep row:
// pgs.hpp). Every constraint has a colour, and no two constraints of one
// colour share a dynamic body (Box2D v3's graph colouring, solver.c and
// constraint_graph.c): the constraints of a colour can be solved in any
// order, by vector lanes or by threads, with the same result. A sweep
// visits the colours in order (or, with randomize_order, in a seeded
// shuffled order), so the Gauss-Seidel order, and the result, depend only on
// the colouring, never on the instruction set or the thread count.
//
// Around the sweeps, as in pgs.hpp: warm start; NNCG momentum between
// sweeps with one beta per island (islands are independent problems);
// a stop at the round-off fixed point or the tolerance; then the
// position-correction passes from zero impulses (Baumgarte rows on the
// velocities, split-impulse rows on the pseudo-velocities); and, once per
// step, restitution.
#pragma once

#include "constraints/row.hpp"
#include "solver/colour_flow.hpp"
#include "solver/contact_batch.hpp"
#include "solver/contact_kernels.hpp"
#include "solver/huge_page_allocator.hpp"
#include "solver/joint_lanes.hpp"
#include "solver/pass_pipeline.hpp"
#include "solver/solver_body.hpp"

#include <cstdint>
#include <span>
#include <vector>

namespace cairn {

class WorkerPool;

// The rows [begin, end) of one joint, solved in order; friction rows'
// normal_row counts from `begin`.
struct RowGroup {
  std::int32_t begin = 0, end = 0;
  std::int32_t island = 0;
};

inline constexpr std::int32_t kGroupAlone = -1;

// A joint's row group costs about 1 / kGroupsPerBatchVisit of a batch visit:
// the work the thresholds and the flow plan count (graph_solver.cpp,
// colour_flow.cpp).
inline constexpr int kGroupsPerBatchVisit = 8;

struct GraphSolveStats {
  int iterations = 0;       // the most sweeps any island took
  Real last_max_delta = 0;  // the largest impulse change of the islands' last sweeps
};

struct GraphColour {
  std::int32_t batch_begin = 0, batch_end = 0;  // ContactBatch range
  std::int32_t group_begin = 0, group_end = 0;  // RowGroup range
};

// One step's PGS problem, rebuilt by the step each (sub)step; vectors keep
// their capacity, so nothing is allocated once the scene has warmed up.
struct GraphProblem {
  std::vector<ContactBatch, HugePageAllocator<ContactBatch>> batches;  // by colour
  std::vector<RowGroup> groups;       // by colour
  std::vector<ConstraintRow> rows;    // the groups' rows
  std::vector<GraphColour> colours;
  int island_count = 0;
  // Parts solved side by side, each on one thread with no barrier between
  // its colours: part k is the colours [part_colour[k], part_colour[k + 1])
  // and the islands [part_island[k], part_island[k + 1]), and no constraint
  // of one part touches an island of another. Empty: one part, whose
  // colours the threads share instead (a scene of one large island: by the
  // flow schedule below, pass by pass with the pipeline below, or colour by
  // colour).
  // An island's constraints are coloured the same either way, and islands
  // never share a sweep's result (each stops on its own, with its own
  // momentum), so the parts change nothing but which thread does the work.
  std::vector<std::int32_t> part_colour, part_island;

  // Joints of a colour solved side by side (joint_lanes.hpp), made by
  // solveGraph from the rows: per group, its lane (JointLanes index times
  // kBatchLanes plus the lane; lane 0 is the lowest group, which visits
  // the others with it) or kGroupAlone.
  std::vector<JointLanes> joint_lanes;
  std::vector<JointLaneRow> joint_lane_rows;
  std::vector<std::int32_t> group_lanes;

  // Scratch, sized by the solver.
  std::vector<Real> row_change, row_dir, row_bias_lambda;
  std::vector<Real> group_delta, group_lambda;  // per group: this sweep's largest change and impulse
  std::vector<double> island_norm2, island_prev_norm2, island_beta;
  std::vector<double> island_active;            // 1 while the island's sweeps go on
  std::vector<double> island_delta, island_lambda;
  std::vector<int> island_iterations;
  // The split-impulse correction swept with the velocities (solveGraph's
  // `pseudo`): whether it was, and its islands' own figures.
  bool correction_swept = false;
  std::vector<double> bias_active, bias_delta, bias_lambda;
  // The batches' lane figures of a sweep, gathered per thread and island
  // as each batch's friction visit ends, while its lines are in cache:
  // [thread][island][the sweep's delta and lambda, the correction's delta
  // and lambda]. Reading them back from the batches after the sweep took
  // a walk of three cache lines per batch (0.45 ms a step on the
  // 5,050-box pyramid, on the calling thread alone).
  std::vector<double> lane_figures;
  int lane_figure_threads = 1;
  std::vector<std::vector<std::int32_t>> part_order;  // per part: its sweep's colour order
  std::vector<GraphSolveStats> part_stats;
  // One part with a pool: the colours' schedule without barriers
  // (colour_flow.hpp), planned at the first pass over this problem.
  ColourFlow flow;
  // One part and no flow schedule: consecutive passes overlapped, side by
  // side on a pool or interleaved on one thread (pass_pipeline.hpp),
  // planned at the first sweep.
  PassPipeline pipeline;

  // Whether the layout (colours, batches, groups, parts) is the one its
  // maker last made: false after clear(). The World keeps a layout from
  // step to step while the constraints it was made from are the same.
  bool laid_out = false;

  void clear() {
    laid_out = false;
    batches.clear();
    groups.clear();
    rows.clear();
    colours.clear();
    island_count = 0;
    part_colour.clear();
    part_island.clear();
    flow.reset();
    pipeline.reset();
    correction_swept = false;
  }
  bool empty() const { return batches.empty() && groups.empty(); }
};

struct GraphSolveOptions {
  int iterations = 10;
  Real tolerance = 0;
  Real sor = 1;
  bool nncg = true;
  bool randomize_order = false;
  int dynamic_end = 1;  // solver bodies [1, dynamic_end) may be written (0 is the world)
  int friction_rows = 2;  // tangent rows per contact point
  bool patch_friction = false;  // friction per manifold patch (solver/contact_batch.hpp)
  const ContactKernels* kernels = nullptr;
  WorkerPool* pool = nullptr;  // null: this thread only
  // Where planned, consecutive passes of a sweep overlap (pass_pipeline.hpp):
  // side by side on the pool, interleaved on one thread. false runs each
  // pass over every constraint before the next, the order that defines the
  // bits (the tests compare the two).
  bool overlap_passes = true;
  // With solveGraph's `pseudo`, the contacts' split-impulse correction is
  // swept with the velocities, each of its visits in a normal visit of the
  // same batch (one read of the batch for both); false leaves it to
  // solveGraphCorrection's pass of its own. The same bits either way.
  bool sweep_correction = true;
  // Joints of a colour with the same number of rows solved side by side in
  // the kernels' lanes (joint_lanes.hpp) where the colours are swept one
  // after another; false solves each alone. The same bits either way.
  bool joint_lanes = true;
};

// Warm start and the velocity sweeps. Given `pseudo` (zeroed by the
// caller), also the split-impulse correction where it is the contacts'
// alone (GraphSolveOptions::sweep_correction), which
// solveGraphCorrection then leaves out.
GraphSolveStats solveGraph(GraphProblem& p, std::span<SolverBody> bodies, const GraphSolveOptions& o,
                           std::uint64_t& rng_state, std::span<SolverBody> pseudo = {});

// The position-correction passes from zero impulses: rows whose correction
// is VelocityBias on `bodies`, then split-impulse rows (contact normals and
// PseudoVelocity joint rows) on `pseudo` (zeroed by the caller before
// solveGraph), unless solveGraph swept them. Returns false when there was
// nothing to correct on the pseudo-velocities (then they stay zero).
bool solveGraphCorrection(GraphProblem& p, std::span<SolverBody> bodies, std::span<SolverBody> pseudo,
                          const GraphSolveOptions& o);

// Restitution of the contacts that bounce, once per step after the last
// substep's solve (Box2D v3's b2ApplyRestitution, with the block of
// contact_kernels.hpp).
void solveGraphRestitution(GraphProblem& p, std::span<SolverBody> bodies, const GraphSolveOptions& o);

}  // namespace cairn
