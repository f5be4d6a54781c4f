// The fixed-step driver (include/cairn/fixed_step.hpp): the accumulator's
// step counts, the spiral-of-death cap, and poses interpolated between the
// last two steps (lerp for positions, slerp for orientations) against the
// closed-form motion of a free body.
#include "cairn/fixed_step.hpp"
#include "cairn/world.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

namespace cairn {
namespace {

// A free sphere in zero gravity moving at constant velocity v and spinning
// at constant w about a fixed axis: its exact pose at time t is
// p0 + v t and exp(t w) (a sphere's inertia is isotropic, so no gyroscopic
// torque bends the spin; the exponential-map integrator is exact for
// constant w).
struct FreeSpinner {
  World world{WorldDef{Vec3::Zero(), {}}};
  Vec3 p0 = Vec3(1, 2, 3), v = Vec3(0.7, -0.2, 0.4), w = Vec3(0, 0, 30);
  BodyId id;
  FreeSpinner() {
    BodyDef d;
    d.name = "spinner";
    d.density = 1000;
    d.shapes.push_back(ShapeDesc::sphere(0.2));
    d.position = p0;
    d.linear_velocity = v;
    d.angular_velocity = w;
    id = world.createBody(d);
  }
  Vec3 position(Real t) const { return p0 + v * t; }
  Quat orientation(Real t) const { return quatFromRotationVector(w * t); }
};

// Frame times in whole milliseconds against h = 10 ms, so the expected
// counts follow from integer arithmetic: steps = floor(accumulated / 10)
// minus the steps already taken.
TEST(FixedStepDriver, StepCountForAFrameSequenceIsExact) {
  World world;
  FixedStepDriver driver(world, {Real(0.01), 8});
  const std::vector<int> frames_ms = {4, 7, 3, 25, 0, 16, 33, 1, 9, 17, 10, 70};
  int accumulated = 0, taken = 0;
  for (int ms : frames_ms) {
    accumulated += ms;
    const int expected = accumulated / 10 - taken;
    EXPECT_EQ(driver.advance(ms * Real(1e-3)), expected) << "after " << accumulated << " ms";
    taken += expected;
    // The remainder waits: alpha is accumulated time beyond whole steps / h.
    EXPECT_NEAR(driver.alpha(), (accumulated % 10) / Real(10), 1e-9) << "after " << accumulated << " ms";
  }
  EXPECT_EQ(world.stepCount(), taken);
  EXPECT_EQ(driver.steps(), taken);
  EXPECT_EQ(driver.droppedTime(), 0);
}

// Frame times that sum to whole steps only in exact arithmetic: 360 frames
// of 1/360 s are 60 steps of 1/60 s, no step lost to round-off.
TEST(FixedStepDriver, FramesSummingToWholeStepsLoseNoStepToRoundOff) {
  World world;
  FixedStepDriver driver(world, {Real(1) / 60, 8});
  for (int i = 0; i < 360; ++i) driver.advance(Real(1) / 360);
  EXPECT_EQ(world.stepCount(), 60);
  EXPECT_LT(driver.alpha(), 1e-6);
  // 144 Hz frames against 60 Hz steps: 144 frames make one second, 60 steps.
  World world2;
  FixedStepDriver driver2(world2, {Real(1) / 60, 8});
  for (int i = 0; i < 144; ++i) driver2.advance(Real(1) / 144);
  EXPECT_EQ(world2.stepCount(), 60);
}

TEST(FixedStepDriver, CapRunsAtMostMaxStepsAndDropsTheRestKeepingTheFraction) {
  World world;
  FixedStepDriver driver(world, {Real(0.01), 4});
  // 0.125 s wants 12 steps with 5 ms left over: 4 run, 8 dropped.
  EXPECT_EQ(driver.advance(0.125), 4);
  EXPECT_EQ(world.stepCount(), 4);
  EXPECT_NEAR(driver.droppedTime(), 0.08, 1e-12);
  EXPECT_NEAR(driver.alpha(), 0.5, 1e-9);
  // The next normal frame is not burdened with the dropped steps.
  EXPECT_EQ(driver.advance(0.005), 1);
  EXPECT_NEAR(driver.alpha(), 0, 1e-9);
  // A pathological frame (a debugger pause) costs at most the cap.
  EXPECT_EQ(driver.advance(3600), 4);
  EXPECT_EQ(world.stepCount(), 9);
}

TEST(FixedStepDriver, NoStepBeforeAWholeStepAccumulates) {
  FreeSpinner s;
  FixedStepDriver driver(s.world, {Real(1) / 60, 8});
  EXPECT_EQ(driver.advance(Real(1) / 120), 0);
  EXPECT_NEAR(driver.alpha(), 0.5, 1e-12);
  // Before any step the drawn pose is the body's pose.
  const Transform t = driver.interpolatedTransform(s.id);
  EXPECT_EQ(t.p, s.p0);
  EXPECT_EQ(driver.renderTime(), 0);
}

// Interpolated poses equal the exact motion at renderTime(): linear in
// time for the position, and for the orientation only because slerp is
// used -- at 0.5 rad per step a normalized lerp would be off by ~4e-4 rad
// at alpha 0.25. 1e-9 covers the round-off of 120 steps of the integrator.
TEST(FixedStepDriver, InterpolatedPoseIsTheExactPoseAtRenderTime) {
  FreeSpinner s;
  const Real h = Real(1) / 60;
  FixedStepDriver driver(s.world, {h, 8});
  const std::vector<Real> frames = {0.013, 0.021, 0.0042, 0.05, 0.0167, 0.007, 0.033, 0.019};
  Real total = 0;
  for (int round = 0; round < 10; ++round) {
    for (Real f : frames) {
      driver.advance(f);
      total += f;
      if (driver.steps() == 0) continue;
      const Real t = driver.renderTime();
      EXPECT_NEAR(t, s.world.time() - (1 - driver.alpha()) * h, 1e-15);
      const Transform pose = driver.interpolatedTransform(s.id);
      EXPECT_LT((pose.p - s.position(t)).norm(), 1e-9) << "t = " << t;
      EXPECT_LT(pose.q.angularDistance(s.orientation(t)), 1e-9) << "t = " << t << ", alpha " << driver.alpha();
    }
  }
  // 1.639 s of frames: 98 whole steps, every one interpolated above.
  EXPECT_EQ(driver.steps(), static_cast<std::int64_t>(std::floor(total / h)));
  EXPECT_EQ(driver.steps(), 98);
}

// A nlerp (normalized linear blend) of the same two orientations is
// measurably wrong: the test above distinguishes slerp from it.
TEST(FixedStepDriver, NormalizedLerpWouldMissTheExactOrientation) {
  const Quat a = quatFromRotationVector(Vec3(0, 0, 0));
  const Quat b = quatFromRotationVector(Vec3(0, 0, 0.5));
  const Quat nlerp = Quat(Real(0.75) * a.coeffs() + Real(0.25) * b.coeffs()).normalized();
  EXPECT_GT(nlerp.angularDistance(quatFromRotationVector(Vec3(0, 0, 0.125))), 1e-4);
  EXPECT_LT(a.slerp(0.25, b).angularDistance(quatFromRotationVector(Vec3(0, 0, 0.125))), 1e-12);
}

TEST(FixedStepDriver, TeleportedBodyIsDrawnWhereItIsNow) {
  FreeSpinner s;
  FixedStepDriver driver(s.world, {Real(1) / 60, 8});
  driver.advance(Real(1.5) / 60);
  const Vec3 there(10, 0, 0);
  s.world.setTransform(s.id, there, Quat::Identity());
  EXPECT_EQ(driver.interpolatedTransform(s.id).p, there);
}

TEST(FixedStepDriver, BadSettingsAndFrameTimesAreInputErrors) {
  World world;
  EXPECT_THROW(FixedStepDriver(world, {0, 8}), InputError);
  EXPECT_THROW(FixedStepDriver(world, {Real(1) / 60, 0}), InputError);
  FixedStepDriver driver(world);
  EXPECT_THROW(driver.advance(-0.01), InputError);
  EXPECT_THROW(driver.advance(std::nan("")), InputError);
  EXPECT_EQ(world.stepCount(), 0);
}

}  // namespace
}  // namespace cairn
