// Wavefront OBJ loading: the subset cairn reads and the errors it reports.
#include "collision/obj_mesh.hpp"
#include "cairn/error.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

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

}  // namespace
}  // namespace cairn
