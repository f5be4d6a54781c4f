/// @file
/// cairn's one include: the whole public API.
///
///     #include <cairn/cairn.hpp>
///
/// The smaller headers beside it may be included on their own:
/// - cairn/math.hpp        Real (double), Vec3, Quat, Mat3, Transform (Eigen)
/// - cairn/error.hpp       InputError, HandleError: bad input, named
/// - cairn/handles.hpp     BodyId, JointId, SpringId, ShapeId
/// - cairn/shape.hpp       ShapeDesc: spheres, boxes, capsules, cylinders,
///                         planes, convex hulls, triangle meshes
/// - cairn/defs.hpp        BodyDef, JointDef, SpringDef and their parts
/// - cairn/settings.hpp    SolverSettings
/// - cairn/events.hpp      contact and joint-break events, joint feedback
/// - cairn/query.hpp       ray and shape casts, overlap queries
/// - cairn/stats.hpp       what a step reports about itself
/// - cairn/scene.hpp       SceneDesc: a scene in memory, built into a World
/// - cairn/world.hpp       World: creates, steps, reports
/// - cairn/fixed_step.hpp  FixedStepDriver: the game loop's accumulator
///
/// docs/user-guide.md explains the game loop, units, frames, handles,
/// callbacks and threading; docs/architecture.md walks through a step.
#pragma once

#include "cairn/defs.hpp"
#include "cairn/error.hpp"
#include "cairn/events.hpp"
#include "cairn/fixed_step.hpp"
#include "cairn/handles.hpp"
#include "cairn/math.hpp"
#include "cairn/query.hpp"
#include "cairn/scene.hpp"
#include "cairn/settings.hpp"
#include "cairn/shape.hpp"
#include "cairn/stats.hpp"
#include "cairn/world.hpp"
