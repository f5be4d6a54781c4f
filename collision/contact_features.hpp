// Supporting features and face clipping: from a contact normal to a full
// manifold.
//
// Given the normal n (A toward B), each shape offers the feature it turns
// toward the other: A its feature in direction +n, B in direction -n.
//   sphere    its center (a point; radius r)
//   capsule   its segment when nearly perpendicular to n, else the nearer end
//   box       the face whose normal is closest to the direction
//   hull      among the faces around the support vertex, the one whose normal
//             is closest to the direction
//   cylinder  a cap (an 8-gon on the rim, starting at the deepest rim
//             point) when the axis is within 60 degrees of the direction,
//             else the side line through the deepest points of both caps
//   triangle  the triangle, facing the direction
// If one of the two features is a face whose normal agrees with n to within
// kFaceCos (4.5e-6 rad: GJK and EPA return a face normal to round-off when a
// face is what touches, and anything looser would tilt the normal of
// near-face edge contacts), it becomes the reference face (A's when both
// qualify, so flush faces pick the same one every frame) and the other
// feature, the incident one, is clipped by the reference face's side planes
// (Sutherland-Hodgman, clip.hpp). Each surviving incident point q, of core
// radius r, lies at separation
//   sep = n_ref . q - r - d_ref
// from the reference plane n_ref . x = d_ref; points with sep <= margin are
// contacts of depth -sep, placed halfway between q - r n_ref and its
// projection on the plane; the normal becomes n_ref (oriented A to B), and
// at most 4 are kept (clip.hpp). This is the "reference face / incident
// face" scheme of Box2D and of Gregorius, "The Separating Axis Test between
// Convex Polyhedra" (GDC 2013).
// Two parallel segments (capsule or cylinder sides) give two points over
// their common extent. Whenever those points fall short of the depth of the
// witness pair the caller found (a curved feature's polygon, or slightly
// skew segments whose closest approach is between their ends), the witness
// pair joins them. Otherwise the contact is the witness pair alone.
#pragma once

#include "collision/clip.hpp"
#include "collision/convex_proxy.hpp"
#include "collision/manifold.hpp"

namespace cairn {

// |cos| of the angle within which a face counts as aligned with the normal.
constexpr Real kFaceCos = Real(1) - Real(1e-11);  // 4.5e-6 rad
// |sin| below which a segment counts as perpendicular to the normal, or two
// segments as parallel.
constexpr Real kSegmentSin = Real(0.0349);  // sin(2 degrees)

struct Feature {
  static constexpr int kMaxVerts = kMaxClipInput;
  int count = 0;           // 1 point, 2 segment, >= 3 convex polygon
  Vec3 v[kMaxVerts];       // world, on the core; polygons counter-clockwise about `normal`
  Vec3 normal = Vec3::Zero();  // polygons: outward unit normal
  Real offset = 0;         // polygons: normal . v
  Real radius = 0;         // core radius
  int index = 0;           // which face / edge / vertex (for feature ids)
};

// The feature of p facing unit world direction `dir` (outward from p).
void supportFeature(const ConvexProxy& p, const Vec3& dir, Feature& f);

// Face `face` of a box (axis face / 2, sign + for even, - for odd), wound
// counter-clockwise seen from outside; index = face.
void boxFace(const Vec3& center, const Mat3& rot, const Vec3& half, int face, Feature& f);

// Clips `inc` by the side planes of reference face `ref` and writes the
// contacts within `margin` to m (normal = ref normal, flipped when the
// reference face belongs to B). If `deepest` (a contact known to be the
// deepest, e.g. GJK's or EPA's witness pair) is deeper than every clipped
// point, it joins them. Returns the number of contacts (0 if the incident
// feature misses the face).
int faceContact(const Feature& ref, const Feature& inc, bool ref_is_b, Real margin, Manifold& m,
                const ContactPoint* deepest = nullptr);

// The manifold of A and B for normal n (A to B) when the deepest pair of
// surface points is (wa on A, wb on B) at depth `depth`. Returns false when
// nothing lies within the margin.
bool buildManifold(const ConvexProxy& a, const ConvexProxy& b, const Vec3& n, Real depth, const Vec3& wa,
                   const Vec3& wb, Real margin, Manifold& m);

// Feature id of a single-point contact from the indices of the features
// (bits 0-29; the parallel-segment rule sets bit 29 on its second point, and
// a witness pair joining a clipped manifold sets bit 28).
inline std::uint32_t pointFeatureId(int a, int b) {
  return 0x40000000u | ((static_cast<std::uint32_t>(a) & 0x7FFF) << 15) | (static_cast<std::uint32_t>(b) & 0x7FFF);
}

}  // namespace cairn
