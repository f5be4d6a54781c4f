// The work of each fuzz target, shared by the libFuzzer entry points
// (fuzz/*_fuzzer.cpp, built with clang by CAIRN_FUZZ=ON) and by the default
// test that replays every input kept in tests/fuzz_regressions/
// (tests/unit/fuzz_regressions_test.cpp, any compiler).
//
// Each returns whether the input loaded or was refused with an InputError;
// anything else (another exception, a non-finite state after a step, a
// broken invariant of the loaded data) escapes or aborts, which is what the
// fuzzer reports as a crash and the replay test as a failure. The work per
// input is bounded by fuzzLimits() and a fixed number of steps, so an input
// that takes long is a bug, not a large input.
#pragma once

#include "cairn/limits.hpp"

#include <cstddef>
#include <cstdint>

namespace cairn::fuzz {

enum class Outcome { Loaded, Refused };

// Small limits: every scene the fuzzer writes is cheap to load and step.
InputLimits fuzzLimits();

// The bytes as a scene file (relative mesh paths resolve to fuzz/seeds/obj):
// parseScene (which validates), buildWorld, then kSteps steps, after each
// of which every body's state must be finite (the NaN guard's promise).
Outcome sceneInput(const std::uint8_t* data, std::size_t size);
inline constexpr int kSteps = 3;

// The bytes as an OBJ file: parseObjMesh, then the mesh's invariants
// (indices in range, every triangle with an area, the tree over all of them).
Outcome objInput(const std::uint8_t* data, std::size_t size);

}  // namespace cairn::fuzz
