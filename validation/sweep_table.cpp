#include "validation/sweep_table.hpp"

#include "cairn/error.hpp"
#include "validation/csv.hpp"
#include "validation/solver_keys.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

namespace cairn::validation {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

namespace {

std::vector<std::string> csvHeader(const SweepTable& t) {
  std::vector<std::string> h{"index"};
  h.insert(h.end(), t.setting_columns.begin(), t.setting_columns.end());
  for (int m = 0; m < kMeasureCount; ++m) h.emplace_back(measureColumn(static_cast<Measure>(m)));
  h.insert(h.end(), {"pareto", "status", "notes"});
  return h;
}

std::string readText(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  if (!f) throw InputError(p.string(), "", "cannot read (not a sweep directory?)");
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

void writeText(const fs::path& p, const std::string& content) {
  std::ofstream f(p, std::ios::binary);
  if (!f || !(f << content) || !f.flush()) throw InputError(p.string(), "", "cannot write sweep file");
}

std::string short4(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, std::abs(v) >= 1e-3 && std::abs(v) < 1e5 ? "%.4g" : "%.3e", v);
  return v == 0 ? "0" : buf;
}

// A setting for the Markdown table: long numbers (a dt of 1/60) to 6 digits.
std::string shortSetting(const std::string& s) {
  double v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (s.size() <= 8 || ec != std::errc() || end != s.data() + s.size()) return s;
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

Measure paretoAxis(const SweepTable& t) {
  const auto m = measureByColumn(t.manifest.value("pareto_axis", std::string()));
  return m ? *m : Measure::JointError;
}

// "pgs, 2 substeps, 10 iterations, erp 0.2": the settings that vary.
std::string settingsText(const SweepTable& t, const SweepRow& r) {
  std::string s;
  const Json& vary = t.manifest["vary"];
  for (size_t c = 0; c < t.setting_columns.size(); ++c) {
    const std::string& key = t.setting_columns[c];
    bool varied = key == "method";
    for (const auto& v : vary) varied = varied || v["key"] == key;
    if (!varied) continue;
    if (!s.empty()) s += ", ";
    s += key == "method" ? r.settings[c] : key + " " + shortSetting(r.settings[c]);
  }
  return s;
}

}  // namespace

std::string fingerprint(const std::string& text) {
  std::uint64_t h = 14695981039346656037ull;
  for (unsigned char c : text) {
    h ^= c;
    h *= 1099511628211ull;
  }
  char buf[20];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

Json sweepIdentity(const Json& manifest) {
  Json id = manifest;
  id.erase("shard");
  id.erase("command");
  id.erase("replay");  // only shard 0 writes the replay page
  return id;
}

void markPareto(std::vector<SweepRow>& rows, Measure axis) {
  const auto usable = [&](const SweepRow& r) {
    return r.status == "ok" && r[Measure::MsPerStep] && r[axis];
  };
  for (SweepRow& r : rows) {
    r.pareto = false;
    if (!usable(r)) continue;
    const double t = *r[Measure::MsPerStep], e = *r[axis];
    r.pareto = std::none_of(rows.begin(), rows.end(), [&](const SweepRow& o) {
      if (&o == &r || !usable(o)) return false;
      const double ot = *o[Measure::MsPerStep], oe = *o[axis];
      return ot <= t && oe <= e && (ot < t || oe < e);
    });
  }
}

std::string sweepCsv(const SweepTable& t) {
  std::string out = csvRecord(csvHeader(t));
  CsvRecord rec;
  for (const SweepRow& r : t.rows) {
    rec.clear();
    rec.integer(r.index);
    for (const std::string& s : r.settings) rec.text(s);
    for (const auto& v : r.values) v ? rec.number(*v) : rec.text("");
    rec.text(r.pareto ? "1" : "0").text(r.status).text(r.notes);
    out += rec.line();
  }
  return out;
}

std::string sweepMarkdown(const SweepTable& t) {
  const Json& m = t.manifest;
  const Measure axis = paretoAxis(t);
  std::ostringstream md;
  md << "# cairn sweep: " << m.value("scene", std::string()) << "\n\n";
  if (m.contains("command")) md << "Made by `" << m["command"].get<std::string>() << "`.\n\n";
  if (m.contains("shard"))
    md << "**Part " << m["shard"].get<std::string>() << " of a sharded sweep** (shards are 0-based): only its jobs are "
       << "below and the Pareto marks are within the part. Join the parts with `cairn sweep --merge DIR... --out DIR`.\n\n";
  md << "Scene: " << m.value("source", std::string()) << "; " << m.value("kind", std::string()) << " scene, "
     << m.value("steps", 0) << " steps of " << short4(m.value("dt", 0.0))
     << " s (a job with another dt runs as many steps as cover the same time). " << m.value("cairn_jobs", 0)
     << " cairn jobs and " << m.value("jobs", 0) - m.value("cairn_jobs", 0)
     << " Bullet jobs (method = bullet: one per distinct setting other than the method).\n\n";
  md << "Pareto axis: wall time per step (ms) against `" << measureColumn(axis)
     << "`; a row marked * is Pareto-optimal: no other row is both as fast and as accurate. ";
  if (m.value("exact_every", 0) > 0)
    md << "The exact-LCP distance is sampled every " << m["exact_every"].get<int>() << " steps. ";
  if (!m.value("analytic", std::string()).empty())
    md << "`analytic_error` is the " << m["analytic"].get<std::string>() << " error against the closed form. ";
  md << "Columns and their meaning: docs/tradeoff.md.\n\n";
  if (m.contains("replay"))
    md << "Replay in 3D of the scene with its own settings, cairn solid and Bullet as orange wireframes: ["
       << m["replay"].get<std::string>() << "](" << m["replay"].get<std::string>() << ") (docs/viewer.md).\n\n";

  // Measure columns any row has.
  std::vector<int> shown;
  for (int k = 0; k < kMeasureCount; ++k)
    if (std::any_of(t.rows.begin(), t.rows.end(), [&](const SweepRow& r) { return r.values[size_t(k)].has_value(); }))
      shown.push_back(k);

  std::vector<const SweepRow*> front;
  for (const SweepRow& r : t.rows)
    if (r.pareto) front.push_back(&r);
  std::sort(front.begin(), front.end(), [](const SweepRow* a, const SweepRow* b) {
    return *(*a)[Measure::MsPerStep] < *(*b)[Measure::MsPerStep];
  });
  md << "## Pareto-optimal settings, fastest first\n\n| index | settings | ms_per_step | " << measureColumn(axis)
     << " |\n|---:|---|---:|---:|\n";
  for (const SweepRow* r : front)
    md << "| " << r->index << " | " << settingsText(t, *r) << " | " << short4(*(*r)[Measure::MsPerStep]) << " | "
       << short4(*(*r)[axis]) << " |\n";
  md << "\n## All jobs\n\n| index | pareto |";
  for (const std::string& c : t.setting_columns) md << " " << c << " |";
  for (int k : shown) md << " " << measureColumn(static_cast<Measure>(k)) << " |";
  md << " status |\n|---:|---|";
  for (size_t c = 0; c < t.setting_columns.size(); ++c) md << "---|";
  for (size_t k = 0; k < shown.size(); ++k) md << "---:|";
  md << "---|\n";
  for (const SweepRow& r : t.rows) {
    md << "| " << r.index << " | " << (r.pareto ? "*" : "") << " |";
    for (const std::string& s : r.settings) md << " " << shortSetting(s) << " |";
    for (int k : shown) md << " " << (r.values[size_t(k)] ? short4(*r.values[size_t(k)]) : "-") << " |";
    md << " " << r.status << " |\n";
  }
  std::map<std::string, int> notes;
  for (const SweepRow& r : t.rows)
    if (!r.notes.empty()) ++notes[r.notes];
  if (!notes.empty()) {
    md << "\nNotes:\n\n";
    for (const auto& [n, count] : notes) md << "- " << count << " job(s): " << n << "\n";
  }
  if (!m.contains("shard")) md << "\n![Pareto plot](pareto.png)\n";
  return md.str();
}

SweepTable readSweepPart(const std::string& dir) {
  const fs::path root(dir);
  SweepTable t;
  const fs::path json_path = root / "sweep.json";
  t.manifest = Json::parse(readText(json_path), nullptr, false);
  if (t.manifest.is_discarded() || !t.manifest.is_object() || t.manifest.value("format", std::string()) != "cairn sweep 1")
    throw InputError(json_path.string(), "", "not a cairn sweep manifest");
  if (!t.manifest.contains("columns") || !t.manifest["columns"].is_array())
    throw InputError(json_path.string(), "columns", "missing");
  for (const auto& c : t.manifest["columns"]) t.setting_columns.push_back(c.get<std::string>());

  const fs::path csv_path = root / "sweep.csv";
  const auto records = parseCsv(readText(csv_path), csv_path.string());
  const auto header = csvHeader(t);
  if (records.empty() || records.front() != header)
    throw InputError(csv_path.string(), "", "header does not match sweep.json's columns");
  for (size_t n = 1; n < records.size(); ++n) {
    const auto& cells = records[n];
    const auto bad = [&](const std::string& why) {
      return InputError(csv_path.string() + ": record " + std::to_string(n + 1), "", why);
    };
    if (cells.size() != header.size())
      throw bad("has " + std::to_string(cells.size()) + " cells, the header " + std::to_string(header.size()));
    SweepRow r;
    size_t c = 0;
    const auto integer = [&](const std::string& s) {
      int v = 0;
      const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
      if (s.empty() || ec != std::errc() || end != s.data() + s.size()) throw bad("'" + s + "' is not an index");
      return v;
    };
    r.index = integer(cells[c++]);
    for (size_t k = 0; k < t.setting_columns.size(); ++k) r.settings.push_back(cells[c++]);
    r.bullet = !r.settings.empty() && r.settings.front() == "bullet";
    for (int k = 0; k < kMeasureCount; ++k) {
      const std::string& s = cells[c++];
      if (s.empty()) continue;
      double v = 0;
      const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
      if (ec != std::errc() || end != s.data() + s.size()) throw bad("'" + s + "' is not a number");
      r.values[size_t(k)] = v;
    }
    r.pareto = cells[c++] == "1";
    r.status = cells[c++];
    r.notes = cells[c++];
    t.rows.push_back(std::move(r));
  }
  return t;
}

SweepTable mergeSweepParts(const std::vector<SweepTable>& parts, const std::vector<std::string>& dirs) {
  if (parts.empty()) throw InputError("--merge", "", "no directories given");
  const Json id = sweepIdentity(parts.front().manifest);
  for (size_t p = 1; p < parts.size(); ++p) {
    const Json other = sweepIdentity(parts[p].manifest);
    if (other == id) continue;
    std::string what;
    for (const auto& [key, value] : id.items())
      if (!other.contains(key) || other[key] != value) what += (what.empty() ? "" : ", ") + key;
    for (const auto& [key, value] : other.items())
      if (!id.contains(key)) what += (what.empty() ? "" : ", ") + key;
    throw InputError("--merge", "", dirs[p] + " is not part of the same sweep as " + dirs.front() + " (" + what +
                                         " differ: sweep.json)");
  }
  const int jobs = id.value("jobs", 0);
  std::vector<int> owner(size_t(std::max(jobs, 0)), -1);
  SweepTable whole;
  whole.manifest = parts.front().manifest;
  whole.manifest.erase("shard");
  whole.setting_columns = parts.front().setting_columns;
  whole.rows.resize(owner.size());
  for (size_t p = 0; p < parts.size(); ++p)
    for (const SweepRow& r : parts[p].rows) {
      if (r.index < 0 || r.index >= jobs)
        throw InputError("--merge", "", dirs[p] + ": job " + std::to_string(r.index) + " is out of range (the sweep has " +
                                            std::to_string(jobs) + " jobs)");
      if (owner[size_t(r.index)] >= 0)
        throw InputError("--merge", "", "job " + std::to_string(r.index) + " is in both " + dirs[size_t(owner[size_t(r.index)])] +
                                            " and " + dirs[p]);
      owner[size_t(r.index)] = int(p);
      whole.rows[size_t(r.index)] = r;
    }
  std::string missing;
  int missing_count = 0;
  for (int i = 0; i < jobs; ++i)
    if (owner[size_t(i)] < 0 && ++missing_count <= 20) missing += (missing.empty() ? "" : ", ") + std::to_string(i);
  if (missing_count > 0)
    throw InputError("--merge", "", std::to_string(missing_count) + " job(s) missing from the parts: " + missing +
                                        (missing_count > 20 ? ", ..." : "") + " (a shard not run or not listed?)");
  markPareto(whole.rows, paretoAxis(whole));
  return whole;
}

void writeSweepFiles(const std::string& dir, const SweepTable& table) {
  const fs::path root(dir);
  writeText(root / "sweep.csv", sweepCsv(table));
  writeText(root / "sweep.md", sweepMarkdown(table));
  writeText(root / "sweep.json", table.manifest.dump(1) + "\n");
}

}  // namespace cairn::validation
