#include "fuzz/targets.hpp"

#include "cairn/error.hpp"
#include "collision/obj_mesh.hpp"
#include "collision/triangle_area.hpp"
#include "world/scene_json.hpp"
#include "cairn/world.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

namespace cairn::fuzz {

namespace {

[[noreturn]] void broken(const char* what) {
  std::fprintf(stderr, "fuzz target: invariant broken: %s\n", what);
  std::abort();
}

bool finiteState(const World& w, BodyId id) {
  const Transform t = w.transform(id);
  return t.p.allFinite() && t.q.coeffs().allFinite() && w.linearVelocity(id).allFinite() &&
         w.angularVelocity(id).allFinite();
}

}  // namespace

InputLimits fuzzLimits() {
  InputLimits l;
  l.bodies = 16;
  l.shapes_per_body = 8;
  l.joints = 16;
  l.springs = 16;
  l.hull_points = 64;
  l.mesh_vertices = 4096;
  l.mesh_triangles = 4096;
  l.json_depth = 32;
  l.file_bytes = 1 << 20;
  l.iterations = 50;
  l.substeps = 4;
  return l;
}

Outcome sceneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const SceneDesc scene = parseScene(text, CAIRN_FUZZ_MESH_DIR "/fuzz-input.json", fuzzLimits());
    World world = buildWorld(scene);
    for (int s = 0; s < kSteps; ++s) {
      world.step(scene.dt);
      for (const BodyId id : world.bodies())
        if (!finiteState(world, id)) broken("a body's state is not finite after a step");
    }
    return Outcome::Loaded;
  } catch (const InputError&) {
    return Outcome::Refused;
  }
}

Outcome objInput(const std::uint8_t* data, std::size_t size) {
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  try {
    const auto mesh = parseObjMesh(in, "fuzz-input.obj", "", "obj", fuzzLimits());
    const int nv = static_cast<int>(mesh->vertices.size());
    if (mesh->triangles.empty()) broken("a loaded mesh has no triangles");
    for (const auto& t : mesh->triangles) {
      for (int i : t)
        if (i < 0 || i >= nv) broken("a triangle index is out of range");
      if (!triangleHasArea(mesh->vertices[t[0]], mesh->vertices[t[1]], mesh->vertices[t[2]]))
        broken("a loaded triangle has no area");
    }
    std::vector<int> order = mesh->bvh_order;
    std::sort(order.begin(), order.end());
    for (size_t i = 0; i < order.size(); ++i)
      if (order[i] != static_cast<int>(i) || order.size() != mesh->triangles.size())
        broken("the tree does not hold every triangle once");
    return Outcome::Loaded;
  } catch (const InputError&) {
    return Outcome::Refused;
  }
}

}  // namespace cairn::fuzz
