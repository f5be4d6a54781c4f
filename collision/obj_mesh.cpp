// Wavefront OBJ reader for static triangle meshes.
//
// The subset read: `v x y z [w]` vertices (trailing vertex colours ignored)
// and `f` faces whose corners are
// `i`, `i/t`, `i//n` or `i/t/n` (only the position index i is used).
// Indices are 1-based; a negative index counts back from the last vertex
// defined so far (-1 is the previous vertex), as the format specifies. A face
// with k > 3 corners is fanned into k - 2 triangles (0, j, j + 1), which is
// exact for the convex planar polygons exporters write.
//
// Records that carry no geometry for collision (vn, vt, vp, o, g, s, usemtl,
// mtllib, l, p, comments) are skipped. Anything else is an error: a typo in
// level geometry is better reported than silently dropped.
//
// Triangles without area (repeated corners, collinear corners, slivers: see
// collision/triangle_area.hpp) are dropped. They cover no surface, so no
// contact is lost: in a mesh that is closed or tiles a surface, their edges
// are edges of the neighbouring triangles. Exporters write them routinely
// (a polygon with collinear corners, fanned), so refusing them would refuse
// ordinary level geometry. A mesh with no triangle left has nothing a body
// can rest on (bodies would fall through it) and is refused.
//
// Counts are checked against InputLimits before each allocation, and a
// coordinate beyond kMaxMagnitude is refused like a non-finite one
// (include/cairn/limits.hpp).
#include "collision/obj_mesh.hpp"

#include "collision/mesh_bvh.hpp"
#include "collision/triangle_area.hpp"
#include "cairn/error.hpp"

#include <cerrno>
#include <cstdlib>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace cairn {
namespace {

struct Reader {
  const std::string& path;
  const std::string& object;
  const std::string& field;
  int line = 0;

  [[noreturn]] void fail(const std::string& reason) const {
    throw InputError(object, field, path + ":" + std::to_string(line) + ": " + reason);
  }
};

bool parseReal(const std::string& tok, Real& out) {
  if (tok.empty()) return false;
  char* end = nullptr;
  errno = 0;
  out = std::strtod(tok.c_str(), &end);
  return end == tok.c_str() + tok.size();
}

bool parseInt(const std::string& tok, long& out) {
  if (tok.empty()) return false;
  char* end = nullptr;
  errno = 0;
  out = std::strtol(tok.c_str(), &end, 10);
  return errno == 0 && end == tok.c_str() + tok.size();
}

std::string magnitudeText() {
  std::ostringstream s;
  s << kMaxMagnitude;
  return s.str();
}

bool ignoredRecord(const std::string& k) {
  static const char* kIgnored[] = {"vn", "vt", "vp", "o", "g", "s", "usemtl", "mtllib", "l", "p"};
  for (const char* s : kIgnored)
    if (k == s) return true;
  return false;
}

}  // namespace

std::shared_ptr<const TriangleMeshData> loadObjMesh(const std::string& path, const std::string& object,
                                                    const std::string& field, const InputLimits& limits) {
  // Only a regular file: a directory, a FIFO or a device (/dev/zero) would
  // fail late or never end.
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw InputError(object, field, path + ":0: cannot open file (not a regular file, or missing)");
  const std::uintmax_t bytes = std::filesystem::file_size(path, ec);
  if (!ec && bytes > limits.file_bytes)
    throw InputError(object, field, path + ":0: " + std::to_string(bytes) + " bytes exceed the limit " +
                                        limitHint("file_bytes", limits.file_bytes));
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(object, field, path + ":0: cannot open file (" + std::strerror(errno) + ")");
  return parseObjMesh(in, path, object, field, limits);
}

std::shared_ptr<const TriangleMeshData> parseObjMesh(std::istream& in, const std::string& path, const std::string& object,
                                                     const std::string& field, const InputLimits& limits) {
  auto mesh = std::make_shared<TriangleMeshData>();
  Reader r{path, object, field};
  // Positive indices are resolved after the whole file is read (some
  // exporters reference vertices written later); keep where each came from.
  struct Pending {
    long index[3];
    int line;
  };
  std::vector<Pending> pending;
  std::string text;
  std::vector<long> corners;
  while (std::getline(in, text)) {
    ++r.line;
    if (!text.empty() && text.back() == '\r') text.pop_back();
    const size_t hash = text.find('#');
    if (hash != std::string::npos) text.resize(hash);
    std::istringstream ls(text);
    std::string key;
    if (!(ls >> key)) continue;  // blank or comment-only line
    if (key == "v") {
      Vec3 v;
      std::string tok;
      for (int k = 0; k < 3; ++k) {
        if (!(ls >> tok) || !parseReal(tok, v[k])) r.fail("malformed vertex: expected 'v x y z'");
      }
      // An optional w, or the r g b vertex colours some exporters add:
      // numbers, ignored.
      for (int extra = 0; ls >> tok; ++extra) {
        Real ignored;
        if (extra >= 4 || !parseReal(tok, ignored)) r.fail("malformed vertex: expected 'v x y z [w] [r g b]'");
      }
      if (!v.allFinite() || v.cwiseAbs().maxCoeff() > kMaxMagnitude)
        r.fail("vertex is not finite or has a coordinate of magnitude above " + magnitudeText());
      if (mesh->vertices.size() >= limits.mesh_vertices)
        r.fail("more than " + std::to_string(limits.mesh_vertices) + " vertices " +
               limitHint("mesh_vertices", limits.mesh_vertices));
      mesh->vertices.push_back(v);
    } else if (key == "f") {
      corners.clear();
      std::string tok;
      while (ls >> tok) {
        // The position index is everything before the first '/'.
        const std::string head = tok.substr(0, tok.find('/'));
        long idx = 0;
        if (!parseInt(head, idx)) r.fail("malformed face corner '" + tok + "'");
        if (idx == 0) r.fail("face index 0 is invalid (OBJ indices start at 1)");
        if (idx < 0) {
          const long resolved = static_cast<long>(mesh->vertices.size()) + idx;
          if (resolved < 0)
            r.fail("face index " + std::to_string(idx) + " out of range (" +
                   std::to_string(mesh->vertices.size()) + " vertices so far)");
          idx = resolved;
        } else {
          idx -= 1;
        }
        corners.push_back(idx);
      }
      if (corners.size() < 3) r.fail("face needs at least 3 vertices");
      if (pending.size() + (corners.size() - 2) > limits.mesh_triangles)
        r.fail("more than " + std::to_string(limits.mesh_triangles) + " triangles " +
               limitHint("mesh_triangles", limits.mesh_triangles));
      for (size_t j = 1; j + 1 < corners.size(); ++j)
        pending.push_back({{corners[0], corners[j], corners[j + 1]}, r.line});
    } else if (!ignoredRecord(key)) {
      r.fail("unknown record '" + key + "'");
    }
  }
  if (in.bad()) r.fail("read error");

  const long nv = static_cast<long>(mesh->vertices.size());
  mesh->triangles.reserve(pending.size());
  for (const Pending& p : pending) {
    for (long idx : p.index) {
      if (idx >= nv) {
        r.line = p.line;
        r.fail("face index " + std::to_string(idx + 1) + " out of range (" + std::to_string(nv) + " vertices)");
      }
    }
    const auto& v = mesh->vertices;
    if (!triangleHasArea(v[p.index[0]], v[p.index[1]], v[p.index[2]])) continue;  // see the top of the file
    mesh->triangles.push_back({static_cast<int>(p.index[0]), static_cast<int>(p.index[1]), static_cast<int>(p.index[2])});
  }
  if (pending.empty())
    throw InputError(object, field, path + ":" + std::to_string(r.line) + ": no triangles (no 'f' records)");
  if (mesh->triangles.empty())
    throw InputError(object, field, path + ":" + std::to_string(r.line) + ": no triangle with an area (" +
                                        std::to_string(pending.size()) +
                                        " faces' triangles, all with repeated or collinear corners): bodies would fall through");
  buildMeshBvh(*mesh);
  return mesh;
}

}  // namespace cairn
