// The viewer's files, embedded at build time by cmake/embed_viewer.cmake
// (the generated viewer_assets.cpp): nothing is read from disk at run time.
#pragma once

#include <string_view>

namespace cairn::validation::viewer_assets {

std::string_view page();     // viewer/page.html: the template
std::string_view style();    // viewer/viewer.css
std::string_view three();    // three.min.js and OrbitControls.js (libjs-three)
std::string_view scripts();  // viewer/*.js in load order

}  // namespace cairn::validation::viewer_assets
