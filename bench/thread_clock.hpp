// CPU time of the calling thread: benchmarks that time only part of an
// iteration, or report time per query, read it so that a loaded machine that
// deschedules the thread does not inflate the figure.
#pragma once

#include <ctime>

namespace cairn::bench {

inline double threadSeconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

}  // namespace cairn::bench
