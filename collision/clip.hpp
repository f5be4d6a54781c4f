// Polygon clipping and contact reduction for face contacts.
//
// Sutherland-Hodgman (Ericson 8.3.4): a convex polygon clipped by the plane
// s.x <= d keeps its inside vertices and, for each edge that crosses the
// plane, the crossing point p + (q - p) (d - s.p) / (s.q - s.p). Clipping the
// incident face by every side plane of the reference face leaves the part
// of it that lies over the reference face.
//
// Every clip vertex carries an id saying how it was made, so a contact keeps
// its id while the same features touch:
//   incident vertex k               -> k                    (k < 128)
//   edge labelled L crossing plane j -> 0x8000 | L << 7 | j
// where incident edge k (from vertex k to k + 1) has label k and the part of
// a polygon running along reference side plane j has label 64 + j.
#pragma once

#include "cairn/math.hpp"

#include <cstdint>

namespace cairn {

struct ClipVertex {
  Vec3 p;
  std::uint16_t id;
  std::uint8_t edge;  // label of the edge from this vertex to the next
};

// Largest incident polygon the clipper accepts and largest output (clipping
// a convex n-gon by m planes leaves at most n + m vertices).
constexpr int kMaxClipInput = 64;
constexpr int kMaxClipVerts = 2 * kMaxClipInput + 8;

// Clips polygon `in` (n vertices, n >= 3) by s.x <= d; writes to `out`
// (capacity kMaxClipVerts) and returns the new count. A 2-vertex input is
// treated as a segment and a 1-vertex input as a point.
int clipByPlane(const ClipVertex* in, int n, const Vec3& s, Real d, int plane, ClipVertex* out);

// Chooses up to 4 of n contacts to keep the support area largest:
//   1. the deepest point;
//   2. the point farthest from it;
//   3. the point farthest from the line through those two;
//   4. the point that adds the most area to that triangle.
// Distances are measured in the plane perpendicular to `normal`. Writes the
// chosen indices to keep[] and returns how many (min(n, 4)).
int reduceToFour(const Vec3* pos, const Real* depth, int n, const Vec3& normal, int keep[4]);

}  // namespace cairn
