// Convex hulls from point clouds, built with qhull's reentrant C library.
//
// qhull (Barber, Dobkin, Huhdanpaa, "The Quickhull algorithm for convex
// hulls", ACM TOMS 1996) is used instead of a hand-written quickhull because
// its merging of nearly coplanar facets ('C-0', on by default in 3-d) is the
// hard, precision-sensitive part, and it is a Debian package already.
//
// What we take from qhull: the set of hull vertices and, per facet, the
// vertices on it. What we compute ourselves, so that every face satisfies
// our own invariants exactly:
//   - the vertex loop of a face, ordered counter-clockwise seen from outside
//     by sorting the vertices by angle about their centroid in the facet
//     plane (a facet is convex, so the angular order is its boundary order);
//   - the outward unit normal n from Newell's method on that loop (exact for
//     a planar polygon, a least-squares plane for a slightly non-planar one),
//     checked against qhull's outward normal;
//   - the offset d = max over the face's vertices of n.v, so every face
//     vertex satisfies n.v <= d;
//   - the unique edges, as (min, max) vertex index pairs of the loops.
#include "collision/hull.hpp"

#include "cairn/error.hpp"

extern "C" {
#include <libqhull_r/qhull_ra.h>
}

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <set>

namespace cairn {
namespace {

// Rejects input that cannot enclose volume before handing it to qhull, so
// that the message says what is wrong instead of qhull's diagnostics. The
// test picks the two points farthest apart along the widest bounding-box
// axis, the point farthest from their line, then the point farthest from the
// plane of those three; each distance is compared with the size of the cloud.
void checkEnclosesVolume(const std::vector<Vec3>& points, const std::string& object, const std::string& field) {
  const char* kCoplanar = "points are coplanar: a hull must enclose volume";
  Vec3 lo = points[0], hi = points[0];
  for (const Vec3& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const Real size = (hi - lo).norm();
  // Relative tolerance: a sliver thinner than 1e-9 of the cloud is flat to
  // the precision qhull can resolve (its own round-off is ~1e-15 * size per
  // operation, amplified by the facet construction).
  const Real tol = Real(1e-9) * size;
  if (!(size > 0)) throw InputError(object, field, kCoplanar);
  int axis = 0;
  (hi - lo).maxCoeff(&axis);
  size_t i0 = 0, i1 = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    if (points[i][axis] < points[i0][axis]) i0 = i;
    if (points[i][axis] > points[i1][axis]) i1 = i;
  }
  const Vec3 a = points[i0];
  const Vec3 u = (points[i1] - a).normalized();
  size_t i2 = i0;
  Real best = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    const Vec3 r = points[i] - a;
    const Real dist = (r - u * u.dot(r)).norm();
    if (dist > best) best = dist, i2 = i;
  }
  if (best <= tol) throw InputError(object, field, kCoplanar);
  const Vec3 n = u.cross(points[i2] - a).normalized();
  best = 0;
  for (const Vec3& p : points) best = std::max(best, std::abs(n.dot(p - a)));
  if (best <= tol) throw InputError(object, field, kCoplanar);
}

// Owns one qhull run and frees its memory on every exit path.
class QhullRun {
 public:
  QhullRun() {
    err_ = open_memstream(&err_text_, &err_size_);
    qh_zero(&qh_, err_);
  }
  ~QhullRun() {
    qh_freeqhull(&qh_, !qh_ALL);
    int curlong = 0, totlong = 0;
    qh_memfreeshort(&qh_, &curlong, &totlong);
    if (err_) std::fclose(err_);
    std::free(err_text_);
  }
  QhullRun(const QhullRun&) = delete;
  QhullRun& operator=(const QhullRun&) = delete;

  int run(std::vector<coordT>& coords) {
    // 'qhull' with its 3-d defaults: C-0 merges facets that are coplanar to
    // round-off, so a cube comes back as 6 quadrilaterals, not 12 triangles.
    char cmd[] = "qhull";
    return qh_new_qhull(&qh_, 3, static_cast<int>(coords.size() / 3), coords.data(), False, cmd, nullptr, err_);
  }
  std::string errorText() {
    if (err_) std::fflush(err_);
    std::string s = err_text_ ? std::string(err_text_, err_size_) : std::string();
    const size_t nl = s.find('\n');
    return nl == std::string::npos ? s : s.substr(0, nl);
  }
  qhT* qh() { return &qh_; }

 private:
  qhT qh_;
  FILE* err_ = nullptr;
  char* err_text_ = nullptr;
  size_t err_size_ = 0;
};

}  // namespace

std::shared_ptr<const ConvexHullData> buildConvexHull(const std::vector<Vec3>& points, const std::string& object,
                                                      const std::string& field, const InputLimits& limits) {
  if (points.size() > limits.hull_points)
    throw InputError(object, field, std::to_string(points.size()) + " points exceed the limit " +
                                        limitHint("hull_points", limits.hull_points));
  for (size_t i = 0; i < points.size(); ++i)
    if (!points[i].allFinite())
      throw InputError(object, field, "points[" + std::to_string(i) + "] is not finite");
  if (points.size() < 4)
    throw InputError(object, field,
                     "a hull needs at least 4 points that enclose volume, got " + std::to_string(points.size()));
  checkEnclosesVolume(points, object, field);

  std::vector<coordT> coords(points.size() * 3);
  for (size_t i = 0; i < points.size(); ++i)
    for (int k = 0; k < 3; ++k) coords[3 * i + k] = points[i][k];

  QhullRun run;
  const int code = run.run(coords);
  if (code == qh_ERRsingular) throw InputError(object, field, "points are coplanar: a hull must enclose volume");
  if (code != qh_ERRnone) throw InputError(object, field, "qhull failed: " + run.errorText());
  qhT* qh = run.qh();  // the FORALL/FOREACH macros below refer to `qh`

  auto hull = std::make_shared<ConvexHullData>();
  // Hull vertices, renumbered densely in input order (deterministic).
  std::vector<int> remap(points.size(), -1);
  {
    vertexT* vertex;
    std::vector<int> ids;
    FORALLvertices ids.push_back(qh_pointid(qh, vertex->point));
    std::sort(ids.begin(), ids.end());
    for (int id : ids) {
      remap[id] = static_cast<int>(hull->vertices.size());
      hull->vertices.push_back(points[id]);
    }
  }

  facetT* facet;
  std::set<std::array<int, 2>> edges;
  FORALLfacets {
    if (facet->upperdelaunay || !facet->normal) continue;
    const Vec3 qn(facet->normal[0], facet->normal[1], facet->normal[2]);
    std::vector<int> loop;
    vertexT *vertex, **vertexp;
    FOREACHvertex_(facet->vertices) loop.push_back(remap[qh_pointid(qh, vertex->point)]);
    if (loop.size() < 3) continue;

    Vec3 centroid = Vec3::Zero();
    for (int v : loop) centroid += hull->vertices[v];
    centroid /= Real(loop.size());
    const Vec3 u = anyPerpendicular(qn);
    const Vec3 w = qn.cross(u);
    std::vector<std::pair<Real, int>> by_angle;
    for (int v : loop) {
      const Vec3 r = hull->vertices[v] - centroid;
      by_angle.emplace_back(std::atan2(w.dot(r), u.dot(r)), v);
    }
    std::sort(by_angle.begin(), by_angle.end());
    // Start each loop at its lowest vertex index so the output does not
    // depend on where the angle origin happened to fall.
    auto first = std::min_element(by_angle.begin(), by_angle.end(),
                                  [](const auto& a, const auto& b) { return a.second < b.second; });
    std::rotate(by_angle.begin(), first, by_angle.end());
    for (size_t k = 0; k < loop.size(); ++k) loop[k] = by_angle[k].second;

    // Newell's method: the area-weighted normal of the loop.
    Vec3 n = Vec3::Zero();
    for (size_t k = 0; k < loop.size(); ++k) {
      const Vec3& a = hull->vertices[loop[k]];
      const Vec3& b = hull->vertices[loop[(k + 1) % loop.size()]];
      n += (a - centroid).cross(b - centroid);
    }
    if (n.norm() <= 0 || n.dot(qn) <= 0) n = qn;  // sliver: trust qhull's plane
    n.normalize();
    Real d = -kInf;
    for (int v : loop) d = std::max(d, n.dot(hull->vertices[v]));

    for (size_t k = 0; k < loop.size(); ++k) {
      const int a = loop[k], b = loop[(k + 1) % loop.size()];
      edges.insert({std::min(a, b), std::max(a, b)});
    }
    hull->faces.push_back(std::move(loop));
    hull->face_normals.push_back(n);
    hull->face_offsets.push_back(d);
  }
  hull->edges.assign(edges.begin(), edges.end());
  if (hull->faces.size() < 4) throw InputError(object, field, "points are coplanar: a hull must enclose volume");
  return hull;
}

}  // namespace cairn
