// cairn and Bullet in one replay (the pages of `cairn validate --report`
// and `cairn sweep`): Bullet's motion, as the validation recorded it, beside
// cairn's, and the first instant the two part by more than the scene's
// tolerance (docs/viewer.md, "Side by side").
#pragma once

#include "validation/compare.hpp"
#include "validation/replay.hpp"

namespace cairn::validation {

// The distance (m) at which the engines count as parted: the scene's
// "position" tolerance where it has one (trajectory scenes), else the
// default trajectory tolerance (statistics scenes part by design; the mark
// shows when).
double partingTolerance(const ValidationSpec& spec);

// Sets replay.bullet from Bullet's run and replay.parting from the two
// tracks.
void addBulletRun(Replay& replay, const EngineRun& bullet, const ValidationSpec& spec);

}  // namespace cairn::validation
