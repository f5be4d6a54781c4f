// Ball-socket joint (3 rows): the anchors coincide, C = p_b - p_a = 0.
#include "constraints/joint.hpp"

namespace cairn {

void buildBallRows(const Joint& j, const BodyView& a, const BodyView& b, RowContext& ctx) {
  ctx.kind = RowKind::JointLinear;
  addPointPart(ctx, a, b, 0, worldPoint(a, j.local_anchor_a), worldPoint(b, j.local_anchor_b));
}

}  // namespace cairn
