// The fixed-step driver (include/cairn/fixed_step.hpp explains the
// accumulator, the cap and the interpolation). It reads and steps the World
// through its public face only.
#include "cairn/fixed_step.hpp"

#include "cairn/error.hpp"
#include "cairn/world.hpp"

#include <algorithm>
#include <cmath>

namespace cairn {

namespace {

constexpr const char* kObject = "fixed step driver";
// A step is taken when the accumulator is within this fraction of h of it,
// so frame times that sum to whole steps in exact arithmetic are not a
// step short after round-off (a sum of n frames is off by ~n ulps).
constexpr Real kSnap = Real(1e-9);

bool samePose(const Transform& a, const Transform& b) { return a.p == b.p && a.q.coeffs() == b.q.coeffs(); }

}  // namespace

FixedStepDriver::FixedStepDriver(World& world, const FixedStepSettings& settings)
    : world_(world), settings_(settings) {
  if (!(std::isfinite(settings.step) && settings.step > 0))
    throw InputError(kObject, "step", "must be positive and finite");
  if (settings.max_steps_per_frame < 1) throw InputError(kObject, "max_steps_per_frame", "must be at least 1");
}

int FixedStepDriver::advance(Real frame_seconds) {
  if (!(std::isfinite(frame_seconds) && frame_seconds >= 0))
    throw InputError(kObject, "frame_seconds", "must be finite and not negative");
  const Real h = settings_.step;
  accumulator_ += frame_seconds;
  auto wanted = static_cast<std::int64_t>(std::floor(accumulator_ / h + kSnap));
  accumulator_ = std::max(accumulator_ - static_cast<Real>(wanted) * h, Real(0));
  // floor of a rounded quotient may fall one short of a whole step.
  while (accumulator_ >= h * (1 - kSnap)) {
    ++wanted;
    accumulator_ = std::max(accumulator_ - h, Real(0));
  }
  const int run = static_cast<int>(std::min<std::int64_t>(wanted, settings_.max_steps_per_frame));
  dropped_ += static_cast<Real>(wanted - run) * h;
  for (int i = 0; i < run; ++i) {
    if (i == run - 1) savePoses();
    world_.step(h);
  }
  if (run > 0) recordAfter();
  steps_ += run;
  return run;
}

Real FixedStepDriver::alpha() const { return std::clamp(accumulator_ / settings_.step, Real(0), Real(1)); }

Real FixedStepDriver::renderTime() const {
  if (steps_ == 0) return world_.time();
  return world_.time() - (1 - alpha()) * settings_.step;
}

void FixedStepDriver::savePoses() {
  for (Saved& s : saved_) s.valid = false;
  for (const BodyId id : world_.bodies()) {
    const auto i = static_cast<size_t>(id.index);
    if (i >= saved_.size()) saved_.resize(i + 1);
    saved_[i] = Saved{id.generation, true, world_.transform(id), {}};
  }
}

void FixedStepDriver::recordAfter() {
  for (size_t i = 0; i < saved_.size(); ++i) {
    Saved& s = saved_[i];
    if (!s.valid) continue;
    const BodyId id{static_cast<std::int32_t>(i), s.generation};
    s.after = world_.transform(id);
  }
}

Transform FixedStepDriver::interpolatedTransform(BodyId body) const {
  const Transform now = world_.transform(body);  // throws HandleError on a stale handle
  const auto i = static_cast<size_t>(body.index);
  if (i >= saved_.size()) return now;
  const Saved& s = saved_[i];
  if (!s.valid || s.generation != body.generation || !samePose(s.after, now)) return now;
  const Real a = alpha();
  return Transform{(1 - a) * s.before.p + a * now.p, s.before.q.slerp(a, now.q).normalized()};
}

void FixedStepDriver::resetInterpolation() {
  for (Saved& s : saved_) s.valid = false;
}

}  // namespace cairn
