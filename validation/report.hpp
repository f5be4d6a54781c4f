// The validation report: DIR/report.md (a summary table, then per scene a
// table of figures, cairn and Bullet side by side with the closed form and
// pass or fail), one CSV of time series per scene, and PNG plots drawn by
// validation/plot_report.py (matplotlib) from a manifest, DIR/plots.json.
//
// Files in DIR, for a scene named N:
//   N.csv                time, then cairn_* and bullet_* columns: each trace,
//                        joint error, energy, penetration
//   N_trace_K.png        trace K (the bob's swing angle, the top box's height...)
//   N_joint_error.png    largest joint error over time
//   N_energy.png         kinetic + potential energy over time
//   N_penetration.png    deepest penetration over time
//   N.replay.html        the run in 3D, cairn and Bullet (docs/viewer.md),
//                        when the result carries a replay
#pragma once

#include "validation/compare.hpp"

#include <string>
#include <vector>

namespace cairn::validation {

// Creates `dir` if needed and checks a file can be written in it. Throws
// InputError naming the directory otherwise.
void prepareReportDir(const std::string& dir);

// The file stem used for a scene in the report: its name with characters
// other than [A-Za-z0-9._-] replaced, made unique among `taken`.
std::string reportStem(const std::string& name, std::vector<std::string>& taken);

// A value as the tables print it (`digits` significant digits, 4 or 6;
// yes/no for flags; "-" when there is none).
std::string formatFigureValue(const Figure& f, const std::optional<double>& v, int digits = 6);

// One line per scene: scene | kind | key figures cairn / Bullet (exact) |
// ms/step cairn / Bullet | result. Markdown, aligned for a terminal.
std::string summaryTable(const std::vector<SceneResult>& results);

// One line per failed figure: "SCENE: KEY (name): cairn V, CHECK, off by X".
std::vector<std::string> failureLines(const SceneResult& r);

struct ReportInfo {
  std::string command;  // the command line, quoted in the report
  std::string date;     // when it ran (UTC)
  std::string python = "/usr/bin/python3";
  std::string plot_script;  // validation/plot_report.py
};

// Writes report.md, the CSVs and plots.json into `dir`, then runs the plot
// script. Returns "" or a one-line warning when the plots could not be
// drawn (the tables are written regardless). Throws InputError when a file
// cannot be written.
std::string writeReport(const std::string& dir, const std::vector<SceneResult>& results, const ReportInfo& info);

}  // namespace cairn::validation
