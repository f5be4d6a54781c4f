// Wavefront OBJ loading: the subset cairn reads and the errors it reports.
#include "collision/obj_mesh.hpp"
#include "cairn/error.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include <unistd.h>

namespace cairn {
namespace {

namespace fs = std::filesystem;

// Writes `text` to a fresh file in the test's temporary directory.
std::string writeTemp(const std::string& name, const std::string& text) {
  const fs::path dir = fs::temp_directory_path() / ("cairn_obj_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path p = dir / name;
  std::ofstream(p) << text;
  return p.string();
}

TEST(ObjMesh, ValidFileLoadsWithFansNegativeIndicesAndIgnoredRecords) {
  const std::string path = writeTemp("valid.obj",
                                     "# a unit quad and a triangle\n"
                                     "mtllib level.mtl\n"
                                     "o floor\n"
                                     "v 0 0 0\n"
                                     "v 1 0 0\n"
                                     "v 1 0 1\n"
                                     "v 0 0 1 0.5 0.5 0.5\n"  // vertex colour, ignored
                                     "vn 0 1 0\n"
                                     "vt 0 0\n"
                                     "g group\n"
                                     "s off\n"
                                     "usemtl stone\n"
                                     "f 1/1/1 4/1/1 3/1/1 2/1/1\n"  // quad, fanned into 2 triangles
                                     "v 0 1 0\r\n"
                                     "f -1//1 -5//1 -4//1\n");      // relative indices
  const auto mesh = loadObjMesh(path);
  ASSERT_EQ(mesh->vertices.size(), 5u);
  ASSERT_EQ(mesh->triangles.size(), 3u);
  EXPECT_EQ(mesh->triangles[0], (std::array<int, 3>{0, 3, 2}));
  EXPECT_EQ(mesh->triangles[1], (std::array<int, 3>{0, 2, 1}));
  EXPECT_EQ(mesh->triangles[2], (std::array<int, 3>{4, 0, 1}));
  EXPECT_EQ(mesh->vertices[4], Vec3(0, 1, 0));
  EXPECT_FALSE(mesh->bvh.empty());  // loaded meshes come with their tree
}

void expectThrowsWith(const std::string& path, const std::string& what) {
  try {
    loadObjMesh(path, "body 'level'", "shapes[0].obj");
    FAIL() << "accepted " << path;
  } catch (const InputError& e) {
    EXPECT_EQ(e.object(), "body 'level'");
    EXPECT_EQ(e.field(), "shapes[0].obj");
    EXPECT_NE(e.message().find(path), std::string::npos) << e.what();
    EXPECT_NE(e.message().find(what), std::string::npos) << e.what();
  }
}

TEST(ObjMesh, MalformedLinesThrowWithPathAndLine) {
  expectThrowsWith(writeTemp("bad_vertex.obj", "v 0 0 0\nv 1 zero 0\n"), ":2: malformed vertex");
  expectThrowsWith(writeTemp("short_vertex.obj", "v 0 0\n"), ":1: malformed vertex");
  expectThrowsWith(writeTemp("long_vertex.obj", "v 0 0 0 1 1 1 1 1\n"), ":1: malformed vertex");
  expectThrowsWith(writeTemp("bad_face.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n"), ":4: face needs at least 3");
  expectThrowsWith(writeTemp("bad_corner.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 x 3\n"), ":4: malformed face corner");
  expectThrowsWith(writeTemp("bad_index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2 9\n"), ":5: face index 9 out of range");
  expectThrowsWith(writeTemp("bad_negative.obj", "v 0 0 0\nf -1 -2 -3\n"), ":2: face index -2 out of range");
  expectThrowsWith(writeTemp("nan.obj", "v 0 nan 0\n"), ":1: vertex is not finite");
  expectThrowsWith(writeTemp("no_tris.obj", "v 0 0 0\nv 1 0 0\n"), "no triangles");
  expectThrowsWith(writeTemp("unknown.obj", "v 0 0 0\nvx 1 0 0\n"), ":2: unknown record 'vx'");
}

TEST(ObjMesh, MissingFileThrowsWithPath) {
  expectThrowsWith((fs::temp_directory_path() / "cairn_no_such_dir" / "missing.obj").string(), "cannot open");
}

// A directory or a device is not read at all: /dev/zero has no line break
// and no end, so reading it would grow one line until memory ran out.
TEST(ObjMesh, OnlyRegularFilesAreRead) {
  expectThrowsWith(fs::temp_directory_path().string(), "not a regular file");
  expectThrowsWith("/dev/zero", "not a regular file");
}

// Every triangle without area: nothing for a body to rest on (bodies fell
// through such a mesh). Refused, whether the corners repeat or are collinear.
TEST(ObjMesh, MeshWhoseTrianglesAllLackAreaIsRefused) {
  expectThrowsWith(writeTemp("collinear.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 3 0 0\nf 1 2 3\nf 1 2 4\n"),
                   "no triangle with an area");
  expectThrowsWith(writeTemp("repeated.obj", "v 0 0 0\nv 1 0 0\nv 0 0 1\nf 1 1 2\nf 2 3 3\n"), "no triangle with an area");
}

// Among good triangles, those without area are dropped: a quad written
// with an extra corner in the middle of one edge (as exporters do), fanned
// from the first corner, gives the sliver (1, 2, 3) along that edge and two
// good triangles, which still cover the whole quad.
TEST(ObjMesh, TrianglesWithoutAreaAmongGoodOnesAreDropped) {
  const auto mesh = loadObjMesh(writeTemp("sliver.obj",
                                          "v 0 0 0\nv 0.5 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\n"
                                          "f 1 2 3 4 5\n"));
  ASSERT_EQ(mesh->triangles.size(), 2u);
  EXPECT_EQ(mesh->triangles[0], (std::array<int, 3>{0, 2, 3}));
  EXPECT_EQ(mesh->triangles[1], (std::array<int, 3>{0, 3, 4}));
  // Their areas sum to the quad's: exact, the corners are 0, 0.5 and 1.
  Real area = 0;
  for (const auto& t : mesh->triangles) {
    const auto& v = mesh->vertices;
    area += 0.5 * (v[t[1]] - v[t[0]]).cross(v[t[2]] - v[t[0]]).norm();
  }
  EXPECT_EQ(area, 1.0);
}

TEST(ObjMesh, VertexBeyondTheRepresentableRangeIsRefused) {
  expectThrowsWith(writeTemp("huge.obj", "v 0 0 0\nv 1e21 0 0\nv 0 0 1\nf 1 2 3\n"),
                   ":2: vertex is not finite or has a coordinate of magnitude above 1e+20");
}

// The counts are checked before the vertex or triangle is stored.
TEST(ObjMesh, CountsBeyondTheLimitsAreRefusedWithTheLimitsName) {
  InputLimits small;
  small.mesh_vertices = 3;
  small.mesh_triangles = 2;
  const auto refused = [&](const std::string& text, const std::string& what) {
    std::istringstream in(text);
    try {
      parseObjMesh(in, "m.obj", "body 'level'", "shapes[0].obj", small);
      ADD_FAILURE() << "accepted";
    } catch (const InputError& e) {
      EXPECT_NE(e.message().find(what), std::string::npos) << e.what();
    }
  };
  refused("v 0 0 0\nv 1 0 0\nv 0 0 1\nv 1 0 1\n", "m.obj:4: more than 3 vertices (limit mesh_vertices = 3");
  refused("v 0 0 0\nv 1 0 0\nv 0 0 1\nf 1 2 3 1 2\n", "m.obj:4: more than 2 triangles (limit mesh_triangles = 2");
  std::istringstream ok("v 0 0 0\nv 1 0 0\nv 0 0 1\nf 1 2 3\nf 1 3 2\n");
  EXPECT_EQ(parseObjMesh(ok, "m.obj", "", "obj", small)->triangles.size(), 2u);
}

}  // namespace
}  // namespace cairn
