// Mass properties of the primitive shapes and of compound bodies.
//
// Solid bodies of uniform density; inertia tensors about the center of mass
// in the shape's own frame (standard table formulas, e.g. any mechanics
// handbook):
//   sphere   I = 2/5 m r^2
//   box      I_xx = m/3 (hy^2 + hz^2) with half extents h (= m/12 (b^2+c^2))
//   cylinder I_yy = 1/2 m r^2, I_xx = I_zz = m/12 (3 r^2 + (2 hh)^2)
//   capsule  a cylinder plus two hemispheres, each hemisphere's inertia moved
//            from its own center of mass (3/8 r from the flat face) by the
//            parallel axis theorem.
// A compound body adds its shapes' tensors after rotating each into the body
// frame (R I R^T) and moving it to the combined center of mass by the
// parallel axis theorem: I += m (|d|^2 E - d d^T).
#pragma once

#include "cairn/shape.hpp"
#include "cairn/math.hpp"

#include <vector>

namespace cairn {

struct MassProperties {
  Real mass = 0;
  Vec3 center = Vec3::Zero();      // center of mass in the frame of reference
  Mat3 inertia = Mat3::Zero();     // about `center`, axes of that frame
};

// Volume of a shape (0 for planes and meshes, which cannot carry mass).
Real shapeVolume(const ShapeDesc& s);

// Unit-density mass properties of one shape in its own frame (before its
// local offset is applied), scaled to `density`.
MassProperties shapeMassProperties(const ShapeDesc& s, Real density);

// Shift an inertia tensor about the center of mass to a point displaced by d
// from it (parallel axis theorem).
Mat3 parallelAxis(const Mat3& inertia_com, Real mass, const Vec3& d);

// Combine shapes (each at its `local` pose in the body frame) of the given
// density into body-frame mass properties about their combined center.
MassProperties compoundMassProperties(const std::vector<ShapeDesc>& shapes, Real density);

}  // namespace cairn
