// solver.method = "auto": each island gets the solver it needs and no
// more (docs/extremes.md, "auto").
//
// PGS converges at a rate set by the condition of A = J M^-1 J^T: a row
// between a heavy and a light body passes only the light body's share of
// an impulse per sweep, so a 1:R mass ratio needs of the order of R sweeps
// (Erleben, "Velocity-based shock propagation for multibody dynamics
// animation", ACM TOG 26(2), 2007, section 2), and an impulse crosses an
// N-link chain in about N sweeps, N^2 to settle. An island is
// ill-conditioned for PGS, and leaves it, when
//
//   mass_ratio   heaviest / lightest of its dynamic bodies >= 100 (at the
//                default 10 sweeps 1:100 is where stacks start to sink,
//                docs/extremes.md's stack-ratio cases);
//   long_chain   it has more joints than 4 x the sweeps (at 10 sweeps, 40:
//                hanging-chain-20 holds to 1.4 mm on PGS, 1000 links open
//                by metres);
//   joint_drift  a rigid joint of it has been open by more than 1 cm (the
//                extremes' hanging-chain limit, 2% of a 0.5 m link) at
//                the start of kDriftSteps = 5 steps in a row without
//                closing (its error never smaller than the step before):
//                PGS's residual does not fall. ERP's feedback alone
//                removes 1 - (1 - ERP)^5 = 67% of an error in 5 steps at
//                the default ERP 0.2 (1/ERP steps, Baumgarte's time
//                constant), so an error that grew or held for that long
//                is one the sweeps leave, not a transient: a ragdoll
//                landing opens its hips by 1.3 cm for 4 steps on PGS and
//                closes (stays PGS), a whipping chain opens for hundreds
//                of steps (leaves it). A joint open by more than 2 cm
//                (kDriftAtOnce) leaves at once: an error that oscillates
//                without closing (two distance joints asking different
//                lengths) never grows 5 steps in a row, and the later
//                auto leaves, the wider the gap the position pass closes
//                on arrival (its velocities follow the positions, a kick
//                that adds energy). Its bodies keep the mark
//                (hysteresis): an island that holds only because it left
//                PGS would drift again on return.
//
// Everything else stays PGS. An ill-conditioned island goes to the exact
// pivoting LCP solver (solver/lcp_exact.hpp) when it has contacts and at
// most kExactRows rows (Dantzig's pivoting costs O(n^3), cheap below a
// few hundred rows, and solves the friction cone exactly where the direct
// solver's inner PGS would meet the same mass ratio), else to the direct
// solver (a sparse factor of the bilateral rows, linear in a tree's joints
// and CHOLMOD's elsewhere, whose cost grows
// with the fill, not the ratio) with the joint position pass.
#include "world/method_choice.hpp"

#include <algorithm>

namespace cairn::detail {

namespace {

constexpr Real kMassRatio = 100;
constexpr int kChainJointsPerSweep = 4;
constexpr Real kDriftLimit = Real(0.01);  // m
constexpr std::uint8_t kDriftSteps = 5;
constexpr Real kDriftAtOnce = 2 * kDriftLimit;  // m
constexpr int kExactRows = 240;

}  // namespace

void chooseIslandMethods(WorldImpl& w, StepContext& ctx) {
  const SolverSettings& s = w.settings_;
  const auto n = static_cast<size_t>(ctx.island_count);
  ctx.island_reason.assign(n, MethodReason::Setting);
  if (s.method != SolverMethod::Auto) return;
  std::vector<IslandFacts>& facts = ctx.island_facts;  // scratch: no allocation once warm
  facts.assign(n, IslandFacts{});
  const auto islandOf = [&](BodyId id) {
    return id.isWorld() ? -1 : ctx.body_island[static_cast<size_t>(id.index)];
  };
  ctx.body_drifted.resize(w.bodies_.size(), 0);
  for (size_t i = 0; i < w.bodies_.size(); ++i) {
    const std::int32_t isl = ctx.body_island[i];
    if (isl < 0) continue;
    IslandFacts& f = facts[static_cast<size_t>(isl)];
    f.drifted = f.drifted || ctx.body_drifted[i] != 0;
    f.min_mass = std::min(f.min_mass, w.bodies_[i].mass);
    f.max_mass = std::max(f.max_mass, w.bodies_[i].mass);
  }
  ctx.joint_error_last.resize(w.joints_.size(), 0);
  ctx.joint_drift_run.resize(w.joints_.size(), 0);
  const auto jointIsland = [&](const Joint& j) {
    return j.alive && !j.broken ? std::max(islandOf(j.def.body_a), islandOf(j.def.body_b)) : -1;
  };
  for (const Joint& j : w.joints_)
    if (const std::int32_t isl = jointIsland(j); isl >= 0) ++facts[static_cast<size_t>(isl)].joints;
  // An island that leaves PGS for its mass ratio or its length needs no
  // drift figure (and a long chain would measure every joint every step):
  // its joints' runs start over, as a dead joint's do.
  const auto settled = [&](const IslandFacts& f) {
    return f.max_mass >= kMassRatio * f.min_mass || f.joints > kChainJointsPerSweep * s.iterations;
  };
  for (size_t i = 0; i < w.joints_.size(); ++i) {
    const Joint& j = w.joints_[i];
    const std::int32_t isl = jointIsland(j);
    if (!j.alive || j.broken || (isl >= 0 && settled(facts[static_cast<size_t>(isl)]))) {
      ctx.joint_error_last[i] = 0;
      ctx.joint_drift_run[i] = 0;
      continue;
    }
    if (isl < 0) continue;  // asleep: its run waits
    IslandFacts& f = facts[static_cast<size_t>(isl)];
    if (j.def.softness.isSet()) continue;
    const Real error = measureJointError(j, w.view(j.def.body_a), w.view(j.def.body_b)).linear;
    std::uint8_t& run = ctx.joint_drift_run[i];
    run = error > kDriftLimit && error >= ctx.joint_error_last[i] ? static_cast<std::uint8_t>(std::min(run + 1, 255)) : 0;
    ctx.joint_error_last[i] = error;
    f.drifting = f.drifting || run >= kDriftSteps || error > kDriftAtOnce;
  }
  if (n > 0)  // else every body is asleep or static: no contact has an island (a walk over 700-byte contacts)
    for (const Contact& c : w.contacts_) {
      if (!c.enabled || c.count == 0) continue;
      const std::int32_t isl = std::max(islandOf(c.body_a), islandOf(c.body_b));
      if (isl >= 0) facts[static_cast<size_t>(isl)].contact_points += c.count;
    }
  for (size_t isl = 0; isl < n; ++isl) {
    const IslandFacts& f = facts[isl];
    MethodReason why = MethodReason::WellConditioned;
    if (f.max_mass >= kMassRatio * f.min_mass) why = MethodReason::MassRatio;
    else if (f.joints > kChainJointsPerSweep * s.iterations) why = MethodReason::LongChain;
    else if (f.drifted || f.drifting) why = MethodReason::JointDrift;
    ctx.island_reason[isl] = why;
    if (why == MethodReason::WellConditioned || f.joints + f.contact_points == 0) {
      ctx.island_method[isl] = SolverMethod::PGS;
      continue;
    }
    const int rows = 6 * f.joints + 3 * f.contact_points;  // at most
    const int exact_rows = std::min(kExactRows, s.max_exact_rows);
    ctx.island_method[isl] = f.contact_points > 0 && rows <= exact_rows ? SolverMethod::LCP : SolverMethod::Direct;
  }
  // The joint_drift islands' bodies keep the mark (one pass over the bodies).
  for (size_t i = 0; i < w.bodies_.size(); ++i) {
    const std::int32_t isl = ctx.body_island[i];
    if (isl >= 0 && ctx.island_reason[static_cast<size_t>(isl)] == MethodReason::JointDrift &&
        ctx.island_method[static_cast<size_t>(isl)] != SolverMethod::PGS)
      ctx.body_drifted[i] = 1;
  }
}

void countIslandMethods(WorldImpl& w, const StepContext& ctx) {
  for (int& k : w.stats_.islands_by_method) k = 0;
  for (int& k : w.stats_.islands_by_reason) k = 0;
  for (size_t isl = 0; isl < ctx.island_method.size(); ++isl) {
    ++w.stats_.islands_by_method[static_cast<int>(ctx.island_method[isl])];
    ++w.stats_.islands_by_reason[static_cast<int>(ctx.island_reason[isl])];
  }
}

}  // namespace cairn::detail
