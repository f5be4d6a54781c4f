#include "validation/replay_bullet.hpp"

namespace cairn::validation {

double partingTolerance(const ValidationSpec& spec) {
  const auto it = spec.tolerances.find("position");
  if (it != spec.tolerances.end()) return it->second;
  return defaultTolerances("", ValidationKind::Trajectory).at("position");
}

void addBulletRun(Replay& replay, const EngineRun& bullet, const ValidationSpec& spec) {
  ReplayTrack t;
  for (int s = 0; s < bullet.samples(); ++s) {
    t.time.push_back(bullet.time[size_t(s)]);
    for (const Vec3& p : bullet.positions[size_t(s)]) t.position.insert(t.position.end(), {float(p.x()), float(p.y()), float(p.z())});
    for (const Quat& q : bullet.orientations[size_t(s)])
      t.orientation.insert(t.orientation.end(), {float(q.x()), float(q.y()), float(q.z()), float(q.w())});
  }
  replay.parting = findParting(replay.cairn, t, replay.bodyCount(), partingTolerance(spec));
  if (!bullet.failure.empty()) replay.notes.push_back("Bullet's run stopped: " + bullet.failure);
  replay.bullet = std::move(t);
}

}  // namespace cairn::validation
