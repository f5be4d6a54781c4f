// Distance joint, 1 row: C = |p_b - p_a| - L along n = (p_b - p_a)/|p_b - p_a|.
// Rigid by default; a stiffness/damping or frequency/damping-ratio softness
// makes it the implicit spring-damper of section 12.2.3 (softness.hpp).
#include "constraints/joint.hpp"

namespace cairn {

void buildDistanceRows(const Joint& j, const BodyView& a, const BodyView& b, RowContext& ctx) {
  const Vec3 pa = worldPoint(a, j.local_anchor_a), pb = worldPoint(b, j.local_anchor_b);
  const Vec3 d = pb - pa;
  const Real len = d.norm();
  if (len < Real(1e-9)) return;  // direction undefined for this step
  const Vec3 n = d / len;
  ctx.kind = RowKind::JointLinear;
  addRow(ctx, a, b, 0, -n, -(pa - a.x).cross(n), n, (pb - b.x).cross(n), len - j.length);
}

}  // namespace cairn
