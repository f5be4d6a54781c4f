// Checks that a definition is within the input limits (counts) and the
// ranges a step can carry in double precision (include/cairn/limits.hpp
// explains the ranges), before anything is built from it. The World checks
// signs, finiteness and cross-references on creation; these checks add
// the magnitudes, so that a scene whose energy, inertia or squared norm
// would overflow or underflow is refused at load with the range, not run
// into infinities.
//
// parseScene() calls checkScene(); World::create* may call the per-object
// checks so that definitions built in code get the same treatment.
#pragma once

#include "cairn/limits.hpp"
#include "cairn/scene.hpp"

#include <string>

namespace cairn {

// Each throws InputError(object, field, "... (got X)") naming the range.
void checkBodyDef(const BodyDef& def, const std::string& object, const InputLimits& limits = {});
void checkSpringDef(const SpringDef& def, const std::string& object);
void checkJointDef(const JointDef& def, const std::string& object);
void checkSolverSettings(const SolverSettings& s, const InputLimits& limits = {});

// Counts of bodies, springs and joints against `limits`, gravity, dt, and
// every body, spring, joint and the solver settings as above.
void checkScene(const SceneDesc& scene, const InputLimits& limits = {});

}  // namespace cairn
