#include "gbdcs/sim/gesture_timeline.hpp"

#include <cmath>

#include "gbdcs/contracts/json_file.hpp"

namespace gbdcs::sim {

namespace {

double number(const nlohmann::json& obj, const char* key, double fallback, double lo, double hi,
              const std::string& where) {
  if (!obj.contains(key)) return fallback;
  const auto& v = obj.at(key);
  if (!v.is_number()) throw TimelineError(where + ": '" + key + "' must be a number");
  const double x = v.get<double>();
  if (!(x >= lo && x <= hi)) {
    throw TimelineError(where + ": '" + key + "' = " + std::to_string(x) + " is outside [" +
                        std::to_string(lo) + ", " + std::to_string(hi) + "]");
  }
  return x;
}

void check_keys(const nlohmann::json& obj, std::initializer_list<const char*> allowed,
                const std::string& where) {
  if (!obj.is_object()) throw TimelineError(where + ": expected a JSON object");
  for (const auto& [key, value] : obj.items()) {
    bool known = false;
    for (const char* a : allowed) known = known || key == a;
    if (!known) throw TimelineError(where + ": unknown field '" + key + "'");
  }
}

const std::initializer_list<const char*> kPlacementKeys = {
    "center_x", "center_y", "size", "roll_deg", "yaw_deg", "pitch_deg", "handedness"};

Placement placement_from(const nlohmann::json& obj, Placement p, const std::string& where) {
  p.center_x = number(obj, "center_x", p.center_x, 0, 1, where);
  p.center_y = number(obj, "center_y", p.center_y, 0, 1, where);
  p.size = number(obj, "size", p.size, 0.05, 1.0, where);
  p.roll_deg = number(obj, "roll_deg", p.roll_deg, -180, 180, where);
  p.yaw_deg = number(obj, "yaw_deg", p.yaw_deg, -40, 40, where);
  p.pitch_deg = number(obj, "pitch_deg", p.pitch_deg, -40, 40, where);
  if (obj.contains("handedness")) {
    const auto& h = obj.at("handedness");
    auto parsed = h.is_string() ? contracts::handedness_from_string(h.get<std::string>())
                                : std::nullopt;
    if (!parsed) throw TimelineError(where + ": 'handedness' must be \"Left\" or \"Right\"");
    p.handedness = *parsed;
  }
  return p;
}

}  // namespace

GestureTimeline GestureTimeline::from_json(const nlohmann::json& doc) {
  check_keys(doc, {"name", "description", "seed", "fps", "noise", "placement", "segments"},
             "timeline");
  GestureTimeline t;
  t.name_ = doc.value("name", std::string("timeline"));
  t.seed_ = static_cast<unsigned>(number(doc, "seed", 1, 0, 4294967295.0, "timeline"));
  t.fps_ = number(doc, "fps", 30, 1, 240, "timeline");
  t.noise_ = number(doc, "noise", 0.004, 0, 0.1, "timeline");
  Placement base;
  if (doc.contains("placement")) {
    check_keys(doc["placement"], kPlacementKeys, "timeline.placement");
    base = placement_from(doc["placement"], base, "timeline.placement");
  }
  if (!doc.contains("segments") || !doc["segments"].is_array() || doc["segments"].empty()) {
    throw TimelineError("timeline: 'segments' must be a non-empty array of "
                        "{\"pose\": ..., \"duration_s\": ...}");
  }
  std::size_t i = 0;
  for (const auto& s : doc["segments"]) {
    const std::string where = "timeline.segments[" + std::to_string(i++) + "]";
    std::vector<const char*> keys = {"pose", "duration_s", "transition_s"};
    keys.insert(keys.end(), kPlacementKeys.begin(), kPlacementKeys.end());
    if (!s.is_object()) throw TimelineError(where + ": expected a JSON object");
    for (const auto& item : s.items()) {
      const std::string& key = item.key();  // not a structured binding: clang 14 cannot capture one
      if (std::find_if(keys.begin(), keys.end(), [&](const char* k) { return key == k; }) ==
          keys.end()) {
        throw TimelineError(where + ": unknown field '" + key + "'");
      }
    }
    TimelineSegment seg;
    if (!s.contains("pose") || !s["pose"].is_string()) {
      throw TimelineError(where + ": 'pose' is required (a pose name or \"NO_HAND\")");
    }
    const auto pose = s["pose"].get<std::string>();
    if (pose != "NO_HAND") {
      seg.pose = pose_from_string(pose);
      if (!seg.pose) {
        std::string known;
        for (auto p : kAllPoses) known += std::string(known.empty() ? "" : ", ") + std::string(to_string(p));
        throw TimelineError(where + ": unknown pose '" + pose + "' (known: NO_HAND, " + known + ")");
      }
    }
    if (!s.contains("duration_s")) throw TimelineError(where + ": 'duration_s' is required");
    seg.duration_s = number(s, "duration_s", 1, 1e-3, 3600, where);
    seg.transition_s = number(s, "transition_s", 0.25, 0, seg.duration_s, where);
    seg.placement = placement_from(s, base, where);
    t.segments_.push_back(seg);
  }
  t.rng_.seed(t.seed_);
  for (const auto& seg : t.segments_) {
    t.poses_.push_back(seg.pose ? pose_for(*seg.pose, t.rng_) : HandPose{});
  }
  return t;
}

GestureTimeline GestureTimeline::load_file(const std::string& path) {
  const auto doc = contracts::read_json_file<TimelineError>(path, "timeline file");
  return contracts::prefix_errors<TimelineError>(path, [&] { return from_json(doc); });
}

double GestureTimeline::duration_s() const {
  double total = 0;
  for (const auto& s : segments_) total += s.duration_s;
  return total;
}

std::size_t GestureTimeline::frame_count() const {
  return static_cast<std::size_t>(std::floor(duration_s() * fps_ + 1e-9));
}

TimelineFrame GestureTimeline::next_frame() {
  TimelineFrame f;
  f.time_s = static_cast<double>(next_index_) / fps_;
  ++next_index_;
  double start = 0;
  std::size_t i = 0;
  for (; i + 1 < segments_.size() && f.time_s >= start + segments_[i].duration_s; ++i) {
    start += segments_[i].duration_s;
  }
  f.segment = i;
  const auto& seg = segments_[i];
  f.label = seg.pose ? std::string(to_string(*seg.pose)) : "NO_HAND";
  if (!seg.pose) return f;
  f.deliberate = gesture_of(*seg.pose);
  HandPose pose = poses_[i];
  const double into = f.time_s - start;
  if (i > 0 && segments_[i - 1].pose && seg.transition_s > 0 && into < seg.transition_s) {
    pose = blend(poses_[i - 1], poses_[i], into / seg.transition_s);
  }
  auto hand = synthesize(pose, seg.placement);
  add_landmark_noise(hand, noise_, seg.placement.size, rng_);
  f.hand = hand;
  return f;
}

}  // namespace gbdcs::sim
