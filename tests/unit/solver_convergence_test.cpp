// PGS against the exact LCP (the speed/accuracy trade, docs/tradeoff.md): on a
// pyramid, the impulses PGS finds in a step approach the exact solution of
// the same step's LCP as the sweeps grow. Distances are the velocity-norm
// figure of validation/lcp_probe.hpp: a box resting on four points is
// statically indeterminate, so only the motion the impulses make is unique.
#include "validation/lcp_probe.hpp"
#include "validation/scenarios.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace cairn {
namespace {

// Distance from the exact LCP at step 10 of pyramid-4 (10 boxes), solved
// cold (no warm start: the step's sweeps alone), at `iterations` sweeps.
double distanceAt(int iterations, bool nncg) {
  SceneDesc s = scenarios::pyramid(4);
  s.solver.sleeping = false;
  s.solver.warm_start = false;
  s.solver.iterations = iterations;
  s.solver.nncg = nncg;
  World w = buildWorld(s);
  for (int k = 0; k < 9; ++k) w.step(s.dt);
  validation::ExactLcpProbe probe;
  probe.beforeStep(w);
  w.step(s.dt);
  const auto d = probe.afterStep(w, s.dt);
  EXPECT_TRUE(d.has_value()) << probe.why();
  return d ? d->velocity : NAN;
}

// Over 1, 4, 16, 64 and 256 sweeps the distance falls: on average (the
// least-squares slope of log distance against log sweeps is negative), no
// quadrupling raises it by more than 10% (projected sweeps need not be
// monotone: a contact may switch between them), and 256 sweeps land at
// least 100 times closer than one. Measured at step 30: 0.75 at one sweep,
// 2.5e-6 at 256 (plain PGS) and 8e-10 (NNCG).
TEST(PgsConvergence, DistanceFromExactLcpFallsAsSweepsGrowOnAPyramid) {
  for (const bool nncg : {false, true}) {
    std::vector<double> x, y;
    for (int it = 1; it <= 256; it *= 4) {
      const double d = distanceAt(it, nncg);
      ASSERT_TRUE(std::isfinite(d));
      x.push_back(std::log2(double(it)));
      y.push_back(std::log10(std::max(d, 1e-16)));
      if (y.size() > 1) {
        EXPECT_LT(y.back(), y[y.size() - 2] + std::log10(1.1)) << "nncg " << nncg << ", " << it << " sweeps";
      }
    }
    double mx = 0, my = 0;
    for (size_t i = 0; i < x.size(); ++i) mx += x[i], my += y[i];
    mx /= double(x.size());
    my /= double(y.size());
    double sxy = 0, sxx = 0;
    for (size_t i = 0; i < x.size(); ++i) sxy += (x[i] - mx) * (y[i] - my), sxx += (x[i] - mx) * (x[i] - mx);
    EXPECT_LT(sxy / sxx, 0) << "nncg " << nncg;
    EXPECT_LT(y.back(), y.front() - 2) << "nncg " << nncg;
  }
}

}  // namespace
}  // namespace cairn
