// EPA (the expansion rule is in epa.hpp).
#include "collision/epa.hpp"

#include <algorithm>
#include <array>

namespace cairn {
namespace {

constexpr int kMaxVerts = 128;
constexpr int kMaxFaces = 2 * kMaxVerts + 16;  // a closed triangulation has 2V - 4

struct Face {
  int v[3];    // counter-clockwise seen from outside
  int adj[3];  // face across edge v[e] -> v[e + 1]
  Vec3 n;      // outward unit normal
  Real dist;   // n . w_v0: distance of the plane from the origin
  bool alive;
};

struct Polytope {
  std::array<SimplexVertex, kMaxVerts> verts;
  std::array<Face, kMaxFaces> faces;
  std::array<int, kMaxFaces> free_list;
  int nv = 0, nf = 0, nfree = 0;

  // Adds face (i, j, k), counter-clockwise seen from outside, reusing a dead
  // slot if there is one. Returns -1 when full or for a sliver with no
  // usable normal.
  int addFace(int i, int j, int k) {
    const Vec3& a = verts[i].w;
    const Vec3 n = (verts[j].w - a).cross(verts[k].w - a);
    const Real len = n.norm();
    if (!(len > 0)) return -1;
    int at;
    if (nfree > 0) at = free_list[--nfree];
    else if (nf < kMaxFaces) at = nf++;
    else return -1;
    Face& f = faces[at];
    f.v[0] = i, f.v[1] = j, f.v[2] = k;
    f.adj[0] = f.adj[1] = f.adj[2] = -1;
    f.n = n / len;
    f.dist = f.n.dot(a);
    f.alive = true;
    return at;
  }
  void kill(int f) {
    faces[f].alive = false;
    free_list[nfree++] = f;
  }
  // The edge of face g that leads back to face f.
  int edgeTo(int g, int f) const {
    for (int e = 0; e < 3; ++e)
      if (faces[g].adj[e] == f) return e;
    return -1;
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
  //    with normals pointing away from the tetrahedron's centroid, and each
  //    face knowing its three neighbours.
  Polytope poly;
  for (int i = 0; i < 4; ++i) poly.verts[poly.nv++] = s.v[i];
  {
    const Vec3 c = (s.v[0].w + s.v[1].w + s.v[2].w + s.v[3].w) * Real(0.25);
    static const int kTet[4][3] = {{0, 1, 2}, {0, 3, 1}, {0, 2, 3}, {1, 3, 2}};
    for (const auto& f : kTet) {
      int i = f[0], j = f[1], k = f[2];
      const Vec3 n = (poly.verts[j].w - poly.verts[i].w).cross(poly.verts[k].w - poly.verts[i].w);
      if (n.dot(poly.verts[i].w - c) < 0) std::swap(j, k);
      if (poly.addFace(i, j, k) < 0) return res;
    }
    // Neighbours: the face holding the same edge the other way round.
    for (int f = 0; f < 4; ++f)
      for (int e = 0; e < 3; ++e)
        for (int g = 0; g < 4; ++g)
          for (int h = 0; h < 3; ++h)
            if (poly.faces[g].v[h] == poly.faces[f].v[(e + 1) % 3] && poly.faces[g].v[(h + 1) % 3] == poly.faces[f].v[e])
              poly.faces[f].adj[e] = g;
  }

  // 3. Expand. The faces w sees are found by a flood fill from the nearest
  //    face across neighbours, so they form one connected region and its
  //    boundary, the horizon, is one loop: on a flat facet of D with many
  //    support points, visibility decided face by face could leave islands
  //    and a polytope that is no longer convex.
  struct HorizonEdge {
    int a, b;      // edge as wound in the removed face
    int outside;   // the kept face across it
  };
  std::array<HorizonEdge, kMaxFaces> horizon;
  std::array<int, kMaxFaces> removed;
  std::array<int, 2 * kMaxFaces> stack;  // (face, edge leading back) pairs
  std::array<int, kMaxFaces> created;
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

    // Flood fill: `best` sees w (gap > tol); a neighbour is removed too when
    // w is strictly in front of it, else the shared edge is on the horizon.
    int nr = 0, nh = 0, top = 0;
    removed[nr++] = best;
    poly.faces[best].alive = false;
    for (int e = 2; e >= 0; --e) {
      stack[top++] = poly.faces[best].adj[e];
      stack[top++] = poly.edgeTo(poly.faces[best].adj[e], best);
    }
    bool broken = false;
    while (top > 0 && !broken) {
      const int back = stack[--top];
      const int g = stack[--top];
      Face& fg = poly.faces[g];
      if (!fg.alive) continue;  // already removed (reached another way)
      if (fg.n.dot(w.w - poly.verts[fg.v[0]].w) > tiny) {
        fg.alive = false;
        removed[nr++] = g;
        for (int k = 2; k >= 1; --k) {  // the two edges other than the way in
          const int e = (back + k) % 3;
          if (top + 2 > static_cast<int>(stack.size())) {
            broken = true;
            break;
          }
          stack[top++] = fg.adj[e];
          stack[top++] = poly.edgeTo(fg.adj[e], g);
        }
      } else {
        horizon[nh++] = HorizonEdge{fg.v[(back + 1) % 3], fg.v[back], g};
      }
    }
    // A removed face reached from another removed face whose edge was
    // already taken as horizon (the region closed around it) would leave a
    // stale horizon edge; drop those whose outside face was removed later.
    int kept_h = 0;
    for (int h = 0; h < nh; ++h)
      if (poly.faces[horizon[h].outside].alive) horizon[kept_h++] = horizon[h];
    nh = kept_h;
    // Every new face must have a normal, and there must be room for them.
    const int room = (kMaxFaces - poly.nf) + poly.nfree + nr;
    bool fits = !broken && nh >= 3 && nh <= room;
    for (int h = 0; h < nh && fits; ++h)
      fits = (poly.verts[horizon[h].b].w - poly.verts[horizon[h].a].w).cross(w.w - poly.verts[horizon[h].a].w).norm() > 0;
    if (!fits) {
      for (int r = 0; r < nr; ++r) poly.faces[removed[r]].alive = true;  // undo: stop with this polytope
      break;
    }
    const int wi = poly.nv++;
    poly.verts[wi] = w;
    for (int r = 0; r < nr; ++r) poly.kill(removed[r]);
    // New faces (a, b, w) over the horizon, stitched to the kept faces and
    // to each other (the face after edge a->b starts at b).
    for (int h = 0; h < nh; ++h) created[h] = poly.addFace(horizon[h].a, horizon[h].b, wi);
    bool ok = true;
    for (int h = 0; h < nh; ++h) {
      Face& nf = poly.faces[created[h]];
      const int out = horizon[h].outside;
      nf.adj[0] = out;
      for (int e = 0; e < 3; ++e)
        if (poly.faces[out].v[e] == horizon[h].b && poly.faces[out].v[(e + 1) % 3] == horizon[h].a) poly.faces[out].adj[e] = created[h];
      for (int k = 0; k < nh; ++k) {
        if (horizon[k].a == horizon[h].b) nf.adj[1] = created[k];  // edge b -> w
        if (horizon[k].b == horizon[h].a) nf.adj[2] = created[k];  // edge w -> a
      }
      ok = ok && nf.adj[1] >= 0 && nf.adj[2] >= 0;
    }
    if (!ok) {
      // The horizon was not one loop (round-off): stop with the nearest
      // face of what is left (its distance is still a lower bound).
      best = -1;
      for (int f = 0; f < poly.nf; ++f)
        if (poly.faces[f].alive && (best < 0 || poly.faces[f].dist < poly.faces[best].dist)) best = f;
      break;
    }
  }
  if (best < 0) return res;

  // 4. The normal and depth are the nearest face's. The witness points are
  //    where the ray from the origin along that normal leaves the polytope,
  //    in barycentric coordinates of the face it crosses: usually the
  //    nearest face itself, but on a flat facet of D split into coplanar
  //    triangles, or on a curved part tiled by many thin faces, the
  //    projection can fall just outside it, and clamping would put the two
  //    witness points off the line of the normal.
  const Face& fb = poly.faces[best];
  if (fb.dist < -tol) return res;  // origin outside: round-off broke the expansion
  auto crossing = [&](const Face& f, Real l[3]) {
    const Real along = f.n.dot(fb.n);
    if (!(along > 0)) return -kInf;
    const Vec3 q = fb.n * (f.dist / along);  // the ray meets f's plane here
    const Vec3& a = poly.verts[f.v[0]].w;
    const Vec3& b = poly.verts[f.v[1]].w;
    const Vec3& c = poly.verts[f.v[2]].w;
    const Vec3 n = (b - a).cross(c - a);
    const Real area = n.squaredNorm();
    l[0] = (c - b).cross(q - b).dot(n) / area;
    l[1] = (a - c).cross(q - c).dot(n) / area;
    l[2] = 1 - l[0] - l[1];
    return std::min({l[0], l[1], l[2]});
  };
  Real l[3];
  int hit = best;
  Real inside = crossing(fb, l);
  for (int g = 0; g < poly.nf && inside < 0; ++g) {
    if (!poly.faces[g].alive || g == best) continue;
    Real lg[3];
    const Real in_g = crossing(poly.faces[g], lg);
    if (in_g > inside) {
      inside = in_g;
      hit = g;
      std::copy(lg, lg + 3, l);
    }
  }
  const Face& f = poly.faces[hit];
  const SimplexVertex& A = poly.verts[f.v[0]];
  const SimplexVertex& B = poly.verts[f.v[1]];
  const SimplexVertex& C = poly.verts[f.v[2]];
  const Real l1 = std::clamp(l[0], Real(0), Real(1));
  const Real l2 = std::clamp(l[1], Real(0), Real(1) - l1);
  const Real l3 = 1 - l1 - l2;
  res.ok = true;
  res.normal = fb.n;
  res.depth = fb.dist;
  res.point_a = l1 * A.a + l2 * B.a + l3 * C.a;
  res.point_b = l1 * A.b + l2 * B.b + l3 * C.b;
  return res;
}

}  // namespace cairn
