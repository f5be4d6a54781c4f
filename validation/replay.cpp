#include "validation/replay.hpp"

#include <algorithm>
#include <cmath>

namespace cairn::validation {

int Replay::shapeCount() const {
  int n = 0;
  for (const ReplayBody& b : bodies) n += static_cast<int>(b.shapes.size());
  return n;
}

namespace {

constexpr std::size_t kManifoldBytes = 3 * 4 + 3 * 4 + 2 * 4 + 1, kPointBytes = 3 * 4 + 4;

std::size_t contactBytes(const ReplayOverlays& o, size_t frames, size_t k) {
  std::size_t bytes = 0;
  for (size_t f = 0; f < frames; f += k)
    bytes += (o.manifold_begin[f + 1] - o.manifold_begin[f]) * kManifoldBytes +
             (o.point_begin[f + 1] - o.point_begin[f]) * kPointBytes;
  return bytes;
}

template <class T>
void keep(std::vector<T>& out, const std::vector<T>& in, size_t begin, size_t end, size_t width) {
  out.insert(out.end(), in.begin() + long(begin * width), in.begin() + long(end * width));
}

}  // namespace

int thinContacts(ReplayOverlays& o, std::size_t max_bytes) {
  const size_t frames = o.contact_frame.size();
  size_t k = 1;
  while (k < frames && contactBytes(o, frames, k) > max_bytes) ++k;
  if (k == 1) return 1;
  ReplayOverlays t;
  t.manifold_begin.push_back(0);
  t.point_begin.push_back(0);
  for (size_t f = 0; f < frames; ++f) {
    if (f % k == 0) {
      const size_t m0 = o.manifold_begin[f], m1 = o.manifold_begin[f + 1], p0 = o.point_begin[f], p1 = o.point_begin[f + 1];
      keep(t.manifold_normal, o.manifold_normal, m0, m1, 3);
      keep(t.manifold_friction, o.manifold_friction, m0, m1, 3);
      keep(t.manifold_body, o.manifold_body, m0, m1, 2);
      keep(t.manifold_points, o.manifold_points, m0, m1, 1);
      keep(t.point_position, o.point_position, p0, p1, 3);
      keep(t.point_impulse, o.point_impulse, p0, p1, 1);
    }
    t.contact_frame.push_back(std::uint32_t(f - f % k));
    t.manifold_begin.push_back(std::uint32_t(t.manifold_points.size()));
    t.point_begin.push_back(std::uint32_t(t.point_impulse.size()));
  }
  o.manifold_begin = std::move(t.manifold_begin);
  o.point_begin = std::move(t.point_begin);
  o.contact_frame = std::move(t.contact_frame);
  o.manifold_normal = std::move(t.manifold_normal);
  o.manifold_friction = std::move(t.manifold_friction);
  o.manifold_body = std::move(t.manifold_body);
  o.manifold_points = std::move(t.manifold_points);
  o.point_position = std::move(t.point_position);
  o.point_impulse = std::move(t.point_impulse);
  return int(k);
}

void fitContacts(Replay& replay) {
  if (!replay.overlays.recorded) return;
  const int k = thinContacts(replay.overlays, kContactBudgetBytes);
  if (k > 1)
    replay.notes.push_back("Contacts are kept for every " + std::to_string(k) +
                           "th frame only (the frames between show the last kept one), to keep the page light.");
}

ReplayParting findParting(const ReplayTrack& a, const ReplayTrack& b, int bodies, double tolerance) {
  ReplayParting p;
  p.tolerance = tolerance;
  const int frames = std::min(a.frames(), b.frames());
  for (int f = 0; f < frames && p.frame < 0; ++f) {
    for (int i = 0; i < bodies; ++i) {
      const size_t k = 3 * (size_t(f) * size_t(bodies) + size_t(i));
      const double d = std::hypot(a.position[k] - b.position[k], a.position[k + 1] - b.position[k + 1],
                                  a.position[k + 2] - b.position[k + 2]);
      if (d > tolerance && d > p.distance) {
        p.frame = f;
        p.time = a.time[size_t(f)];
        p.body = i;
        p.distance = d;
      }
    }
  }
  return p;
}

}  // namespace cairn::validation
