// EPA (the expansion rule is in epa.hpp).
#include "collision/epa.hpp"

#include <algorithm>
#include <array>

namespace cairn {
namespace {

constexpr int kMaxVerts = 128;
constexpr int kMaxFaces = 2 * kMaxVerts;

struct Face {
  int v[3];
  Vec3 n;      // outward unit normal
  Real dist;   // n . w_v0: distance of the plane from the origin
  bool alive;
};

struct Polytope {
  std::array<SimplexVertex, kMaxVerts> verts;
  std::array<Face, kMaxFaces> faces;
  int nv = 0, nf = 0;

  // Adds face (i, j, k), counter-clockwise seen from outside. Returns false
  // for a sliver with no usable normal.
  bool addFace(int i, int j, int k) {
    if (nf >= kMaxFaces) return false;
    const Vec3& a = verts[i].w;
    const Vec3 n = (verts[j].w - a).cross(verts[k].w - a);
    const Real len = n.norm();
    if (!(len > 0)) return false;
    Face& f = faces[nf++];
    f.v[0] = i, f.v[1] = j, f.v[2] = k;
    f.n = n / len;
    f.dist = f.n.dot(a);
    f.alive = true;
    return true;
  }
};

}  // namespace

EpaResult epaPenetration(const ConvexProxy& pa, const ConvexProxy& pb, bool full, const Simplex& start) {
  EpaResult res;
  const Real scale = pa.scale + pb.scale + (full ? pa.radius + pb.radius : Real(0));
  const Real tiny = Real(1e-9) * scale;
  // Accuracy asked of the depth: exact for polytopes (they stop when the
  // support repeats a vertex), 1e-8 of the size for curved boundaries.
  const Real tol = Real(1e-8) * scale;
  auto support = [&](const Vec3& d) { return minkowskiSupport(pa, pb, d, full); };

  // 1. A tetrahedron with volume, from the simplex plus support points in
  //    directions that leave its span.
  Simplex s = start;
  if (s.count == 0) s.v[s.count++] = support(Vec3::UnitX());
  if (s.count == 1) {
    static const Vec3 kDirs[6] = {Vec3::UnitX(), -Vec3::UnitX(), Vec3::UnitY(), -Vec3::UnitY(), Vec3::UnitZ(), -Vec3::UnitZ()};
    for (const Vec3& d : kDirs) {
      const SimplexVertex w = support(d);
      if ((w.w - s.v[0].w).norm() > tiny) {
        s.v[s.count++] = w;
        break;
      }
    }
  }
  if (s.count == 2) {
    const Vec3 axis = (s.v[1].w - s.v[0].w).normalized();
    const Vec3 u = anyPerpendicular(axis), v = axis.cross(u);
    for (int k = 0; k < 6 && s.count == 2; ++k) {
      const Real ang = k * kPi / 3;
      const SimplexVertex w = support(std::cos(ang) * u + std::sin(ang) * v);
      const Vec3 r = w.w - s.v[0].w;
      if ((r - axis * axis.dot(r)).norm() > tiny) s.v[s.count++] = w;
    }
  }
  if (s.count == 3) {
    const Vec3 n = (s.v[1].w - s.v[0].w).cross(s.v[2].w - s.v[0].w).normalized();
    for (const Vec3& d : {n, Vec3(-n)}) {
      const SimplexVertex w = support(d);
      if (std::abs(n.dot(w.w - s.v[0].w)) > tiny) {
        s.v[s.count++] = w;
        break;
      }
    }
  }
  if (s.count < 4) return res;  // D is flat: no volume to expand into
  {
    const Vec3& a = s.v[0].w;
    const Real vol = (s.v[1].w - a).cross(s.v[2].w - a).dot(s.v[3].w - a);
    if (std::abs(vol) <= tiny * tiny * tiny) return res;
  }

  // 2. The polytope: faces wound counter-clockwise seen from outside, i.e.
  //    with normals pointing away from the tetrahedron's centroid.
  Polytope poly;
  for (int i = 0; i < 4; ++i) poly.verts[poly.nv++] = s.v[i];
  {
    const Vec3 c = (s.v[0].w + s.v[1].w + s.v[2].w + s.v[3].w) * Real(0.25);
    static const int kTet[4][3] = {{0, 1, 2}, {0, 3, 1}, {0, 2, 3}, {1, 3, 2}};
    for (const auto& f : kTet) {
      int i = f[0], j = f[1], k = f[2];
      const Vec3 n = (poly.verts[j].w - poly.verts[i].w).cross(poly.verts[k].w - poly.verts[i].w);
      if (n.dot(poly.verts[i].w - c) < 0) std::swap(j, k);
      if (!poly.addFace(i, j, k)) return res;
    }
  }

  // 3. Expand.
  std::array<std::array<int, 2>, 3 * kMaxFaces> horizon;
  int best = -1;
  for (int iter = 0; iter < kMaxVerts; ++iter) {
    res.iterations = iter + 1;
    best = -1;
    for (int f = 0; f < poly.nf; ++f)
      if (poly.faces[f].alive && (best < 0 || poly.faces[f].dist < poly.faces[best].dist)) best = f;
    if (best < 0) return res;
    const Face& fb = poly.faces[best];
    const SimplexVertex w = support(fb.n);
    const Real gap = fb.n.dot(w.w) - fb.dist;
    if (gap <= tol || poly.nv >= kMaxVerts) break;
    // A support point equal to a polytope vertex cannot grow it: done.
    bool repeated = false;
    for (int i = 0; i < poly.nv && !repeated; ++i) repeated = (poly.verts[i].w - w.w).squaredNorm() <= tiny * tiny;
    if (repeated) break;

    const int wi = poly.nv++;
    poly.verts[wi] = w;
    // Remove the faces w sees; their unpaired edges form the horizon.
    int nh = 0;
    for (int f = 0; f < poly.nf; ++f) {
      Face& face = poly.faces[f];
      if (!face.alive) continue;
      // Strictly visible only: a face coplanar with w (common when D is a
      // polytope with many support points on one facet) stays, or round-off
      // would decide and could leave a horizon that is not a closed loop.
      if (face.n.dot(w.w - poly.verts[face.v[0]].w) <= tiny && f != best) continue;
      face.alive = false;
      for (int e = 0; e < 3; ++e) {
        const int i = face.v[e], j = face.v[(e + 1) % 3];
        int found = -1;
        for (int h = 0; h < nh; ++h)
          if (horizon[h][0] == j && horizon[h][1] == i) {
            found = h;
            break;
          }
        if (found >= 0) horizon[found] = horizon[--nh];
        else horizon[nh++] = {i, j};
      }
    }
    // Compact dead faces so the array does not fill with them.
    int live = 0;
    for (int f = 0; f < poly.nf; ++f)
      if (poly.faces[f].alive) poly.faces[live++] = poly.faces[f];
    poly.nf = live;
    bool ok = true;
    for (int h = 0; h < nh && ok; ++h) ok = poly.addFace(horizon[h][0], horizon[h][1], wi);
    if (!ok) {
      // Out of room or a sliver: stop with the best face of the last
      // complete polytope (faces added so far only refine it).
      best = -1;
      for (int f = 0; f < poly.nf; ++f)
        if (poly.faces[f].alive && (best < 0 || poly.faces[f].dist < poly.faces[best].dist)) best = f;
      break;
    }
  }
  if (best < 0) return res;

  // 4. The nearest point of the face, in barycentric coordinates, gives the
  //    two witness points. A flat facet of D is split into coplanar
  //    triangles of (almost) equal distance, and round-off may pick one
  //    that does not contain the origin's projection: among the faces in
  //    the same plane, take the one that contains it best.
  auto barycentric = [&](const Face& f, Real l[3]) {
    const Vec3& a = poly.verts[f.v[0]].w;
    const Vec3& b = poly.verts[f.v[1]].w;
    const Vec3& c = poly.verts[f.v[2]].w;
    const Vec3 p = f.n * f.dist;
    const Vec3 n = (b - a).cross(c - a);
    const Real area = n.squaredNorm();
    l[0] = (c - b).cross(p - b).dot(n) / area;
    l[1] = (a - c).cross(p - c).dot(n) / area;
    l[2] = 1 - l[0] - l[1];
    return std::min({l[0], l[1], l[2]});
  };
  Real l[3];
  Real inside = barycentric(poly.faces[best], l);
  for (int g = 0; g < poly.nf && inside < 0; ++g) {
    const Face& o = poly.faces[g];
    if (!o.alive || g == best || std::abs(o.dist - poly.faces[best].dist) > tol || o.n.dot(poly.faces[best].n) < 1 - 1e-9) continue;
    Real lo[3];
    const Real in_o = barycentric(o, lo);
    if (in_o > inside) {
      inside = in_o;
      best = g;
      std::copy(lo, lo + 3, l);
    }
  }
  const Face& f = poly.faces[best];
  const SimplexVertex& A = poly.verts[f.v[0]];
  const SimplexVertex& B = poly.verts[f.v[1]];
  const SimplexVertex& C = poly.verts[f.v[2]];
  const Real l1 = std::clamp(l[0], Real(0), Real(1));
  const Real l2 = std::clamp(l[1], Real(0), Real(1) - l1);
  const Real l3 = 1 - l1 - l2;
  // The origin must be inside (or on) the polytope; a face beyond it means
  // round-off broke the expansion, and the caller falls back.
  if (f.dist < -tol) return res;
  res.ok = true;
  res.normal = f.n;
  res.depth = f.dist;
  res.point_a = l1 * A.a + l2 * B.a + l3 * C.a;
  res.point_b = l1 * A.b + l2 * B.b + l3 * C.b;
  return res;
}

}  // namespace cairn
