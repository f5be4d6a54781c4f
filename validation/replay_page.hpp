// A replay as one self-contained HTML page (docs/viewer.md): the page
// template, style and scripts of viewer/ and three.js (Debian's
// libjs-three), embedded in the binary at build time, around the replay's
// data as JSON with its arrays as base64 typed-array blocks. The page needs
// nothing else: it opens offline from a file:// URL.
#pragma once

#include "validation/replay.hpp"

#include <string>

namespace cairn::validation {

std::string replayPageHtml(const Replay& replay);

// Writes the page to `path` through a temporary file (no partial page on
// failure). Returns the size in bytes. Throws InputError naming the path
// when it cannot be written.
std::size_t writeReplayPage(const std::string& path, const Replay& replay);

}  // namespace cairn::validation
