// The output of `cairn bench` (docs/benchmarks.md, "cairn bench"):
//   DIR/bench.csv   one row per scene x engine configuration (RFC 4180:
//                   comma-separated, CRLF line ends, fields with a comma,
//                   quote or line break quoted); numbers as the shortest
//                   text that reads back to the same double; an empty
//                   cell where a figure does not apply
//   DIR/bench.md    the same for people: times and ratios, accuracy beside
//                   time, cairn's stages, and the settings of every column
//   DIR/bench.json  the manifest: command, date, machine and load, repeats,
//                   overrides, scene list (the plot script reads it)
//   DIR/*.png       drawn by validation/plot_bench.py
//
// bench.csv's columns, in order (benchCsvColumns()):
//   scene, family, engine, status            what ran; status "ok" or why not
//   bodies, joints, steps, dt                dynamic bodies; steps per run; s
//   method, iterations, substeps, sleeping,  the settings that engine used
//   friction_directions, threads, overrides  (overrides: what the command changed)
//   repeats, ms_per_step                     median over repeats of a run's mean step time (ms)
//   ms_per_step_repeats                      each repeat's value, ';'-separated, in run order
//   ratio_vs_cairn                           ms_per_step / cairn's ms_per_step on the scene
//                                            (> 1: cairn is faster; 1 on cairn's row)
//   rows, contacts, contact_points           cairn's StepStats, mean per step (cairn's row only)
//   sleeping_bodies_end                      dynamic bodies asleep after the last step
//   rest_from, rest_displacement_m           "start" or "last_second" (bench_run.hpp)
//   penetration_m, joint_error_m, exact_distance_m
//   stage_<name>_ms                          cairn's median ms per step in each stage of its
//                                            step (stageName order; cairn's row only)
#pragma once

#include "validation/bench_run.hpp"

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace cairn::validation {

struct BenchTable {
  // format, command, date, machine {cpus, cpu_model, load_start, load_end,
  // core_check_threads, core_share_start, core_share_end},
  // repeats, threads, steps, set, cairn_set, bullet_set, scaling, scenes.
  nlohmann::ordered_json manifest;
  std::vector<BenchScene> scenes;          // as run (the settings columns read them)
  std::vector<BenchSceneResult> results;   // by scene
};

std::vector<std::string> benchCsvColumns();
std::string benchCsv(const BenchTable& table);
std::string benchMarkdown(const BenchTable& table);

// Writes bench.csv, bench.md and bench.json into `dir` (which exists and
// is writable: report.hpp's prepareReportDir). Throws InputError when a
// file cannot be written.
void writeBenchFiles(const std::string& dir, const BenchTable& table);

}  // namespace cairn::validation
