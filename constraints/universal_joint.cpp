// Universal (Cardan) joint, 4 rows: the point part, and one angular row
// keeping axis a1 (fixed in a) perpendicular to axis a2 (fixed in b):
//   C = a1.a2,  C' = (w_a - w_b).(a1 x a2),  so J = [0, u, 0, -u], u = a1 x a2.
// Rotation about a1 and about a2 stays free.
#include "constraints/joint.hpp"

namespace cairn {

void buildUniversalRows(const Joint& j, const BodyView& a, const BodyView& b, RowContext& ctx) {
  ctx.kind = RowKind::JointLinear;
  addPointPart(ctx, a, b, 0, worldPoint(a, j.local_anchor_a), worldPoint(b, j.local_anchor_b));
  ctx.kind = RowKind::JointAngular;
  const Vec3 a1 = worldVector(a, j.local_axis_a);
  const Vec3 a2 = worldVector(b, j.local_axis2_b);
  addAnglePart(ctx, a, b, 3, -a1.cross(a2), a1.dot(a2));
}

}  // namespace cairn
