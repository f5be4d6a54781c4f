// The output of `cairn sweep` (docs/tradeoff.md): DIR/sweep.csv (one row
// per job, every number as the shortest text that reads back to the same
// double), DIR/sweep.md (the same for people, with the Pareto-optimal
// settings listed), DIR/sweep.json (the manifest: scene, vary lists, job
// count, Pareto axis, shard) and DIR/pareto.png (validation/plot_sweep.py).
//
// A shard writes sweep.csv, sweep.json and sweep.md for its jobs only;
// `cairn sweep --merge` reads parts back (readSweepPart), checks they
// belong together and cover every job once, and writes the whole.
#pragma once

#include "validation/sweep_run.hpp"

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace cairn::validation {

struct SweepTable {
  // format, scene, source, scene_hash, kind, steps, dt, vary, columns,
  // jobs, cairn_jobs, pareto_axis, analytic, exact_every; plus shard
  // ("i/n") for a part, command (how it was made) and replay (the replay
  // page's file name, written by the whole sweep or shard 0).
  nlohmann::ordered_json manifest;
  std::vector<std::string> setting_columns;
  std::vector<SweepRow> rows;  // by index
};

// The manifest fields that must agree for parts to be merged (all but
// shard and command).
nlohmann::ordered_json sweepIdentity(const nlohmann::ordered_json& manifest);

// 64-bit FNV-1a of the text, as 16 hex digits (the scene's fingerprint).
std::string fingerprint(const std::string& text);

// Marks the rows on the Pareto front of (ms_per_step, axis), both to be
// minimized: a row is marked when no other row is at most as slow and at
// most as wrong, and strictly better in one. Rows that stopped, or lack
// either figure, are never marked and do not dominate.
void markPareto(std::vector<SweepRow>& rows, Measure axis);

std::string sweepCsv(const SweepTable& table);
std::string sweepMarkdown(const SweepTable& table);

// Reads DIR/sweep.json and DIR/sweep.csv. Throws InputError naming the
// file (and the line) when either is missing or malformed.
SweepTable readSweepPart(const std::string& dir);

// Joins parts: the same identity, no index twice, none missing. Throws
// InputError naming the directories and the indices otherwise. The result
// has no shard and its Pareto marks recomputed.
SweepTable mergeSweepParts(const std::vector<SweepTable>& parts, const std::vector<std::string>& dirs);

// Writes sweep.csv, sweep.md and sweep.json into `dir` (which exists and
// is writable: report.hpp's prepareReportDir). Throws InputError when a
// file cannot be written.
void writeSweepFiles(const std::string& dir, const SweepTable& table);

}  // namespace cairn::validation
