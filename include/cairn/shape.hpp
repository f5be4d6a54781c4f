/// @file
/// Collision shape descriptions: plain data, attached to a body at a local
/// offset. A body with several shapes is a compound body; its mass properties
/// combine through the parallel axis theorem (dynamics/mass_properties.hpp).
///
/// Conventions (shared with the scene format, docs/scene-format.md):
///   sphere   {radius}
///   box      {half_extents}
///   capsule  {radius, half_height}  segment along the local y axis
///   cylinder {radius, half_height}  axis along the local y axis
///   plane    {normal, offset}       points x with n.x <= offset are inside;
///                                   static bodies only
///   convex_hull {points}            hull of the points (ConvexHullData)
///   mesh     {triangles}            static triangle mesh (TriangleMeshData)
#pragma once

#include "cairn/math.hpp"

#include <array>
#include <memory>
#include <string>
#include <vector>

namespace cairn {

/// The kinds of shape (the table above).
enum class ShapeType { Sphere, Box, Capsule, Cylinder, Plane, ConvexHull, Mesh };

const char* shapeTypeName(ShapeType t);  ///< lower-case name, as in scene files

/// A convex polyhedron: vertices, faces as vertex loops (counter-clockwise
/// seen from outside) and one outward unit plane per face (n, d: n.x = d).
struct ConvexHullData {
  std::vector<Vec3> vertices;  ///< shape frame (m)
  std::vector<std::vector<int>> faces;  ///< each a loop of vertex indices, counter-clockwise seen from outside
  std::vector<Vec3> face_normals;  ///< outward unit normal n of each face
  std::vector<Real> face_offsets;  ///< d of each face's plane n.x = d (m)
  /// Unique edges as vertex index pairs (for the separating-axis test).
  std::vector<std::array<int, 2>> edges;
};

/// A static triangle mesh (level geometry), triangles counter-clockwise seen
/// from the side that pushes bodies out.
struct TriangleMeshData {
  std::vector<Vec3> vertices;  ///< shape frame (m)
  std::vector<std::array<int, 3>> triangles;  ///< vertex indices, counter-clockwise seen from the pushing side

  /// Optional bounding volume hierarchy over the triangles, filled by
  /// buildMeshBvh() (collision/mesh_bvh.hpp; loadObjMesh does it). Empty:
  /// the narrowphase tests every triangle.
  struct BvhNode {
    Vec3 lo;      ///< lower corner of the bounds of the node's triangles
    Vec3 hi;      ///< upper corner of those bounds
    int first;    ///< leaf: start in bvh_order; inner: index of the left child (right = first + 1)
    int count;    ///< leaf: number of triangles; inner: 0
  };
  std::vector<BvhNode> bvh;  ///< the nodes, root first; empty: no hierarchy
  std::vector<int> bvh_order;  ///< triangle indices, grouped by leaf
};
/// A collision shape: its type, its sizes, its pose in the body frame.
struct ShapeDesc {
  ShapeType type = ShapeType::Sphere;  ///< which shape; the fields below it uses
  Real radius = 0;  ///< sphere, capsule, cylinder (m)
  Real half_height = 0;  ///< capsule segment, cylinder (m)
  Vec3 half_extents = Vec3::Zero();  ///< box (m)
  Vec3 normal = Vec3::UnitY();  ///< plane
  Real offset = 0;              ///< plane
  std::shared_ptr<const ConvexHullData> hull;  ///< convex hull
  std::shared_ptr<const TriangleMeshData> mesh;  ///< triangle mesh
  std::string source;  ///< e.g. the OBJ path a mesh came from (for messages)
  Transform local;     ///< pose in the body frame (relative to the body origin)

  static ShapeDesc sphere(Real r) { ShapeDesc s; s.type = ShapeType::Sphere; s.radius = r; return s; }  ///< a sphere of radius r
  static ShapeDesc box(const Vec3& he) { ShapeDesc s; s.type = ShapeType::Box; s.half_extents = he; return s; }  ///< a box of half extents he
  static ShapeDesc capsule(Real r, Real hh) { ShapeDesc s; s.type = ShapeType::Capsule; s.radius = r; s.half_height = hh; return s; }  ///< a capsule along local y: radius, segment half height
  static ShapeDesc cylinder(Real r, Real hh) { ShapeDesc s; s.type = ShapeType::Cylinder; s.radius = r; s.half_height = hh; return s; }  ///< a cylinder along local y: radius, half height
  static ShapeDesc plane(const Vec3& n, Real d) { ShapeDesc s; s.type = ShapeType::Plane; s.normal = n; s.offset = d; return s; }  ///< the half-space n.x <= d (static bodies)
};

}  // namespace cairn
