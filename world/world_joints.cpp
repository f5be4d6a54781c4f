// Joint creation, destruction, lookup and feedback (the World's side of
// constraints/).
#include "cairn/error.hpp"
#include "world/world_impl.hpp"

#include <algorithm>

namespace cairn::detail {

BodyView WorldImpl::view(int index) const {
  const Body& b = bodies_[static_cast<size_t>(index)];
  // Every member written once (a default-constructed view would first be
  // filled with identities and zeros; the step makes a view per joint side
  // several times a step).
  return BodyView{.solver_index = index + 1,  // the step replaces it with the body's solver index
                  .x = b.position,
                  .q = b.orientation,
                  .rot = b.rotation,
                  .inv_mass = b.solverInvMass(),
                  .lin_factor = b.linear_factor,
                  .inv_inertia = b.solverInvInertia(),
                  .v = b.linear_velocity,
                  .w = b.angular_velocity};
}

BodyView WorldImpl::view(BodyId id) const { return id.isWorld() ? BodyView{} : view(id.index); }

JointId WorldImpl::createJoint(const JointDef& def) {
  JointDef d = def;
  if (d.name.empty()) d.name = "joint" + std::to_string(joints_.size());
  const std::string obj = "joint '" + d.name + "'";
  if (findJoint(d.name).index >= 0) throw InputError(obj, "name", "another joint has this name");
  for (const auto& [id, field] : {std::pair{d.body_a, "bodies[0]"}, std::pair{d.body_b, "bodies[1]"}})
    if (!id.isWorld() && !valid(id)) throw InputError(obj, field, "no such body");
  validateJointDef(d, bodySlots());
  Joint j = makeJoint(d, view(d.body_a), view(d.body_b));
  std::int32_t index;
  if (!free_joints_.empty()) {
    index = free_joints_.back();
    free_joints_.pop_back();
    j.generation = joints_[static_cast<size_t>(index)].generation;
    joints_[static_cast<size_t>(index)] = std::move(j);
  } else {
    index = static_cast<std::int32_t>(joints_.size());
    joints_.push_back(std::move(j));
  }
  if (!d.body_a.isWorld()) wakeBody(d.body_a);
  if (!d.body_b.isWorld()) wakeBody(d.body_b);
  return JointId{index, joints_[static_cast<size_t>(index)].generation};
}

void WorldImpl::destroyJoint(JointId id) {
  check(id);
  Joint& j = joints_[static_cast<size_t>(id.index)];
  if (!j.def.body_a.isWorld() && valid(j.def.body_a)) wakeBody(j.def.body_a);
  if (!j.def.body_b.isWorld() && valid(j.def.body_b)) wakeBody(j.def.body_b);
  const std::uint32_t generation = j.generation + 1;
  j = Joint{};
  j.alive = false;
  j.broken = true;
  j.generation = generation;
  free_joints_.push_back(id.index);
}

JointId WorldImpl::findJoint(const std::string& name) const {
  for (size_t i = 0; i < joints_.size(); ++i)
    if (joints_[i].alive && joints_[i].def.name == name) return jointId(static_cast<int>(i));
  return JointId{};
}

JointError WorldImpl::jointError(JointId id) const {
  const Joint& j = joint(id);
  if (!j.alive || j.broken) return {};
  return measureJointError(j, view(j.def.body_a), view(j.def.body_b));
}

void WorldImpl::removeJoint(JointId id) {
  Joint& j = joints_.at(static_cast<size_t>(id.index));
  j.broken = true;
  j.feedback = {};
  std::fill(j.warm.begin(), j.warm.end(), Real(0));
}

}  // namespace cairn::detail
