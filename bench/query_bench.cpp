// Query timings over the pile-1000 scene through the World's public
// queries (Google Benchmark). docs/collision.md records the results and the
// command that produced them.
//
// The scene is scenarios::pile(10) as built, not settled: a 10 x 10 x 10
// grid of 1 m boxes 0.2 m apart over a 200 x 1 x 200 ground box, in a World
// (buildWorld), whose broadphase holds each shape's box grown by the
// contact margin. Rays start at random points 2-6 m above the pile and aim
// at random points inside its bounds, extended by half again so that a ray
// slipping through a gap can reach a lower box or the ground; the seed is
// fixed, so every run casts the same rays.
//
//   BM_RayCastPile1000/all:A  100,000 rays per iteration; A = 0 closest hit
//                             (World::castRay), A = 1 every hit (castRayAll)
//   BM_SphereCastPile1000     10,000 sweeps of a 0.25 m sphere, closest hit
//                             (World::castShape)
//
// Counters: ns_per_query (the thread's CPU time per ray or sweep, so a
// loaded machine does not inflate it), hit_rate (fraction of queries that
// hit something) and hits_per_query (mean hits reported).
#include "bench/thread_clock.hpp"
#include "cairn/scene.hpp"
#include "cairn/world.hpp"
#include "validation/scenarios.hpp"

#include <benchmark/benchmark.h>

#include <random>
#include <vector>

namespace cairn::bench {
namespace {

const World& pile1000() {
  static const World world = buildWorld(scenarios::pile(10));
  return world;
}

struct Segment {
  Vec3 origin, translation;
};

// The pile's boxes fill x, z in [-5.9, 5.9] and y in [0.5, 12.3].
std::vector<Segment> raysIntoPile(int count) {
  std::mt19937_64 rng(20261124);
  std::uniform_real_distribution<Real> u(0, 1);
  auto in = [&](Real lo, Real hi) { return lo + (hi - lo) * u(rng); };
  std::vector<Segment> rays;
  rays.reserve(static_cast<size_t>(count));
  for (int i = 0; i < count; ++i) {
    const Vec3 from(in(-8, 8), in(14.3, 18.3), in(-8, 8));
    const Vec3 to(in(-5.9, 5.9), in(0.5, 12.3), in(-5.9, 5.9));
    rays.push_back({from, Real(1.5) * (to - from)});
  }
  return rays;
}

void setCounters(benchmark::State& state, int queries, double seconds, double hits, double hit_queries) {
  const double n = static_cast<double>(state.iterations()) * queries;
  state.counters["ns_per_query"] = 1e9 * seconds / n;
  state.counters["hit_rate"] = hit_queries / n;
  state.counters["hits_per_query"] = hits / n;
}

void BM_RayCastPile1000(benchmark::State& state) {
  constexpr int kRays = 100000;
  const World& world = pile1000();
  static const std::vector<Segment> rays = raysIntoPile(kRays);
  const bool all = state.range(0) != 0;
  double hits = 0, hit_rays = 0;
  const double t0 = threadSeconds();
  for (auto _ : state) {
    for (const Segment& r : rays) {
      if (all) {
        const std::vector<RayHit> h = world.castRayAll(r.origin, r.translation);
        hits += static_cast<double>(h.size());
        hit_rays += !h.empty();
      } else {
        const std::optional<RayHit> h = world.castRay(r.origin, r.translation);
        hits += h.has_value();
        hit_rays += h.has_value();
        benchmark::DoNotOptimize(h);
      }
    }
  }
  setCounters(state, kRays, threadSeconds() - t0, hits, hit_rays);
}
BENCHMARK(BM_RayCastPile1000)->ArgName("all")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

void BM_SphereCastPile1000(benchmark::State& state) {
  constexpr int kCasts = 10000;
  const World& world = pile1000();
  static const std::vector<Segment> rays = raysIntoPile(kCasts);
  const ShapeDesc sphere = ShapeDesc::sphere(0.25);
  double hits = 0;
  const double t0 = threadSeconds();
  for (auto _ : state) {
    for (const Segment& r : rays) {
      const std::optional<ShapeCastHit> h = world.castShape(sphere, Transform{r.origin, Quat::Identity()}, r.translation);
      hits += h.has_value();
      benchmark::DoNotOptimize(h);
    }
  }
  setCounters(state, kCasts, threadSeconds() - t0, hits, hits);
}
BENCHMARK(BM_SphereCastPile1000)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace cairn::bench
