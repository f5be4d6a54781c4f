// Sutherland-Hodgman clipping with feature labels, and the 4-point
// reduction (both described in clip.hpp).
#include "collision/clip.hpp"

#include <algorithm>

namespace cairn {

int clipByPlane(const ClipVertex* in, int n, const Vec3& s, Real d, int plane, ClipVertex* out) {
  auto crossing = [&](const ClipVertex& a, const ClipVertex& b, Real da, Real db) {
    ClipVertex x;
    const Real t = da / (da - db);
    x.p = a.p + t * (b.p - a.p);
    x.id = static_cast<std::uint16_t>(0x8000 | ((a.edge & 0x7F) << 7) | (plane & 0x7F));
    x.edge = a.edge;
    return x;
  };
  if (n == 1) {
    if (s.dot(in[0].p) - d <= 0) {
      out[0] = in[0];
      return 1;
    }
    return 0;
  }
  if (n == 2) {
    // A segment: the part with s.x <= d.
    const Real da = s.dot(in[0].p) - d, db = s.dot(in[1].p) - d;
    if (da > 0 && db > 0) return 0;
    out[0] = da <= 0 ? in[0] : crossing(in[0], in[1], da, db);
    out[1] = db <= 0 ? in[1] : crossing(in[0], in[1], da, db);
    return 2;
  }
  int m = 0;
  for (int i = 0; i < n; ++i) {
    const ClipVertex& a = in[i];
    const ClipVertex& b = in[(i + 1) % n];
    const Real da = s.dot(a.p) - d, db = s.dot(b.p) - d;
    if (da <= 0) {
      if (db <= 0) {
        out[m++] = b;  // inside to inside
      } else {
        ClipVertex x = crossing(a, b, da, db);  // leaving: continue along the plane
        x.edge = static_cast<std::uint8_t>(64 + plane);
        out[m++] = x;
      }
    } else if (db <= 0) {
      out[m++] = crossing(a, b, da, db);  // entering: continue along edge a-b
      out[m++] = b;
    }
    if (m >= kMaxClipVerts - 1) break;
  }
  return m;
}

int reduceToFour(const Vec3* pos, const Real* depth, int n, const Vec3& normal, int keep[4]) {
  if (n <= 4) {
    for (int i = 0; i < n; ++i) keep[i] = i;
    return n;
  }
  auto flat = [&](const Vec3& v) { return Vec3(v - normal * normal.dot(v)); };
  int a = 0;
  for (int i = 1; i < n; ++i)
    if (depth[i] > depth[a]) a = i;
  int b = -1;
  Real best = -1;
  for (int i = 0; i < n; ++i) {
    const Real d2 = flat(pos[i] - pos[a]).squaredNorm();
    if (i != a && d2 > best) best = d2, b = i;
  }
  int c = -1;
  best = -1;
  Real signed_area = 0;
  for (int i = 0; i < n; ++i) {
    if (i == a || i == b) continue;
    const Real ar = (pos[b] - pos[a]).cross(pos[i] - pos[a]).dot(normal);
    if (std::abs(ar) > best) best = std::abs(ar), c = i, signed_area = ar;
  }
  // Orient a, b, c counter-clockwise about the normal, then the fourth point
  // is the one farthest outside the triangle's edges.
  if (signed_area < 0) std::swap(b, c);
  const int tri[3] = {a, b, c};
  int d = -1;
  best = 0;
  for (int i = 0; i < n; ++i) {
    if (i == a || i == b || i == c) continue;
    Real added = 0;
    for (int e = 0; e < 3; ++e) {
      const Vec3& p = pos[tri[e]];
      const Vec3& q = pos[tri[(e + 1) % 3]];
      added = std::max(added, -(q - p).cross(pos[i] - p).dot(normal));
    }
    if (added > best) best = added, d = i;
  }
  keep[0] = a;
  keep[1] = b;
  keep[2] = c;
  if (d < 0) return 3;
  keep[3] = d;
  return 4;
}

}  // namespace cairn
