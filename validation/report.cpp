#include "validation/report.hpp"

#include "validation/csv.hpp"

#include "cairn/error.hpp"
#include "validation/plot_script.hpp"
#include "validation/replay_page.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace cairn::validation {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

namespace {

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

// 4 significant digits for the summary, 6 in the scene tables.
std::string num(double v, int digits = 6) {
  if (!std::isfinite(v)) return std::isnan(v) ? "n/a" : (v > 0 ? "inf" : "-inf");
  if (v == 0) return "0";
  const double a = std::abs(v);
  if (a >= 1e-3 && a < 1e5) return fmt(digits == 4 ? "%.4g" : "%.6g", v);
  return fmt(digits == 4 ? "%.2e" : "%.4e", v);
}

// Shortest text that reads back to the same double, for the CSVs; a
// missing sample (non-finite) is an empty cell.
std::string exact(double v) {
  std::string s;
  if (std::isfinite(v)) appendExactNumber(s, v);
  return s;
}

void writeFile(const fs::path& path, const std::string& content) {
  std::ofstream f(path, std::ios::binary);
  if (!f) throw InputError(path.string(), "", "cannot write report file");
  f << content;
  if (!f) throw InputError(path.string(), "", "cannot write report file");
}

std::string shortLabel(const std::string& key) {
  if (key == "position") return "pos. diff";
  if (key == "top_height") return "top y";
  if (key == "drift") return "drift";
  if (key == "penetration") return "pen.";
  if (key == "joint_error") return "joint err.";
  if (key == "period") return "period";
  if (key == "slide") return "slide a";
  if (key == "stick") return "stick";
  if (key == "apex_ratio") return "apex ratio";
  if (key == "open_time") return "open t";
  if (key == "projectile") return "x err.";
  if (key == "spring_period") return "spring T";
  return key;
}

std::string resultText(const Figure& f) {
  if (f.check == Check::None) return "";
  return f.pass ? "pass" : "**FAIL**";
}

std::string escapeCell(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '|') out += '\\';
    out += c;
  }
  return out;
}

const Figure* findFigure(const SceneResult& r, const std::string& key) {
  for (const Figure& f : r.figures)
    if (f.key == key) return &f;
  return nullptr;
}

std::string excessText(const Figure& f) {
  if (f.check == Check::NotWorseFlag) return "cairn collapsed and Bullet did not";
  if (f.check == Check::RelAnalytic) return "off by " + fmt("%.3g%%", 100 * f.excess);
  return "off by " + num(f.excess) + (f.unit.empty() ? "" : " " + f.unit);
}

// Pads each column of a Markdown table to its widest cell.
std::string alignTable(const std::vector<std::vector<std::string>>& rows) {
  std::vector<size_t> width;
  for (const auto& r : rows)
    for (size_t c = 0; c < r.size(); ++c) {
      if (width.size() <= c) width.push_back(0);
      width[c] = std::max(width[c], r[c].size());
    }
  std::string out;
  for (size_t i = 0; i < rows.size(); ++i) {
    out += "|";
    for (size_t c = 0; c < rows[i].size(); ++c) out += " " + rows[i][c] + std::string(width[c] - rows[i][c].size(), ' ') + " |";
    out += "\n";
    if (i == 0) {
      out += "|";
      for (size_t c = 0; c < width.size(); ++c) out += std::string(width[c] + 2, '-') + "|";
      out += "\n";
    }
  }
  return out;
}

}  // namespace

void prepareReportDir(const std::string& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir)) throw InputError(dir, "", "cannot create report directory");
  const fs::path probe = fs::path(dir) / ".cairn-write-test";
  {
    std::ofstream f(probe);
    if (!f || !(f << "x") || !f.flush()) throw InputError(dir, "", "report directory is not writable");
  }
  fs::remove(probe, ec);
}

std::string reportStem(const std::string& name, std::vector<std::string>& taken) {
  std::string stem;
  for (char c : name) stem += (std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '-' || c == '_') ? c : '_';
  if (stem.empty()) stem = "scene";
  std::string unique = stem;
  for (int k = 2; std::find(taken.begin(), taken.end(), unique) != taken.end(); ++k) unique = stem + "_" + std::to_string(k);
  taken.push_back(unique);
  return unique;
}

std::string formatFigureValue(const Figure& f, const std::optional<double>& v, int digits) {
  if (!v) return "-";
  if (f.check == Check::NotWorseFlag || f.key == "collapse") return *v > 0.5 ? "yes" : "no";
  return num(*v, digits);
}

std::string summaryTable(const std::vector<SceneResult>& results) {
  std::vector<std::vector<std::string>> rows;
  rows.push_back({"scene", "kind", "key figures: cairn / Bullet (exact)", "ms/step cairn / Bullet", "result"});
  for (const SceneResult& r : results) {
    std::string keys;
    for (const Figure& f : r.figures) {
      if (!f.summary || f.key == "ms_per_step") continue;
      if (!keys.empty()) keys += "; ";
      const int d = f.key == "period" || f.key == "open_time" || f.key == "spring_period" ? 6 : 4;
      keys += shortLabel(f.key) + " " + formatFigureValue(f, f.cairn, d);
      if (f.key != "position") keys += " / " + formatFigureValue(f, f.bullet, d);
      if (f.analytic && f.key != "joint_error" && f.key != "stick" && f.key != "projectile") keys += " (" + formatFigureValue(f, f.analytic, d) + ")";
      if (!f.unit.empty()) keys += " " + f.unit;
      if (!f.pass) keys += " FAIL";
    }
    std::string cost = "-";
    if (const Figure* ms = findFigure(r, "ms_per_step")) {
      cost = formatFigureValue(*ms, ms->cairn, 4) + " / " + formatFigureValue(*ms, ms->bullet, 4);
      if (ms->cairn && ms->bullet && *ms->bullet > 0) cost += " (" + fmt("%.2fx", *ms->cairn / *ms->bullet) + ")";
    }
    rows.push_back({r.name, kindName(r.spec.kind), keys, cost, r.pass() ? "pass" : "FAIL"});
  }
  return alignTable(rows);
}

std::vector<std::string> failureLines(const SceneResult& r) {
  std::vector<std::string> out;
  for (const Figure* f : r.failures()) {
    std::string line = r.name + ": " + f->key + " (" + f->name + "): cairn " + formatFigureValue(*f, f->cairn) +
                       (f->unit.empty() ? "" : " " + f->unit);
    if (f->bullet) line += ", Bullet " + formatFigureValue(*f, f->bullet);
    if (f->analytic) line += ", exact " + formatFigureValue(*f, f->analytic);
    line += "; check " + f->checkText() + ": " + excessText(*f);
    if (!f->note.empty()) line += " (" + f->note + ")";
    out.push_back(line);
  }
  return out;
}

namespace {

struct PlotSeries {
  std::string column, label;
};

Json plotEntry(const std::string& csv, const std::string& png, const std::string& title, const std::string& ylabel,
               const std::vector<PlotSeries>& series, bool logy = false) {
  Json s = Json::array();
  for (const PlotSeries& p : series) s.push_back(Json{{"column", p.column}, {"label", p.label}});
  return Json{{"csv", csv}, {"png", png}, {"title", title}, {"xlabel", "time (s)"}, {"ylabel", ylabel},
              {"series", s}, {"logy", logy}};
}

std::string quantityName(const TraceSpec& t) {
  if (t.quantity == "height") return "height of the centre of mass";
  if (t.quantity == "x") return "x of the centre of mass";
  if (t.quantity == "z") return "z of the centre of mass";
  if (t.quantity == "swing_angle") return "swing angle from straight down";
  if (t.quantity == "angle") return "angle turned about the hinge axis";
  if (t.quantity == "slope") return "distance down the slope";
  return t.quantity;
}

// The CSV of one scene and its plot entries.
std::string sceneCsv(const SceneResult& r, const std::string& stem, Json& plots, std::vector<std::string>& pngs) {
  const EngineRun& c = r.cairn;
  const EngineRun& b = r.bullet;
  std::vector<std::string> header{"time"};
  std::vector<std::pair<const std::vector<double>*, const std::vector<double>*>> cols;
  const std::string csv = stem + ".csv";
  const auto addPair = [&](const std::string& name, const std::vector<double>* cv, const std::vector<double>* bv) {
    header.push_back("cairn_" + name);
    header.push_back("bullet_" + name);
    cols.push_back({cv, bv});
  };
  for (size_t t = 0; t < r.spec.traces.size(); ++t) {
    const TraceSpec& ts = r.spec.traces[t];
    const std::string name = "trace" + std::to_string(t);
    addPair(name, t < c.traces.size() ? &c.traces[t] : nullptr, t < b.traces.size() ? &b.traces[t] : nullptr);
    const std::string png = stem + "_trace_" + std::to_string(t) + ".png";
    plots.push_back(plotEntry(csv, png, r.name + ": '" + ts.body + "', " + quantityName(ts),
                              quantityName(ts) + " (" + ts.unit() + ")",
                              {{"cairn_" + name, "cairn"}, {"bullet_" + name, "Bullet"}}));
    pngs.push_back(png);
  }
  if (!r.scene.joints.empty()) {
    addPair("joint_error", &c.joint_error, &b.joint_error);
    plots.push_back(plotEntry(csv, stem + "_joint_error.png", r.name + ": largest joint error",
                              "joint position error (m)", {{"cairn_joint_error", "cairn"}, {"bullet_joint_error", "Bullet"}}));
    pngs.push_back(stem + "_joint_error.png");
  }
  addPair("energy", &c.energy, &b.energy);
  plots.push_back(plotEntry(csv, stem + "_energy.png", r.name + ": kinetic + potential energy", "energy (J)",
                            {{"cairn_energy", "cairn"}, {"bullet_energy", "Bullet"}}));
  pngs.push_back(stem + "_energy.png");
  if (!c.penetration.empty()) {
    addPair("penetration", &c.penetration, &b.penetration);
    plots.push_back(plotEntry(csv, stem + "_penetration.png", r.name + ": deepest penetration", "penetration (m)",
                              {{"cairn_penetration", "cairn"}, {"bullet_penetration", "Bullet"}}));
    pngs.push_back(stem + "_penetration.png");
  }
  std::string out = csvRecord(header);
  CsvRecord rec;
  const int n = std::max(c.samples(), b.samples());
  for (int s = 0; s < n; ++s) {
    const std::vector<double>& times = s < c.samples() ? c.time : b.time;
    rec.clear();
    rec.text(exact(times[size_t(s)]));
    for (const auto& [cv, bv] : cols) {
      rec.text(cv && s < int(cv->size()) ? exact((*cv)[size_t(s)]) : "");
      rec.text(bv && s < int(bv->size()) ? exact((*bv)[size_t(s)]) : "");
    }
    out += rec.line();
  }
  return out;
}

std::string sceneSection(const SceneResult& r, const std::vector<std::string>& pngs, const std::string& replay_page) {
  std::ostringstream md;
  md << "## " << r.name << " — " << (r.pass() ? "pass" : "FAIL") << "\n\n";
  if (!replay_page.empty()) {
    md << "Replay in 3D: [" << replay_page << "](" << replay_page << ") (cairn solid, Bullet as orange wireframes";
    if (r.replay->parting && r.replay->parting->frame >= 0)
      md << "; they part by more than " << num(r.replay->parting->tolerance) << " m at t = "
         << fmt("%.3f", r.replay->parting->time) << " s, marked red on the time slider";
    md << "; docs/viewer.md).\n\n";
  }
  md << "Source: " << r.source << ". " << kindName(r.spec.kind) << " comparison";
  if (!r.spec.scenario.empty()) md << " (scenario type " << r.spec.scenario << ")";
  md << "; " << r.scene.steps << " steps of " << num(r.scene.dt) << " s, " << r.scene.bodies.size() << " bodies, "
     << r.scene.joints.size() << " joints, " << r.scene.solver.iterations << " iterations.\n\n";
  if (!r.description.empty()) md << "> " << r.description << "\n\n";
  std::vector<std::vector<std::string>> rows;
  rows.push_back({"figure", "cairn", "Bullet", "exact", "check", "result", "notes"});
  for (const Figure& f : r.figures) {
    const std::string unit = f.unit.empty() ? "" : " (" + f.unit + ")";
    rows.push_back({escapeCell(f.name + unit), formatFigureValue(f, f.cairn), formatFigureValue(f, f.bullet),
                    formatFigureValue(f, f.analytic), escapeCell(f.checkText()), resultText(f), escapeCell(f.note)});
  }
  md << alignTable(rows) << "\n";
  const auto fails = failureLines(r);
  if (!fails.empty()) {
    md << "Outside tolerance:\n\n";
    for (const auto& l : fails) md << "- " << l << "\n";
    md << "\n";
  }
  if (!r.skipped.empty()) {
    md << "Not validated against Bullet, or mapped only approximately (BulletOracle::skipped()); the rest of the "
          "scene was compared:\n\n";
    for (const auto& s : r.skipped) md << "- " << s << "\n";
    md << "\n";
  }
  for (const auto& p : pngs) md << "![" << p << "](" << p << ")\n";
  md << "\n";
  return md.str();
}

}  // namespace

std::string writeReport(const std::string& dir, const std::vector<SceneResult>& results, const ReportInfo& info) {
  const fs::path root(dir);
  Json plots = Json::array();
  std::vector<std::string> taken;
  std::ostringstream md;
  md << "# cairn validation report\n\n";
  md << "Generated " << info.date << " by `" << info.command << "`.\n\n";
  md << "cairn against Bullet 3.24 (double precision, cairn's settings mapped: docs/validation.md) and against "
        "closed forms where they exist. Each scene runs in both engines for its full step count; cairn is "
        "judged against the tolerances of the scene's `validation` block, Bullet is the reference. See "
        "docs/validation.md, \"How to read the report\".\n\n";
  md << "## Summary\n\n" << summaryTable(results) << "\n";
  std::string sections;
  for (const SceneResult& r : results) {
    const std::string stem = reportStem(r.name, taken);
    std::vector<std::string> pngs;
    writeFile(root / (stem + ".csv"), sceneCsv(r, stem, plots, pngs));
    std::string page;
    if (r.replay) {
      page = stem + ".replay.html";
      writeReplayPage((root / page).string(), *r.replay);
    }
    sections += sceneSection(r, pngs, page);
  }
  md << sections;
  writeFile(root / "report.md", md.str());
  writeFile(root / "plots.json", plots.dump(1) + "\n");

  if (info.plot_script.empty()) return "validation/plot_report.py not found; plots not drawn";
  return runPlotScript(info.python, info.plot_script, root.string());
}

}  // namespace cairn::validation
