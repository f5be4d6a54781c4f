// Angular velocity motor on up to three axes fixed in body a: each axis u
// gets a motor row u.(w_b - w_a) -> target with |lambda| <= max torque h.
#include "constraints/joint.hpp"

namespace cairn {

void buildAngularMotorRows(const Joint& j, const BodyView& a, const BodyView& b, RowContext& ctx) {
  const Vec3 zero = Vec3::Zero();
  for (size_t k = 0; k < j.local_motor_axes.size(); ++k) {
    const Vec3 u = worldVector(a, j.local_motor_axes[k]);
    addMotorPart(ctx, a, b, static_cast<int>(k), j.def.motor_targets[k], j.def.motor_max_torques[k], zero, -u, zero, u);
  }
}

}  // namespace cairn
