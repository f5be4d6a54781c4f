// The standard scenarios as shipped in scenes/: the generators of
// validation/scenarios.hpp plus what a file adds, a description (units and
// what a user should see) and a "validation" block (kind, tolerances,
// traces to plot, closed-form references). `cairn scenes` writes these;
// `cairn validate KEY` runs them without a file.
//
// Every standard scene runs with sleeping off, as docs/scenarios.md
// asks (cairn's default is on).
#pragma once

#include "cairn/scene.hpp"

#include <string>
#include <vector>

namespace cairn::validation {

struct StandardScene {
  SceneDesc scene;  // validation_json filled
  std::string description;
};

// The scenario `key` (scenarios::byName keys); throws InputError for an
// unknown key.
StandardScene standardScene(const std::string& key);

// The keys written by `cairn scenes` (scenarios::standardNames()).
std::vector<std::string> standardSceneNames();

// Exact period of the standard hinge pendulum (1 m cube of 1 kg, center
// 1 m below the hinge, I_pivot = 7/6 kg m^2) released from `amplitude`:
// T = 4 sqrt(I / (m g d)) K(sin(amplitude / 2)), K by the arithmetic-
// geometric mean. 2.168155 s at 0.1 rad, 2.517753 s at 1.5 rad.
double hingePendulumPeriod(double amplitude, double g = 9.81);

}  // namespace cairn::validation
