// Drawing plots with a Python script next to the sources (validation/*.py,
// matplotlib): finding the script and running it with its output kept in
// a log. Shared by `cairn validate --report` (plot_report.py),
// `cairn sweep` (plot_sweep.py) and `cairn bench` (plot_bench.py).
#pragma once

#include <string>

namespace cairn::validation {

// validation/NAME: $CAIRN_PLOT_SCRIPT when set (for NAME = plot_report.py;
// $CAIRN_SWEEP_PLOT_SCRIPT for plot_sweep.py, $CAIRN_BENCH_PLOT_SCRIPT for
// plot_bench.py), else next to the source
// tree the executable was built in (build*/cairn -> ../validation), else
// under the working directory; "" when none exists.
std::string findPlotScript(const std::string& name);

// Runs `python script dir` with its output in dir/plots.log. Returns "" on
// success (the log is removed) or a one-line warning naming the script and
// the last line it printed (matplotlib missing, ...).
std::string runPlotScript(const std::string& python, const std::string& script, const std::string& dir);

}  // namespace cairn::validation
