#include "validation/standard_scenes.hpp"

#include "cairn/error.hpp"
#include "validation/compare.hpp"
#include "validation/scenarios.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>

namespace cairn::validation {

using Json = nlohmann::ordered_json;

namespace {

Json vec(const Vec3& v) { return Json::array({v.x(), v.y(), v.z()}); }

std::string fixed(double v, int digits) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

Json trace(const std::string& body, const std::string& quantity) { return Json{{"body", body}, {"quantity", quantity}}; }

// The block's tolerances: the scenario type's defaults (compare.cpp),
// overridden by `over`, written out in full so the file shows them.
Json tolerances(const std::string& scenario, ValidationKind kind, const Json& over = Json::object()) {
  Json t = Json::object();
  for (const auto& [k, v] : defaultTolerances(scenario, kind)) t[k] = v;
  for (auto it = over.begin(); it != over.end(); ++it) t[it.key()] = it.value();
  return t;
}

Json block(const std::string& scenario, ValidationKind kind, Json traces, Json analytic = Json::array(),
           const Json& over = Json::object()) {
  Json v;
  v["kind"] = kindName(kind);
  v["scenario"] = scenario;
  v["tolerances"] = tolerances(scenario, kind, over);
  v["traces"] = std::move(traces);
  if (!analytic.empty()) v["analytic"] = std::move(analytic);
  return v;
}

int suffixInt(const std::string& key, const std::string& prefix) { return std::stoi(key.substr(prefix.size())); }

bool startsWith(const std::string& s, const std::string& prefix) { return s.rfind(prefix, 0) == 0; }

}  // namespace

double hingePendulumPeriod(double amplitude, double g) {
  const double k = std::sin(amplitude / 2);
  double a = 1, b = std::sqrt(1 - k * k);
  for (int i = 0; i < 40 && std::abs(a - b) > 1e-16 * a; ++i) {
    const double an = (a + b) / 2;
    b = std::sqrt(a * b);
    a = an;
  }
  const double K = kPi / (2 * a);
  const double inertia = 7.0 / 6.0, mass = 1, d = 1;
  return 4 * std::sqrt(inertia / (mass * g * d)) * K;
}

std::vector<std::string> standardSceneNames() { return scenarios::standardNames(); }

StandardScene standardScene(const std::string& key) {
  StandardScene out;
  out.scene = scenarios::byName(key);  // throws InputError for an unknown key
  SceneDesc& s = out.scene;
  s.solver.sleeping = false;  // docs/scenarios.md: no sleeping
  const std::string steps = std::to_string(s.steps) + " steps of 1/60 s (" + fixed(s.steps / 60.0, 0) + " s)";
  const std::string common = "Units SI (m, kg, s, rad), y up, g = 9.81 m/s^2 down, friction 0.5, no sleeping; ";
  Json v;
  const auto top = [&] {
    int best = -1;
    for (size_t i = 0; i < s.bodies.size(); ++i)
      if (s.bodies[i].type == BodyType::Dynamic && (best < 0 || s.bodies[i].position.y() > s.bodies[size_t(best)].position.y()))
        best = static_cast<int>(i);
    return s.bodies.at(static_cast<size_t>(best)).name;
  };

  if (startsWith(key, "pyramid-")) {
    const int n = suffixInt(key, "pyramid-");
    out.description = common + steps + ". A 2D pyramid of " + std::to_string(n * (n + 1) / 2) +
                      " 1 m boxes of 1 kg on the ground, bottom row of " + std::to_string(n) +
                      " with 1 cm gaps. It should stand still for the whole run: the top box stays at y = " +
                      fixed(n - 0.5, 1) + " m, no box moves more than a few mm, and nothing collapses.";
    v = block("pyramid", ValidationKind::Statistics, Json::array({trace(top(), "height"), trace(top(), "x")}), {},
              Json{{"top_height", n * s.solver.slop}});
    v["top_body"] = top();
  } else if (startsWith(key, "column-")) {
    const int n = suffixInt(key, "column-");
    out.description = common + steps + ". A column of " + std::to_string(n) +
                      " 1 m boxes of 1 kg stacked on the ground. It should stand still: the top box stays at y = " +
                      fixed(n - 0.5, 1) + " m, upright and centred.";
    v = block("column", ValidationKind::Statistics, Json::array({trace(top(), "height"), trace(top(), "x")}), {},
              Json{{"top_height", n * s.solver.slop}});
    v["top_body"] = top();
  } else if (startsWith(key, "hanging-chain-")) {
    const int n = suffixInt(key, "hanging-chain-");
    out.description = common + steps + ". " + std::to_string(n) +
                      " rods of 0.1 x 0.5 x 0.1 m (1 kg) hanging from the world on ball joints, the lowest nudged "
                      "sideways at 0.5 m/s. The chain sways gently and stays " + fixed(0.5 * n, 1) + " m long.";
    const std::string tip = "link_" + std::to_string(n - 1);
    v = block("hanging-chain", ValidationKind::Trajectory, Json::array({trace(tip, "x"), trace(tip, "height")}));
  } else if (startsWith(key, "chain-")) {
    const int n = suffixInt(key, "chain-");
    out.description = common + steps + ". " + std::to_string(n) +
                      " spheres (radius 0.1 m, 1 kg) 1 m apart on ball joints, hung from the origin and released "
                      "horizontally along +x. The chain falls and whips under the pivot; the joints should stay "
                      "together (anchor separation near zero) and the tip swings through x = 0 below the pivot.";
    const std::string tip = "link_" + std::to_string(n - 1);
    v = block("chain", ValidationKind::Trajectory, Json::array({trace(tip, "height"), trace(tip, "x")}));
  } else if (startsWith(key, "hinge-pendulum-")) {
    const double a0 = std::stod(key.substr(std::string("hinge-pendulum-").size()));
    const double period = hingePendulumPeriod(a0);
    out.description = common + steps + ". A 1 m cube of 1 kg on a hinge about the world z axis at the origin, its "
                      "centre 1 m below the hinge, released from " + fixed(a0, 1) +
                      " rad. It swings with the exact period " + fixed(period, 6) +
                      " s (elliptic integral, I_pivot = 7/6 kg m^2) and keeps its amplitude; the pivot does not drift.";
    Json analytic = Json::array({Json{{"type", "pendulum_period"}, {"body", "bob"}, {"pivot", vec(Vec3::Zero())},
                                      {"value", period}, {"angle", a0}}});
    // Baumgarte's steady pivot error: each step the bob moves h v along the
    // tangent, h^2 v^2 / (2 d) off the circle, and ERP of that is corrected
    // per step, so the error settles at h^2 v^2 / (2 d ERP), largest at the
    // bottom, where v^2 = 2 m g d (1 - cos a0) d^2 / I. Allow 1.5 times it.
    const double v2 = 2 * 9.81 * (1 - std::cos(a0)) * 6 / 7;
    const double pivot = s.dt * s.dt * v2 / (2 * s.solver.erp);
    Json over{{"joint_error", 1.5 * pivot}};
    if (a0 > 1) {
      // Velocity-level joints lose energy at O(h^2) at this amplitude (1.11,
      // 0.26, 0.072 J over 10 s at h, h/2, h/4), the same in Bullet to 0.1%;
      // the period then follows the smaller amplitude. Bars: the 10 s
      // figures with a third to a half again as margin (docs/validation.md).
      over["period"] = 0.015;
      over["amplitude"] = 0.1;
      over["energy"] = 1.5;
    }
    v = block("hinge-pendulum", ValidationKind::Trajectory, Json::array({trace("bob", "swing_angle")}), analytic, over);
  } else if (startsWith(key, "mass-ratio-")) {
    const double r = std::stod(key.substr(std::string("mass-ratio-").size()));
    out.description = common + steps + ". A 1 kg box on the ground with a box of " + fixed(r, 0) +
                      " kg resting on it. The pair should stay put: the heavy box's centre stays at y = 1.5 m "
                      "with the light box barely squeezed.";
    v = block("mass-ratio", ValidationKind::Statistics, Json::array({trace("heavy", "height"), trace("light", "height")}));
    v["top_body"] = "heavy";
  } else if (startsWith(key, "pile-")) {
    const std::string side = std::to_string(static_cast<int>(std::lround(std::cbrt(suffixInt(key, "pile-")))));
    out.description = common + steps + ". A " + side + " x " + side + " x " + side +
                      " grid of 1 m boxes (1 kg), 1.2 m apart, lowest layer at y = 1 m, dropped on the ground. The "
                      "boxes fall, tumble and settle into a heap" + (side == "10" ? " about 5 m high" : "") +
                      "; what is compared is cost per step and the heap's statistics, not box-by-box positions.";
    v = block("pile", ValidationKind::Statistics, Json::array({trace(top(), "height")}));
    v["top_body"] = top();
  } else if (key == "hinge-chain") {
    out.description = common + steps + ". Five planks of 0.2 x 1 x 0.2 m (1 kg) hung end to end on hinges about z "
                      "from the origin, released straight at 0.3 rad. The chain swings in the x-y plane in a mix of "
                      "its normal modes, the tip rippling; the hinges stay together and nothing leaves the plane.";
    v = block("hinge-chain", ValidationKind::Trajectory,
              Json::array({trace("plank_0", "swing_angle"), trace("plank_4", "x")}));
  } else if (key == "door") {
    const double inertia = 10 * (1 + 0.05 * 0.05) / 12 + 10 * 0.25;
    // Accelerating at 5/I to 1 rad/s takes t1 = I/5 and turns t1/2 rad,
    // less than the 99% of pi/2 at which the opening is timed.
    const double open = kPi / 2 / 1.0 + 1.0 * inertia / 5 / 2;
    const double open99 = 0.99 * kPi / 2 / 1.0 + 1.0 * inertia / 5 / 2;
    out.description = common + steps + ". A 1 x 2 x 0.05 m door of 10 kg on a vertical hinge along its edge "
                      "(x = 0), limits [0, pi/2] rad, motor toward +1 rad/s with at most 5 N m. It accelerates at "
                      "5/I = " + fixed(5 / inertia, 3) + " rad/s^2 (I = " + fixed(inertia, 4) +
                      " kg m^2 about the hinge), swings open at 1 rad/s and stops on the pi/2 limit after " +
                      fixed(open, 3) + " s (99% of the way after " + fixed(open99, 3) + " s), where the motor holds it.";
    Json analytic = Json::array({Json{{"type", "open_time"}, {"body", "door"}, {"axis", vec(Vec3::UnitY())},
                                      {"angle", kPi / 2}, {"value", open99}}});
    Json t = trace("door", "angle");
    t["axis"] = vec(Vec3::UnitY());
    v = block("door", ValidationKind::Trajectory, Json::array({t}), analytic);
  } else if (key == "ragdoll" || key == "ragdoll-6dof") {
    const std::string joints =
        key == "ragdoll" ? "cone-twist neck, shoulders and hips, hinge spine, elbows and knees, all limited"
                         : "six_dof joints with their translations locked and each rotation limited or locked as the "
                           "body part allows; shoulders and hips swing up to 1.5 rad (86 degrees), the neck has a "
                           "2 Hz spring";
    out.description = common + steps + ". An 11-part ragdoll (about 1.8 m, 56 kg; box pelvis and chest, capsule "
                      "head and limbs; " + joints + "; each joint lists the child first) laid face down 1 m above "
                      "the ground and dropped. It lands, its limbs flop within their limits and it comes to rest "
                      "lying on the ground with every joint together.";
    v = block("ragdoll", ValidationKind::Statistics, Json::array({trace("pelvis", "height"), trace("head", "height")}));
    v["top_body"] = "pelvis";
  } else if (key == "motor-limits") {
    const double inertia = 2 * (1 + 0.01) / 12 + 2 * 0.25;
    // Accelerating at 2/I to 1.5 rad/s takes t1 = 1.5 I / 2 and turns
    // 1.5 t1 / 2 rad, less than the 99% of 1.1 rad at which it is timed.
    const double open99 = 0.99 * 1.1 / 1.5 + 1.5 * inertia / 2 / 2;
    out.description = common + steps + ". Two motors driving into asymmetric limits, each body listed first so "
                      "that targets and limits are its own motion. An arm (1 x 0.1 x 0.1 m, 2 kg) on a vertical hinge "
                      "at its end, limits [-0.4, 1.1] rad, motor +1.5 rad/s with at most 2 N m: it accelerates at 2/I = " +
                      fixed(2 / inertia, 3) + " rad/s^2 (I = " + fixed(inertia, 4) +
                      " kg m^2), turns at 1.5 rad/s and stops on +1.1 rad (99% of the way after " + fixed(open99, 3) +
                      " s). A cart (0.4 m cube, 1 kg) on a rail along x, limits [-0.3, 0.6] m, motor -0.4 m/s with "
                      "at most 1 N: it accelerates at 1 m/s^2, slides at 0.4 m/s and stops on -0.3 m after 0.95 s.";
    Json analytic = Json::array({Json{{"type", "open_time"}, {"body", "arm"}, {"axis", vec(Vec3::UnitY())},
                                      {"angle", 1.1}, {"value", open99}}});
    Json arm = trace("arm", "angle");
    arm["axis"] = vec(Vec3::UnitY());
    v = block("motor-limits", ValidationKind::Trajectory, Json::array({arm, trace("cart", "x")}), analytic);
  } else if (key == "six-dof") {
    out.description = common + steps + ". A 0.4 m cube of 2 kg held at its center by a six_dof joint to the world "
                      "(cube listed first, frame = world axes), one axis of each kind: translation x free (it starts "
                      "at 0.3 m/s), y limited to [-0.25, 0.1] m (it falls onto -0.25), z locked; rotation x a "
                      "velocity motor (1 rad/s, at most 0.5 N m), y a spring (0.2 N m/rad, 0.02 N m s/rad; it starts "
                      "turning at 0.3 rad/s), z limited to [-0.15, 0.3] rad (it starts turning at 0.5 rad/s and "
                      "stops on 0.3).";
    Json spin = trace("cube", "angle");
    spin["axis"] = vec(Vec3::UnitX());
    v = block("six-dof", ValidationKind::Trajectory, Json::array({trace("cube", "height"), trace("cube", "x"), spin}));
  } else if (key == "ramp") {
    const double g = 9.81, a35 = g * (std::sin(35 * kPi / 180) - 0.5 * std::cos(35 * kPi / 180));
    out.description = common + steps + ". Two 1 m boxes of 1 kg resting on static ramps, friction 0.5 "
                      "(combined 0.5). On the 20 degree ramp (z = -3 m; tan 20 = 0.36 < 0.5) the box sticks. On "
                      "the 35 degree ramp (z = +3 m) it slides down with a = g (sin 35 - 0.5 cos 35) = " +
                      fixed(a35, 3) + " m/s^2, about " + fixed(0.5 * a35 * 9, 1) + " m in 3 s.";
    const Vec3 d20 = Quat(Eigen::AngleAxis<Real>(-20 * kPi / 180, Vec3::UnitZ())) * Vec3::UnitX();
    const Vec3 d35 = Quat(Eigen::AngleAxis<Real>(-35 * kPi / 180, Vec3::UnitZ())) * Vec3::UnitX();
    Json t20 = trace("box_20", "slope"), t35 = trace("box_35", "slope");
    t20["axis"] = vec(d20);
    t35["axis"] = vec(d35);
    Json analytic = Json::array({Json{{"type", "stick"}, {"body", "box_20"}},
                                 Json{{"type", "slide"}, {"body", "box_35"}, {"axis", vec(d35)}, {"value", a35}}});
    v = block("ramp", ValidationKind::Trajectory, Json::array({t20, t35}), analytic);
  } else if (key == "restitution-drop") {
    out.description = common + steps + ". A sphere of radius 0.25 m and 1 kg with restitution 0.8, its bottom 2 m "
                      "above the ground (restitution 0; cairn takes the larger), dropped. Each bounce rises to "
                      "e^2 = 0.64 of the previous height: 1.28 m after the first.";
    Json analytic = Json::array({Json{{"type", "apex_ratio"}, {"body", "ball"}, {"rest_height", 0.25}, {"value", 0.64}}});
    v = block("restitution-drop", ValidationKind::Trajectory, Json::array({trace("ball", "height")}), analytic);
  } else {
    throw InputError("scenario '" + key + "'", "", "no description for this scenario");
  }
  s.validation_json = v.dump();
  return out;
}

}  // namespace cairn::validation
