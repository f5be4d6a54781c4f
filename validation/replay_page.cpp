// The page's data block (docs/viewer.md, "Data format"): one JSON object in
// a <script type="application/json"> element. Small things (bodies,
// shapes, joints) are plain JSON; every per-frame array is a base64 string
// of little-endian typed-array bytes (float32 unless noted), decoded in the
// page with one atob and a typed-array view, no per-number parsing.
#include "validation/replay_page.hpp"

#include "cairn/error.hpp"
#include "validation/viewer_assets.hpp"

#include <nlohmann/json.hpp>

#include <bit>
#include <cstring>
#include <filesystem>
#include <fstream>

namespace cairn::validation {

namespace {

using Json = nlohmann::ordered_json;
static_assert(std::endian::native == std::endian::little, "the page reads typed arrays as little-endian bytes");

std::string base64(const void* data, size_t bytes) {
  static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  const auto* p = static_cast<const unsigned char*>(data);
  std::string out;
  out.reserve((bytes + 2) / 3 * 4);
  for (size_t i = 0; i < bytes; i += 3) {
    const unsigned v = unsigned(p[i]) << 16 | (i + 1 < bytes ? unsigned(p[i + 1]) << 8 : 0u) | (i + 2 < bytes ? p[i + 2] : 0u);
    out += kAlphabet[v >> 18 & 63];
    out += kAlphabet[v >> 12 & 63];
    out += i + 1 < bytes ? kAlphabet[v >> 6 & 63] : '=';
    out += i + 2 < bytes ? kAlphabet[v & 63] : '=';
  }
  return out;
}

template <class T>
std::string block(const std::vector<T>& v) {
  return base64(v.data(), v.size() * sizeof(T));
}

Json vec(const Vec3& v) { return Json::array({v.x(), v.y(), v.z()}); }

Json shapeJson(const ShapeDesc& s) {
  Json j;
  j["type"] = shapeTypeName(s.type);
  j["position"] = vec(s.local.p);
  j["orientation"] = Json::array({s.local.q.x(), s.local.q.y(), s.local.q.z(), s.local.q.w()});
  switch (s.type) {
    case ShapeType::Sphere: j["radius"] = s.radius; break;
    case ShapeType::Box: j["half_extents"] = vec(s.half_extents); break;
    case ShapeType::Capsule:
    case ShapeType::Cylinder:
      j["radius"] = s.radius;
      j["half_height"] = s.half_height;
      break;
    case ShapeType::Plane:
      j["normal"] = vec(s.normal);
      j["offset"] = s.offset;
      break;
    case ShapeType::ConvexHull: {  // faces as triangle fans (each face is a convex loop)
      Json v = Json::array(), t = Json::array();
      for (const Vec3& p : s.hull->vertices) v.insert(v.end(), {p.x(), p.y(), p.z()});
      for (const auto& f : s.hull->faces)
        for (size_t k = 1; k + 1 < f.size(); ++k) t.insert(t.end(), {f[0], f[k], f[k + 1]});
      j["vertices"] = v;
      j["triangles"] = t;
      break;
    }
    case ShapeType::Mesh: {
      Json v = Json::array(), t = Json::array();
      for (const Vec3& p : s.mesh->vertices) v.insert(v.end(), {p.x(), p.y(), p.z()});
      for (const auto& tri : s.mesh->triangles) t.insert(t.end(), {tri[0], tri[1], tri[2]});
      j["vertices"] = v;
      j["triangles"] = t;
      break;
    }
  }
  return j;
}

Json trackJson(const ReplayTrack& t) {
  Json j;
  j["time"] = block(t.time);  // float64
  j["position"] = block(t.position);
  j["orientation"] = block(t.orientation);
  if (!t.velocity.empty()) j["velocity"] = block(t.velocity);
  if (!t.angular_velocity.empty()) j["angular_velocity"] = block(t.angular_velocity);
  return j;
}

Json overlaysJson(const ReplayOverlays& o) {
  if (!o.recorded) return nullptr;
  Json j;
  j["asleep"] = block(o.asleep);              // uint8
  j["island"] = block(o.island);              // int32
  j["manifold_begin"] = block(o.manifold_begin);    // uint32
  j["point_begin"] = block(o.point_begin);          // uint32
  j["contact_frame"] = block(o.contact_frame);      // uint32
  j["manifold_normal"] = block(o.manifold_normal);
  j["manifold_friction"] = block(o.manifold_friction);
  j["manifold_body"] = block(o.manifold_body);      // int32
  j["manifold_points"] = block(o.manifold_points);  // uint8
  j["point_position"] = block(o.point_position);
  j["point_impulse"] = block(o.point_impulse);
  j["joint_anchor_a"] = block(o.joint_anchor_a);
  j["joint_anchor_b"] = block(o.joint_anchor_b);
  j["joint_axis"] = block(o.joint_axis);
  j["joint_error"] = block(o.joint_error);
  j["joint_force_a"] = block(o.joint_force_a);
  j["joint_force_b"] = block(o.joint_force_b);
  return j;
}

std::string dataJson(const Replay& r) {
  Json j;
  j["format"] = "cairn replay 1";
  j["title"] = r.title;
  j["source"] = r.source;
  j["notes"] = r.notes;
  j["dt"] = r.dt;
  j["substeps"] = r.substeps;
  j["gravity"] = vec(r.gravity);
  j["frames"] = r.cairn.frames();
  Json bodies = Json::array();
  for (const ReplayBody& b : r.bodies) {
    Json shapes = Json::array();
    for (const ShapeDesc& s : b.shapes) shapes.push_back(shapeJson(s));
    bodies.push_back(Json{{"name", b.name}, {"type", bodyTypeName(b.type)}, {"mass", b.mass}, {"shapes", shapes}});
  }
  j["bodies"] = bodies;
  Json joints = Json::array();
  for (const ReplayJoint& jt : r.joints)
    joints.push_back(Json{{"name", jt.name}, {"type", jointTypeName(jt.type)}, {"bodies", {jt.body_a, jt.body_b}}});
  j["joints"] = joints;
  j["cairn"] = trackJson(r.cairn);
  j["overlays"] = overlaysJson(r.overlays);
  j["bullet"] = r.bullet ? trackJson(*r.bullet) : Json(nullptr);
  if (r.parting)
    j["parting"] = Json{{"tolerance", r.parting->tolerance}, {"frame", r.parting->frame}, {"time", r.parting->time},
                        {"body", r.parting->body}, {"distance", r.parting->distance}};
  else
    j["parting"] = nullptr;
  // '<' only occurs inside JSON strings, where \u003c reads back the same:
  // no name can close the script element early.
  std::string text = j.dump(-1, ' ', false, Json::error_handler_t::replace);
  std::string out;
  out.reserve(text.size());
  for (char c : text) c == '<' ? out += "\\u003c" : out += c;
  return out;
}

std::string escapeHtml(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '<') out += "&lt;";
    else if (c == '>') out += "&gt;";
    else if (c == '&') out += "&amp;";
    else if (c == '"') out += "&quot;";
    else out += c;
  }
  return out;
}

// Replaces the first `marker` at or after `from` in `page`; returns where
// the inserted text ends, so no inserted text is searched for a later
// marker (the template holds them in document order).
size_t fill(std::string& page, size_t from, std::string_view marker, std::string_view content) {
  const size_t at = page.find(marker, from);
  if (at == std::string::npos) throw std::logic_error("viewer/page.html lacks the marker " + std::string(marker));
  page.replace(at, marker.size(), content);
  return at + content.size();
}

}  // namespace

std::string replayPageHtml(const Replay& replay) {
  std::string page(viewer_assets::page());
  size_t at = fill(page, 0, "{{TITLE}}", escapeHtml(replay.title));
  at = fill(page, at, "/*{{STYLE}}*/", viewer_assets::style());
  at = fill(page, at, "{{DATA}}", dataJson(replay));
  at = fill(page, at, "//{{THREE}}", viewer_assets::three());
  fill(page, at, "//{{VIEWER}}", viewer_assets::scripts());
  return page;
}

std::size_t writeReplayPage(const std::string& path, const Replay& replay) {
  const std::string html = replayPageHtml(replay);
  const std::string tmp = path + ".tmp";
  {
    std::ofstream f(tmp, std::ios::binary);
    if (!f || !(f << html) || !f.flush()) {
      std::error_code ec;
      std::filesystem::remove(tmp, ec);
      throw InputError(path, "", "cannot write the replay page");
    }
  }
  std::filesystem::rename(tmp, path);
  return html.size();
}

}  // namespace cairn::validation
