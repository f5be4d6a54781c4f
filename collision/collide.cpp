// collide(): picks the routine for a pair of shape types.
//
// Shape types are ranked plane < mesh < sphere < capsule < box < cylinder <
// hull; each routine takes the lower-ranked shape first. For the other order
// the pair is swapped and the normals of what it appended are negated
// (positions, depths and feature ids do not depend on the order).
#include "collision/narrowphase.hpp"

namespace cairn {
namespace {

int rank(ShapeType t) {
  switch (t) {
    case ShapeType::Plane: return 0;
    case ShapeType::Mesh: return 1;
    case ShapeType::Sphere: return 2;
    case ShapeType::Capsule: return 3;
    case ShapeType::Box: return 4;
    case ShapeType::Cylinder: return 5;
    case ShapeType::ConvexHull: return 6;
  }
  return 7;
}

int collideOrdered(const ShapeDesc& a, const Transform& ta, const ShapeDesc& b, const Transform& tb, Real margin,
                   std::vector<Manifold>& out) {
  using namespace narrow;
  switch (a.type) {
    case ShapeType::Plane: return b.type == ShapeType::Plane || b.type == ShapeType::Mesh ? 0 : planeConvex(a, ta, b, tb, margin, out);
    case ShapeType::Mesh: return b.type == ShapeType::Mesh ? 0 : meshConvex(a, ta, b, tb, margin, out);
    case ShapeType::Sphere:
      if (b.type == ShapeType::Sphere) return sphereSphere(a, ta, b, tb, margin, out);
      if (b.type == ShapeType::Capsule) return sphereCapsule(a, ta, b, tb, margin, out);
      if (b.type == ShapeType::Box) return sphereBox(a, ta, b, tb, margin, out);
      break;
    case ShapeType::Capsule:
      if (b.type == ShapeType::Capsule) return capsuleCapsule(a, ta, b, tb, margin, out);
      if (b.type == ShapeType::Box) return capsuleBox(a, ta, b, tb, margin, out);
      break;
    case ShapeType::Box:
      if (b.type == ShapeType::Box) return boxBox(a, ta, b, tb, margin, out);
      break;
    default: break;
  }
  return convexConvex(a, ta, b, tb, margin, out);
}

}  // namespace

bool canCollide(ShapeType a, ShapeType b) {
  const bool sa = a == ShapeType::Plane || a == ShapeType::Mesh;
  const bool sb = b == ShapeType::Plane || b == ShapeType::Mesh;
  return !(sa && sb);
}

int collide(const ShapeDesc& a, const Transform& ta, const ShapeDesc& b, const Transform& tb, Real margin,
            std::vector<Manifold>& out) {
  if (!canCollide(a.type, b.type)) return 0;
  if (rank(a.type) <= rank(b.type)) return collideOrdered(a, ta, b, tb, margin, out);
  const size_t first = out.size();
  const int n = collideOrdered(b, tb, a, ta, margin, out);
  for (size_t i = first; i < out.size(); ++i) out[i].normal = -out[i].normal;
  return n;
}

}  // namespace cairn
