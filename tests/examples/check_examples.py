#!/usr/bin/env python3
"""Runs one example program (examples/) and checks the figures it prints
against physics: closed forms, conservation laws and invariants. Each
check's tolerance says where its size comes from.

    check_examples.py NAME PATH_TO_EXAMPLE

Exit 0 when every check holds, 1 (naming the check and the figures) when
one fails."""
import math
import subprocess
import sys

failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        failures.append(what)


def near(value, expected, tol, what):
    check(abs(value - expected) <= tol,
          f"{what}: {value:.9g} against {expected:.9g} (tolerance {tol:.3g}, off by {abs(value - expected):.3g})")


def scalars(lines):
    """'key value' lines as floats."""
    out = {}
    for line in lines:
        parts = line.split()
        if len(parts) == 2:
            try:
                out[parts[0]] = float(parts[1])
            except ValueError:
                pass
    return out


def fields(line):
    """'tag k1 v1 k2 v2 ...' as a dict of floats (vector values kept as lists)."""
    parts = line.split()[1:]
    out, key = {}, None
    for p in parts:
        try:
            v = float(p)
            if key is None:
                continue
            out.setdefault(key, []).append(v)
        except ValueError:
            key = p
    return {k: (v[0] if len(v) == 1 else v) for k, v in out.items()}


def tagged(lines, tag):
    return [fields(l) for l in lines if l.split() and l.split()[0] == tag]


def hello_world(lines):
    s = scalars(lines)
    h, g, y0 = s["step"], s["gravity"], s["start"]
    samples = []
    for l in lines:
        p = l.split()
        if p and p[0] == "t":
            samples.append((int(p[1]), float(p[3])))
    check(len(samples) == 6, "six heights printed, t = 0 .. 5 s")
    landing = math.sqrt(2 * (y0 - 0.5) / g)  # the box's bottom reaches y = 0
    for t, y in samples:
        if t < landing:
            # Free fall: the closed form y0 - g t^2 / 2. The engine's
            # semi-implicit Euler is exactly y0 - g h^2 n (n + 1) / 2, which
            # lies below it by g h t / 2 (its first-order lag); round-off
            # is far below 1e-9 m.
            n = round(t / h)
            near(y, y0 - g * h * h * n * (n + 1) / 2, 1e-9, f"t = {t} s: height against the discrete free fall")
            near(y, y0 - g * t * t / 2, g * h * t / 2 + 1e-9, f"t = {t} s: height against y0 - g t^2 / 2")
        elif t > landing + 1:
            # At rest on the ground: the push-out removes only penetration
            # beyond the 5 mm slop, so the box settles that deep; it may fall
            # asleep once the push-out has under 1% of the slop (5e-5 m) to
            # go (the sleep rule, docs/extremes.md), and stays there.
            near(y, 0.5 - 0.005, 0.01 * 0.005, f"t = {t} s: resting height 0.5 m less the 5 mm slop")


def game_loop(lines):
    s = scalars(lines)
    h, mu, g, v, x0 = s["step"], s["friction"], s["gravity"], s["platform_speed"], s["platform_x0"]
    # The accumulator: every whole step of the frames' total is run (the
    # cap of 8 steps is never reached by frames of at most 50 ms), the
    # remainder of less than a step waits.
    expected_steps = math.floor(s["total_frame_time"] / h + 1e-9)
    check(int(s["steps"]) == expected_steps, f"steps {int(s['steps'])} = floor(total / h) = {expected_steps}")
    check(s["dropped"] == 0, "no time dropped by the cap")
    near(s["world_time"], s["steps"] * h, 1e-9, "world time = steps h")
    for row in tagged(lines, "frame"):
        # Kinematic motion is exact and the interpolation linear in time:
        # only round-off (1e-9 m over a few hundred steps) separates them.
        near(row["platform_x"], x0 + v * row["render_time"], 1e-9,
             f"render time {row['render_time']:.4f} s: drawn platform at x0 + v t")
        # The crate stays on the platform: its centre 0.5 m above the top
        # face (y = 1.25), within the 5 mm slop.
        near(row["crate_y"], 1.75, 0.005, f"render time {row['render_time']:.4f} s: crate on the platform")
    # Friction accelerates the crate at mu g until it moves at v; meanwhile
    # the platform moves v T, T = v / (mu g): the crate slips back by
    # v^2 / (2 mu g). The step resolves the moment it catches up to within
    # one step, in which the relative speed is at most v: tolerance v h.
    near(s["slip"], -v * v / (2 * mu * g), v * h, "crate's slip on the platform = -v^2 / (2 mu g)")
    # Once caught up it rides at the platform's speed (static friction;
    # 1e-6 m/s: the solver's residual at 10 iterations on one contact).
    near(s["crate_speed"], v, 1e-6, "crate rides at the platform's speed")


def pd_character(lines):
    s = scalars(lines)
    m, kp, kd, w, xt, h, x0 = s["mass"], s["kp"], s["kd"], s["omega"], s["target"], s["step"], s["x0"]
    # The exact recurrence of the force applied over each step in the
    # engine's semi-implicit Euler (frictionless ground: nothing else acts
    # along x), compared at the printed steps; round-off only, 1e-9.
    printed = {}
    for l in lines:
        p = l.split()
        if p and p[0] == "n":
            printed[int(p[1])] = (float(p[3]), float(p[5]), float(p[7]))
    check(len(printed) == 16, "16 samples printed")
    x, v = x0, 0.0
    for n in range(1, max(printed) + 1):
        f = kp * (xt - x) - kd * v
        v += h * f / m
        x += h * v
        if n in printed:
            px, pv, py = printed[n]
            t = n * h
            near(px, x, 1e-9, f"step {n}: x against the PD recurrence")
            near(pv, v, 1e-9, f"step {n}: v against the PD recurrence")
            # The critically damped closed form. Semi-implicit Euler's
            # global error is first order: at most w h (5%) of the distance
            # to go, |x_t - x0| w h = 0.2 m.
            exact = xt - (xt - x0) * (1 + w * t) * math.exp(-w * t)
            near(px, exact, abs(xt - x0) * w * h, f"t = {t:.2f} s: x against the critically damped closed form")
            # Standing on the ground, upright: centre at r + half height.
            near(py, 0.9, 0.005, f"step {n}: the character stands on the ground")
    # Critical damping does not overshoot; the discrete controller by at
    # most round-off here.
    check(max(x for x, _, _ in printed.values()) <= xt + 1e-9, "the character never passes the target")
    near(printed[max(printed)][0], xt, 1e-3, "the character arrives at the target (4 s = 12 / w)")


def door(lines):
    s = scalars(lines)
    m, width, d, tau, target, g = s["mass"], s["width"], s["thickness"], s["motor_torque"], s["motor_target"], s["gravity"]
    breaking = s["break_force"]
    spin = [l.split() for l in lines if l.startswith("spinup_time")][0]
    t, spin_speed = float(spin[1]), float(spin[3])
    inertia = m * (width ** 2 + d ** 2) / 12 + m * (width / 2) ** 2
    # The saturated motor gives tau t / I (its row's impulse is capped at
    # tau h every step). The hinge's anchor rows supply the tangential force
    # m alpha r and share the door with the motor row; 10 PGS sweeps leave
    # that coupling unconverged by ~1e-5 relative: tolerance 1e-4 relative.
    near(spin_speed, tau * t / inertia, 1e-4 * tau * t / inertia, "spin-up: w = tau t / I_hinge")
    # At speed the motor row meets the centripetal anchor rows the same way:
    # 5e-4 measured at 10 sweeps, 1e-3 relative allowed.
    near(s["cruise_speed"], target, 1e-3 * target, "the motor holds its target speed")
    rest = [l.split() for l in lines if l.startswith("rest_angle")][0]
    # The limit stops the door at 90 degrees (within the limit's softness:
    # ERP closes a residual of order tau h^2 / I per step, under 1e-3 rad).
    near(float(rest[1]), math.pi / 2, 1e-3, "the door rests against its 90 degree limit")
    # Standing still, the hinge holds the weight and nothing else (motor
    # and limit are torques): m g, to 1e-3 relative (the solver residual).
    near(float(rest[3]), m * g, 1e-3 * m * g, "at rest the hinge carries the door's weight m g")
    check(float(rest[3]) < breaking, "the hinge holds the door's weight without breaking")
    breaks = [fields(l) for l in lines if l.startswith("break ")]
    check(len(breaks) == 1, "the hinge breaks once, under the hit")
    if breaks:
        check(breaks[0]["force"] > breaking, f"the breaking force {breaks[0]['force']:.1f} N exceeds {breaking} N")
    check(s.get("broken") == 1, "World::isBroken reports the hinge broken")
    dp = [float(x) for x in [l for l in lines if l.startswith("free_dp")][0].split()[1:]]
    M, dt = s["free_mass"], s["free_dt"]
    # Door and ball free: only gravity changes their total momentum,
    # M g dt; round-off at 1e-9 of it.
    near(dp[0], 0, 1e-9 * M * g * dt, "after the break: horizontal momentum conserved (x)")
    near(dp[1], -M * g * dt, 1e-9 * M * g * dt, "after the break: vertical momentum changes by -M g dt")
    near(dp[2], 0, 1e-9 * M * g * dt, "after the break: horizontal momentum conserved (z)")


def ragdoll(lines):
    s = scalars(lines)
    M, h, g = s["mass"], s["step"], s["gravity"]
    c0 = [float(x) for x in [l for l in lines if l.startswith("com0")][0].split()[1:]]
    p0 = [float(x) for x in [l for l in lines if l.startswith("momentum0")][0].split()[1:]]
    v0 = [p / M for p in p0]
    flights = tagged(lines, "flight")
    check(len(flights) >= 4, f"{len(flights)} samples in flight before the first contact")
    for row in flights:
        n = int(row["n"])
        # Joint impulses are equal and opposite: only gravity changes the
        # total momentum (round-off: 1e-9 of M g t).
        near(row["momentum"][1], p0[1] - M * g * n * h, 1e-9 * M * g * n * h + 1e-12, f"step {n}: momentum y = p0 - M g t")
        near(row["momentum"][0], p0[0], 1e-9 * M * g * n * h + 1e-12, f"step {n}: momentum x conserved")
        # The centre of mass follows the discrete free fall exactly.
        y = c0[1] + n * h * v0[1] - g * h * h * n * (n + 1) / 2
        near(row["com"][1], y, 1e-9, f"step {n}: centre of mass on the discrete free fall")
        near(row["com"][0], c0[0] + n * h * v0[0], 1e-9, f"step {n}: centre of mass moves at p0 / M along x")
    # At rest: the ground carries M g (PGS at 10 iterations leaves a
    # residual; 2% of the weight covers it, and a ragdoll hanging on a
    # joint or sinking would be far off), the joints hold to 1 cm, and no
    # part sinks deeper than the 5 mm slop plus the solver's residual, 1 cm.
    near(s["rest_support"], M * g, 0.02 * M * g, "at rest the ground carries the whole weight M g")
    # Come to rest: the rms speed sqrt(2 KE / M) below the engine's own
    # sleep threshold, 0.05 m/s (sleeping is off here so contacts stay solved).
    rms = math.sqrt(2 * s["rest_kinetic"] / M)
    check(rms < 0.05, f"at rest: rms speed {rms:.3g} m/s < 0.05 m/s")
    check(s["rest_joint_error"] < 0.01, f"at rest: joint anchors within 1 cm ({s['rest_joint_error']:.3g} m)")
    check(s["rest_depth"] < 0.01, f"at rest: penetration under 1 cm ({s['rest_depth']:.3g} m)")


def car(lines):
    s = scalars(lines)
    R, w, M, h, g = s["radius"], s["wheel_speed"], s["mass"], s["step"], s["gravity"]
    flat = tagged(lines, "flat")
    check(len(flat) == 1, "a sample on the flat before the ramp")
    if flat:
        # Rolling without slipping: v = w R. The wheels' contact friction
        # is solved to the PGS residual: 1% of the speed.
        near(flat[0]["speed"], w * R, 0.01 * w * R, "on the flat the car rolls at w R")
        near(abs(flat[0]["wheel_spin"]), w, 0.01 * w, "the motors turn the wheels at their target speed")
    # Over the ramp the chassis rises by the ramp's height: when the front
    # wheels reach the top edge the chassis centre, half a wheelbase (0.8 m)
    # back down the slope, sits 0.8 sin(a) below ride + ramp height; the
    # launch off the edge lifts it at most (v sin a)^2 / (2 g) more. 1 cm
    # for contact softness either side.
    top = s["ride_height"] + s["ramp_height"]
    sin_a = s["ramp_height"] / (s["ramp_end"] - s["ramp_start"]) / math.sqrt(1 + (s["ramp_height"] / (s["ramp_end"] - s["ramp_start"])) ** 2)
    lo, hi = top - 0.8 * sin_a - 0.01, top + (w * R * sin_a) ** 2 / (2 * g) + 0.01
    check(lo <= s["max_chassis_y"] <= hi, f"the chassis climbs the ramp: top height {s['max_chassis_y']:.4f} m in [{lo:.4f}, {hi:.4f}]")
    flight = [fields(l) for l in lines if l.startswith("flight")][0]
    check(flight["steps"] >= 10, f"the car flies off the ramp ({int(flight['steps'])} steps in the air)")
    dt = flight["steps"] * h
    dp = flight["dp"]
    near(dp[1], -M * g * dt, 1e-9 * M * g * dt, "in flight the momentum changes by -M g dt")
    near(dp[0], 0, 1e-9 * M * g * dt, "in flight the horizontal momentum is conserved")
    final = [fields(l) for l in lines if l.startswith("final")][0]
    check(final["x"] > s["ramp_end"] + 2, f"the car drove on past the ramp (x = {final['x']:.2f} m)")
    check(final["up_y"] > 0.95, "the car landed upright")
    check(final["axle_error"] < 0.01, f"the wheels stay on their axles ({final['axle_error']:.3g} m)")


def main():
    name, exe = sys.argv[1], sys.argv[2]
    out = subprocess.run([exe], capture_output=True, text=True, timeout=300)
    print(out.stdout)
    if out.returncode != 0:
        print(out.stderr)
        print(f"FAIL {name} exited with {out.returncode}")
        return 1
    globals()[name](out.stdout.splitlines())
    if failures:
        print(f"{len(failures)} check(s) failed")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
