// A replay's motion from the trajectory CSV that `cairn run --out` writes
// (cli/run_command.cpp): a header
//   step,time,body,px,py,pz,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz
// then, for every recorded step, one row per non-static body in scene
// order (fields may be RFC 4180-quoted). Static bodies keep the pose they
// have in the scene.
#pragma once

#include "validation/replay.hpp"

#include <string>

namespace cairn::validation {

// Fills `replay.cairn` (replay.bodies already describe the scene:
// describeWorld) from the CSV file's text. Throws InputError naming `path`
// and what does not match: the columns, a body the scene does not have or
// lacks, a number, the step order, or a run with no frames. On a throw
// `replay` is unchanged.
void readRunCsv(const std::string& text, const std::string& path, Replay& replay);

}  // namespace cairn::validation
