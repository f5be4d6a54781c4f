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

}  // namespace cairn::validation
