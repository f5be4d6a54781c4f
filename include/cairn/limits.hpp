/// @file
/// Limits on the size of input, each checked before anything is allocated
/// for what it counts, so that an oversized scene or mesh is refused with an
/// InputError that names the limit instead of exhausting memory
/// (std::bad_alloc) or running for hours. docs/reliability.md lists them and
/// why each default is what it is; `cairn run --limit NAME=VALUE` sets them
/// from the command line (inputLimitNames() below is that table).
///
/// They bound the cost of loading and of one step, not what a scene may
/// mean: raise one when a real scene needs more.
#pragma once

#include "cairn/error.hpp"

#include <charconv>
#include <cstdint>
#include <string>
#include <vector>

namespace cairn {

/// The limits on the size of input (see the file's description); defaults as documented in docs/reliability.md.
struct InputLimits {
  std::uint64_t bodies = 10000;            ///< bodies in a scene
  std::uint64_t shapes_per_body = 1000;    ///< shapes of one (compound) body
  std::uint64_t joints = 10000;            ///< joints in a scene
  std::uint64_t springs = 100000;          ///< springs in a scene
  std::uint64_t hull_points = 10000;       ///< input points of one convex hull
  std::uint64_t mesh_vertices = 3000000;   ///< `v` records of one OBJ file
  std::uint64_t mesh_triangles = 1000000;  ///< triangles of one OBJ file (after fanning)
  std::uint64_t json_depth = 64;           ///< nesting of arrays and objects in a scene file
  std::uint64_t file_bytes = 256u << 20;   ///< size of a scene or OBJ file (256 MiB)
  std::uint64_t iterations = 10000;        ///< solver.iterations (sweeps per (sub)step)
  std::uint64_t substeps = 1000;           ///< solver.substeps
};

// Ranges of values a step can carry in double precision, checked when a
// scene is loaded (world/def_checks.hpp). Every dimensional input in SI
// units (a coordinate, length, velocity, mass, density, force, stiffness,
// time step, gravity...) must have magnitude at most kMaxMagnitude, and
// every size, mass and density that is divided by or multiplied into an
// inertia must be at least kMinSize. The longest products of inputs in a
// step are the gyroscopic torque w x (I w) with I ~ rho L^5 (8 inputs) and
// the kinetic energy rho L^3 v^2 (6 inputs); with each input within
// 1e-20..1e20 even a product of 15 of them stays within 1e-300..1e300,
// inside double's normal range (2.2e-308..1.8e308), leaving headroom for the
// sums of the solver and the effective masses that combine several bodies.
// A squared norm of a position (1e40 at most) is nowhere near overflow
// (|x| > 1.3e154). Physically the range spans far below an atom to far
// beyond a galaxy, so no meaningful scene is refused.
inline constexpr double kMaxMagnitude = 1e20;  ///< largest magnitude of a dimensional input (SI units)
inline constexpr double kMinSize = 1e-20;      ///< smallest size, mass or density that meets an inertia (SI units)
// An inertia tensor is m L^2: its eigenvalues lie in kMinSize^3..kMaxMagnitude^3.
inline constexpr double kMaxInertia = 1e60;   ///< largest inertia eigenvalue (kg m^2)
inline constexpr double kMinInertia = 1e-60;  ///< smallest inertia eigenvalue (kg m^2)

/// One row of the table of limits: its name on the command line, what it
/// counts (for --help), and the member it sets.
struct InputLimitName {
  const char* name;    ///< the limit's name, e.g. "bodies" (--limit NAME=VALUE)
  const char* counts;  ///< what it counts, for --help
  std::uint64_t InputLimits::*member;  ///< the InputLimits member it sets
};

/// Every limit, in the order of the struct.
inline const std::vector<InputLimitName>& inputLimitNames() {
  static const std::vector<InputLimitName> kNames = {
      {"bodies", "bodies in a scene", &InputLimits::bodies},
      {"shapes_per_body", "shapes of one body", &InputLimits::shapes_per_body},
      {"joints", "joints in a scene", &InputLimits::joints},
      {"springs", "springs in a scene", &InputLimits::springs},
      {"hull_points", "points of one convex hull", &InputLimits::hull_points},
      {"mesh_vertices", "vertices of one OBJ file", &InputLimits::mesh_vertices},
      {"mesh_triangles", "triangles of one OBJ file", &InputLimits::mesh_triangles},
      {"json_depth", "nesting depth of a scene file", &InputLimits::json_depth},
      {"file_bytes", "bytes of a scene or OBJ file", &InputLimits::file_bytes},
      {"iterations", "solver iterations per (sub)step", &InputLimits::iterations},
      {"substeps", "solver substeps per step", &InputLimits::substeps},
  };
  return kNames;
}

/// "(limit NAME = N; raise it with --limit NAME=...)": the tail of every
/// message that refuses input for exceeding a limit.
inline std::string limitHint(const char* name, std::uint64_t value) {
  return std::string("(limit ") + name + " = " + std::to_string(value) + "; raise it with --limit " + name +
         "=N or InputLimits::" + name + ")";
}

/// Sets one limit from "NAME=VALUE" (VALUE a decimal integer >= 1). Throws
/// InputError naming `option` when the name is unknown or the value is not
/// such an integer.
inline void setInputLimit(InputLimits& limits, const std::string& assignment, const std::string& option = "--limit") {
  const size_t eq = assignment.find('=');
  const std::string name = assignment.substr(0, eq);
  for (const InputLimitName& n : inputLimitNames()) {
    if (name != n.name) continue;
    const std::string text = eq == std::string::npos ? std::string() : assignment.substr(eq + 1);
    std::uint64_t v = 0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
    if (text.empty() || ec != std::errc() || end != text.data() + text.size() || v < 1)
      throw InputError(option, "", "'" + assignment + "': the value must be an integer in [1, 2^64 - 1]");
    limits.*n.member = v;
    return;
  }
  std::string known;
  for (const InputLimitName& n : inputLimitNames()) known += (known.empty() ? "" : ", ") + std::string(n.name);
  throw InputError(option, "", "'" + assignment + "': unknown limit (known: " + known + ")");
}

}  // namespace cairn
