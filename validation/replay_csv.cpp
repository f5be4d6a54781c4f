#include "validation/replay_csv.hpp"

#include "cairn/error.hpp"
#include "validation/csv.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>

namespace cairn::validation {

namespace {

constexpr const char* kColumns[] = {"step", "time", "body", "px", "py", "pz", "qw", "qx",
                                    "qy",   "qz",   "vx",   "vy", "vz", "wx", "wy", "wz"};
constexpr size_t kColumnCount = std::size(kColumns);

std::string expectedHeader() {
  std::string s;
  for (const char* c : kColumns) s += std::string(s.empty() ? "" : ",") + c;
  return s;
}

}  // namespace

void readRunCsv(const std::string& text, const std::string& path, Replay& replay) {
  const std::vector<CsvRow> records = parseCsvRows(text, path);
  const auto bad = [&](int line, const std::string& why) {
    return InputError(path, "", (line > 0 ? "line " + std::to_string(line) + ": " : "") + why);
  };
  if (records.empty()) throw bad(0, "empty file: expected the header " + expectedHeader() + " (as `cairn run --out` writes)");
  const CsvRow& head = records.front();
  bool header_ok = head.fields.size() == kColumnCount;
  for (size_t c = 0; header_ok && c < kColumnCount; ++c) header_ok = head.fields[c] == kColumns[c];
  if (!header_ok) {
    std::string got;
    for (const auto& f : head.fields) got += std::string(got.empty() ? "" : ",") + f;
    throw bad(head.line, "columns do not match: expected " + expectedHeader() + " (as `cairn run --out` writes), got " + got);
  }
  if (records.size() == 1) throw bad(0, "empty run: the header and no rows (no frame to replay)");

  std::vector<int> moving;  // scene bodies the CSV lists, in order
  for (int i = 0; i < replay.bodyCount(); ++i)
    if (replay.bodies[size_t(i)].type != BodyType::Static) moving.push_back(i);
  if (moving.empty()) throw bad(0, "the scene has no moving body to replay");
  const size_t rows = records.size() - 1;

  ReplayTrack track;
  const size_t n = size_t(replay.bodyCount());
  long last_step = -1;
  for (size_t r = 1; r < records.size(); ++r) {
    const CsvRow& rec = records[r];
    const size_t slot = (r - 1) % moving.size();
    const ReplayBody& body = replay.bodies[size_t(moving[slot])];
    if (rec.fields.size() != kColumnCount)
      throw bad(rec.line, std::to_string(rec.fields.size()) + " fields, expected " + std::to_string(kColumnCount));
    if (rec.fields[2] != body.name) {
      const bool known = std::any_of(replay.bodies.begin(), replay.bodies.end(),
                                     [&](const ReplayBody& b) { return b.name == rec.fields[2] && b.type != BodyType::Static; });
      throw bad(rec.line, known ? "body '" + rec.fields[2] + "' where the scene's order expects '" + body.name +
                                      "' (each step lists every non-static body of the scene, in scene order)"
                                : "body '" + rec.fields[2] + "' is not a moving body of the scene");
    }
    double v[kColumnCount] = {};
    for (size_t c = 0; c < kColumnCount; ++c) {
      if (c == 2) continue;
      const std::string& s = rec.fields[c];
      const auto res = std::from_chars(s.data(), s.data() + s.size(), v[c]);
      if (res.ec != std::errc() || res.ptr != s.data() + s.size() || !std::isfinite(v[c]))
        throw bad(rec.line, "column '" + std::string(kColumns[c]) + "': '" + s + "' is not a finite number");
    }
    const long step = std::lround(v[0]);
    if (double(step) != v[0] || step < 0) throw bad(rec.line, "column 'step': '" + rec.fields[0] + "' is not a step number");
    if (slot == 0) {
      if (step <= last_step)
        throw bad(rec.line, "step " + std::to_string(step) + " after step " + std::to_string(last_step) + ": steps must increase");
      last_step = step;
      track.time.push_back(v[1]);
      for (size_t i = 0; i < n; ++i) {  // static bodies keep their scene pose
        const ReplayBody& b = replay.bodies[i];
        track.position.insert(track.position.end(), {float(b.position.x()), float(b.position.y()), float(b.position.z())});
        track.orientation.insert(track.orientation.end(), {float(b.orientation.x()), float(b.orientation.y()),
                                                           float(b.orientation.z()), float(b.orientation.w())});
      }
      track.velocity.resize(track.position.size(), 0.0f);
      track.angular_velocity.resize(track.position.size(), 0.0f);
    } else if (step != last_step) {
      throw bad(rec.line, "step " + std::to_string(last_step) + " lists " + std::to_string(slot) + " of the scene's " +
                              std::to_string(moving.size()) + " moving bodies (missing '" + body.name + "')");
    }
    const size_t k = (track.time.size() - 1) * n + size_t(moving[slot]);
    const Quat raw(v[6], v[7], v[8], v[9]);
    if (raw.norm() < 1e-6) throw bad(rec.line, "columns 'qw'..'qz': not a rotation (zero quaternion)");
    const Quat q = raw.normalized();
    for (int d = 0; d < 3; ++d) {
      track.position[3 * k + size_t(d)] = float(v[3 + d]);
      track.velocity[3 * k + size_t(d)] = float(v[10 + d]);
      track.angular_velocity[3 * k + size_t(d)] = float(v[13 + d]);
    }
    const float qv[4] = {float(q.x()), float(q.y()), float(q.z()), float(q.w())};
    for (int d = 0; d < 4; ++d) track.orientation[4 * k + size_t(d)] = qv[d];
  }
  if (rows % moving.size() != 0)
    throw bad(records.back().line, "the last step lists " + std::to_string(rows % moving.size()) + " of the scene's " +
                                       std::to_string(moving.size()) + " moving bodies");
  replay.cairn = std::move(track);
}

}  // namespace cairn::validation
