// The mass/inertia-ratio table of docs/constraints.md: a hinge limit
// stopping a box on an arm. A 1 kg box hangs on a hinge (axis z) whose
// anchor is L metres from its center; released horizontally, it swings
// down into the lower limit at -0.5 rad.
//
//   cube-1m-at-1m           1 m cube, L = 1   (m L^2 / I = 6; the joint test's case)
//   box-0.1m-at-5m          0.1 m cube, L = 5 (m L^2 / I = 15000)
//   box-0.1m-at-5m-no-limit the same without the limit
//
// With a tiny inertia on a long lever, the rows that act on the box's spin
// (the point rows across the lever, the limit row) are nearly dependent in
// the metric M^-1: one Gauss-Seidel sweep passes the impulse back and forth
// between them and gains about I / (m L^2) of the way each time.
//
// Part 1 simulates each case with solver.method pgs, direct and lcp, and in
// Bullet (validation/bullet_oracle.hpp). Part 2 takes one step's LCP (the
// impact step; without a limit, step 30) and solves it with PGS at rising
// sweeps, the direct solver and the exact LCP solver.
//
//   cairn_bench --table mass-ratio
#include "solver/direct_solver.hpp"
#include "solver/lcp_exact.hpp"
#include "solver/lcp_residual.hpp"
#include "solver/pgs.hpp"
#include "validation/bullet_oracle.hpp"
#include "cairn/scene.hpp"
#include "world/world_access.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

namespace cairn::bench {

namespace {

struct Case {
  const char* name;
  Real half_extent, arm;
  bool limit;
};
constexpr Case kCases[] = {{"cube-1m-at-1m", Real(0.5), 1, true},
                           {"box-0.1m-at-5m", Real(0.05), 5, true},
                           {"box-0.1m-at-5m-no-limit", Real(0.05), 5, false}};

SceneDesc caseScene(const Case& c, SolverMethod method, int iterations, int substeps) {
  SceneDesc s;
  s.dt = Real(1) / 60;
  s.steps = 600;
  s.solver.method = method;
  s.solver.iterations = iterations;
  s.solver.substeps = substeps;
  s.solver.sleeping = false;
  BodyDef b;
  b.name = "box";
  b.mass = 1;
  b.position = Vec3(c.arm, 0, 0);
  b.shapes.push_back(ShapeDesc::box(Vec3::Constant(c.half_extent)));
  s.bodies.push_back(b);
  JointDef j;
  j.name = "hinge";
  j.type = JointType::Hinge;
  j.body_a = kWorldBody;
  j.body_b = BodyId{0};
  j.anchor = Vec3::Zero();
  j.axis = Vec3::UnitZ();
  j.limit.enabled = c.limit;
  j.limit.lower = Real(-0.5);
  j.limit.upper = Real(0.5);
  s.joints.push_back(j);
  return s;
}

// Largest excursion of the box's center past the limit's swing angle
// (atan2 about the anchor, -0.5 rad) and largest anchor separation.
struct RunResult {
  double swing_overshoot = 0, separation = 0;
};

void track(RunResult& r, const Vec3& p, double separation) {
  r.swing_overshoot = std::max(r.swing_overshoot, -0.5 - std::atan2(double(p.y()), double(p.x())));
  r.separation = std::max(r.separation, separation);
}

RunResult simulate(const SceneDesc& scene) {
  World w = buildWorld(scene);
  RunResult r;
  for (int s = 0; s < scene.steps; ++s) {
    w.step(scene.dt);
    track(r, cairn::detail::internals(w).body(BodyId{0}).position, w.jointError(JointId{0}).linear);
  }
  return r;
}

RunResult simulateBullet(const SceneDesc& scene) {
  validation::BulletOracle o(scene);
  RunResult r;
  for (int s = 0; s < scene.steps; ++s) {
    o.step();
    track(r, o.state(0).position, o.jointAnchorSeparation(0).norm());
  }
  return r;
}

// One step's LCP as the World posed it: the rows (built at the state
// before the step), lambda set to the warm start the World used, and v*
// recovered from the step's result. The run uses a single-pass correction
// (InRhs) so that v = v* + M^-1 J^T lambda holds exactly after the solve.
struct StepLcp {
  std::vector<ConstraintRow> rows;
  std::vector<SolverBody> v_star;
};

StepLcp stepLcp(const Case& c) {
  SceneDesc scene = caseScene(c, SolverMethod::PGS, 1000, 1);
  scene.solver.position_correction = Correction::InRhs;
  World w = buildWorld(scene);
  for (int s = 0; s < scene.steps; ++s) {
    const std::vector<Real> warm = cairn::detail::internals(w).joint(JointId{0}).warm;
    w.step(scene.dt);
    const bool impact = w.lastStepStats().rows_by_kind[static_cast<int>(RowKind::Limit)] > 0;
    if (c.limit ? !impact : s != 29) continue;
    StepLcp p;
    p.rows = cairn::detail::internals(w).expandedRows();
    const Body& b = cairn::detail::internals(w).body(BodyId{0});
    p.v_star = {SolverBody{}, SolverBody{b.linear_velocity, b.angular_velocity}};
    for (ConstraintRow& r : p.rows) {
      p.v_star[1].v -= r.m_lin_b * r.lambda;
      p.v_star[1].w -= r.m_ang_b * r.lambda;
      r.lambda = std::clamp(warm[static_cast<size_t>(r.owner_row)], r.lo, r.hi);
    }
    return p;
  }
  return {};
}

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

}  // namespace

int massRatioTable() {
  std::printf("Simulation, 600 steps of 1/60 s: largest swing past -0.5 rad (rad) / largest anchor separation (m)\n\n");
  std::printf("| case | iterations x substeps | pgs | direct | lcp (exact) | Bullet |\n|---|---:|---:|---:|---:|---:|\n");
  for (const Case& c : kCases) {
    for (const auto& [it, sub] : {std::pair{10, 1}, {100, 1}, {1000, 1}, {10, 10}}) {
      std::string row = std::string("| ") + c.name + " | " + std::to_string(it) + " x " + std::to_string(sub) + " |";
      const auto cell = [&](const RunResult& r) {
        row += " " + (c.limit ? num(r.swing_overshoot) + " / " : std::string()) + num(r.separation) + " |";
      };
      for (SolverMethod m : {SolverMethod::PGS, SolverMethod::Direct, SolverMethod::LCP})
        cell(simulate(caseScene(c, m, it, sub)));
      cell(simulateBullet(caseScene(c, SolverMethod::PGS, it, sub)));
      std::printf("%s\n", row.c_str());
    }
  }

  for (const Case& c : kCases) {
    const StepLcp p = stepLcp(c);
    if (p.rows.empty()) continue;
    std::vector<ConstraintRow> exact_rows = p.rows;
    std::vector<SolverBody> exact_v = p.v_star;
    const ExactLcpResult ex = solveLcpExact(exact_rows, exact_v);
    const std::vector<double> exact = rowLambdas(exact_rows);
    std::printf("\n%s, the LCP of %s (%zu rows), from the warm start; exact solver residual %.2g\n\n", c.name,
                c.limit ? "the impact step" : "step 30", p.rows.size(), ex.residual);
    std::printf("| solver | residual (max norm) | distance to the exact lambda |\n|---|---:|---:|\n");
    PgsScratch scratch;
    for (int it : {10, 100, 1000, 10000}) {
      std::vector<ConstraintRow> rows = p.rows;
      std::vector<SolverBody> v = p.v_star;
      std::uint64_t rng = 1;
      applyWarmStart(rows, v);
      PgsSettings ps;
      ps.iterations = it;
      solvePgs(rows, v, ps, scratch, rng);
      std::printf("| PGS, %d sweeps | %.2g | %.2g |\n", it, lcpResidual(rows, v), lambdaDistance(rowLambdas(rows), exact));
    }
    for (int outer : {8, 1000}) {
      if (!c.limit && outer > 8) break;  // no unilateral row: one outer iteration is exact
      std::vector<ConstraintRow> rows = p.rows;
      std::vector<SolverBody> v = p.v_star;
      DirectSolver direct;
      DirectSolverOptions opt;
      opt.outer_iterations = outer;
      const DirectSolveStats ds = direct.solve(rows, v, opt);
      std::printf("| direct, %d outer iteration(s) (%d PGS sweeps on the unilateral rows each) | %.2g | %.2g |\n",
                  ds.outer_iterations, opt.inner_pgs_iterations, ds.residual, lambdaDistance(rowLambdas(rows), exact));
    }
  }
  return 0;
}

}  // namespace cairn::bench
