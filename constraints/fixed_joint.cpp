// Fixed (weld) joint, 6 rows: the point part keeps the anchors together and
// the orientation part keeps q_a^-1 q_b at its value at creation; its error
// is the rotation vector log(q_b (q_a q_rel0)^-1) in the world frame.
#include "constraints/joint.hpp"

namespace cairn {

void buildFixedRows(const Joint& j, const BodyView& a, const BodyView& b, RowContext& ctx) {
  ctx.kind = RowKind::JointLinear;
  addPointPart(ctx, a, b, 0, worldPoint(a, j.local_anchor_a), worldPoint(b, j.local_anchor_b));
  ctx.kind = RowKind::JointAngular;
  addOrientationPart(ctx, a, b, 3, j.rel_orientation0);
}

}  // namespace cairn
