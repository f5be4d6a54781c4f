// When and where a run happened, as reports quote it: the date (UTC), the
// number of logical CPUs (what `nproc` prints), the CPU model
// (/proc/cpuinfo) and the load average (/proc/loadavg). Timings on a
// machine shared with other work mean little without the load beside them.
#pragma once

#include <string>

namespace cairn::validation {

std::string utcNow();  // "2026-11-24 11:36 UTC"

struct MachineInfo {
  int cpus = 0;            // logical CPUs
  std::string cpu_model;   // first "model name" of /proc/cpuinfo, or "unknown"
};
MachineInfo currentMachine();

// The 1, 5 and 15 minute load averages ("8.71 7.99 5.43"), or "unknown".
std::string loadAverage();

// What share of one thread's arithmetic rate each of `threads` threads
// keeps when all run at once: twelve independent multiply-add chains in
// double (enough in flight to keep a core's floating-point units busy),
// timed on one thread and then on `threads` together, the best of three
// each. About 1 where the logical CPUs are cores of their own and idle;
// about 0.5 to 0.7 where two of them share one core (hyperthreads, or a
// virtual machine's CPUs whose host core runs other work), and then no
// loop the step hands to its threads can run near `threads` times
// faster. 1 for fewer than two threads. Takes some 30 ms.
double coreShare(int threads);

}  // namespace cairn::validation
