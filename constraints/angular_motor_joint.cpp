// Angular velocity motor on up to three axes fixed in body a: each axis u
// gets a motor row u.(w_a - w_b) -> target (a relative to b, as every joint
// coordinate; ODE's dJointTypeAMotor) with |lambda| <= max torque h.
#include "constraints/joint.hpp"

namespace cairn {

void buildAngularMotorRows(const Joint& j, const BodyView& a, const BodyView& b, RowContext& ctx) {
  for (size_t k = 0; k < j.local_motor_axes.size(); ++k) {
    MotorDef m;
    m.enabled = true;
    m.target_velocity = j.def.motor_targets[k];
    m.max_force = j.def.motor_max_torques[k];
    addMotorPart(ctx, a, b, static_cast<int>(k), m, 0, true, relativeRotation(worldVector(a, j.local_motor_axes[k])));
  }
}

}  // namespace cairn
