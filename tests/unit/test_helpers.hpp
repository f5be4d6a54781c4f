// Shared helpers for the physics tests.
#pragma once

#include "validation/scenarios.hpp"
#include "world/world_access.hpp"

#include <sched.h>

#include <atomic>
#include <string>
#include <thread>

namespace cairn::test {

// While alive, pins the calling thread, and the threads it starts, to the
// core it runs on: a machine with no core to spare, made certain.
class OneCore {
 public:
  OneCore() {
    sched_getaffinity(0, sizeof saved_, &saved_);
    cpu_set_t one;
    CPU_ZERO(&one);
    const int cpu = sched_getcpu();
    CPU_SET(cpu < 0 ? 0 : cpu, &one);
    sched_setaffinity(0, sizeof one, &one);
  }
  ~OneCore() { sched_setaffinity(0, sizeof saved_, &saved_); }
  OneCore(const OneCore&) = delete;
  OneCore& operator=(const OneCore&) = delete;

 private:
  cpu_set_t saved_{};
};

// Another task busy on the core for as long as it lives (a spinning
// thread, with the creating thread's affinity: under OneCore, that core),
// as on a machine whose other processes leave the step no core to spare.
// A thread that yields the core then gets it back only after a time slice.
class BusyCore {
 public:
  BusyCore()
      : spinner_([this] {
          while (!stop_.load(std::memory_order_relaxed)) {
          }
        }) {}
  ~BusyCore() {
    stop_.store(true, std::memory_order_relaxed);
    spinner_.join();
  }
  BusyCore(const BusyCore&) = delete;
  BusyCore& operator=(const BusyCore&) = delete;

 private:
  std::atomic<bool> stop_{false};
  std::thread spinner_;
};

inline BodyDef boxDef(const std::string& name, const Vec3& pos, Real mass = 1, const Vec3& he = Vec3(0.5, 0.5, 0.5)) {
  return scenarios::solid(name, mass, pos, ShapeDesc::box(he));
}

inline BodyDef sphereDef(const std::string& name, const Vec3& pos, Real mass = 1, Real r = 0.5) {
  return scenarios::solid(name, mass, pos, ShapeDesc::sphere(r));
}

// A world that never sleeps (default gravity: none), for tests that follow
// motions slowing below the sleep thresholds.
inline World awakeWorld(const Vec3& gravity = Vec3::Zero()) {
  World w(gravity);
  SolverSettings s;
  s.sleeping = false;
  w.setSettings(s);
  return w;
}

inline std::string sourcePath(const std::string& rel) { return std::string(CAIRN_SOURCE_DIR) + "/" + rel; }

}  // namespace cairn::test
