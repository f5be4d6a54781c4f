// Joint creation, lookup and feedback (the World's side of constraints/).
#include "cairn/error.hpp"
#include "world/world.hpp"

namespace cairn {

BodyView World::view(BodyId id) const {
  BodyView v;
  if (id.isWorld()) return v;
  const Body& b = body(id);
  v.solver_index = id.index + 1;
  v.x = b.position;
  v.q = b.orientation;
  v.rot = b.rotation;
  v.inv_mass = b.inv_mass;
  v.inv_inertia = b.isDynamic() ? b.inv_inertia_world : Mat3::Zero();
  v.v = b.linear_velocity;
  v.w = b.angular_velocity;
  return v;
}

JointId World::createJoint(const JointDef& def) {
  JointDef d = def;
  if (d.name.empty()) d.name = "joint" + std::to_string(joints_.size());
  const std::string obj = "joint '" + d.name + "'";
  if (findJoint(d.name).index >= 0) throw InputError(obj, "name", "another joint has this name");
  validateJointDef(d, bodyCount());
  joints_.push_back(makeJoint(d, view(d.body_a), view(d.body_b)));
  return JointId{static_cast<std::int32_t>(joints_.size() - 1)};
}

JointId World::findJoint(const std::string& name) const {
  for (size_t i = 0; i < joints_.size(); ++i)
    if (joints_[i].def.name == name) return JointId{static_cast<std::int32_t>(i)};
  return JointId{};
}

JointError World::jointError(JointId id) const {
  const Joint& j = joint(id);
  if (j.broken) return {};
  return measureJointError(j, view(j.def.body_a), view(j.def.body_b));
}

void World::removeJoint(JointId id) {
  Joint& j = joints_.at(static_cast<size_t>(id.index));
  j.broken = true;
  j.feedback = {};
  std::fill(j.warm.begin(), j.warm.end(), Real(0));
}

}  // namespace cairn
