// Worker messages and recognition records as JSON.
#include "gbdcs/vision/vision_messages.hpp"

#include <chrono>

#include "gbdcs/contracts/codec.hpp"

namespace gbdcs::vision {
namespace {

using nlohmann::json;

double to_ms(contracts::Duration d) {
  return std::chrono::duration<double, std::milli>(d).count();
}

[[noreturn]] void bad(const std::string& where, const std::string& problem) {
  throw std::invalid_argument(where + ": " + problem);
}

double number(const json& obj, const char* key, const std::string& where) {
  const auto it = obj.find(key);
  if (it == obj.end() || !it->is_number())
    bad(where, std::string("'") + key + "' must be a number");
  return it->get<double>();
}

HandResult hand_from_json(const json& doc, const std::string& where) {
  if (!doc.is_object()) bad(where, "a hand must be an object");
  HandResult h;
  const auto handed = doc.find("handedness");
  if (handed == doc.end() || !handed->is_string()) bad(where, "'handedness' must be a string");
  const auto side = contracts::handedness_from_string(handed->get<std::string>());
  if (!side) bad(where, "'handedness' must be \"Left\" or \"Right\"");
  h.landmarks.handedness = *side;
  h.landmarks.score = number(doc, "score", where);
  const auto points = doc.find("landmarks");
  if (points == doc.end() || !points->is_array() || points->size() != contracts::kLandmarkCount) {
    bad(where, "'landmarks' must be an array of 21 [x, y, z]");
  }
  for (std::size_t i = 0; i < contracts::kLandmarkCount; ++i) {
    const auto& p = (*points)[i];
    if (!p.is_array() || p.size() < 2 || p.size() > 3 || !p[0].is_number() || !p[1].is_number() ||
        (p.size() == 3 && !p[2].is_number())) {
      bad(where, "landmark " + std::to_string(i) + " must be [x, y, z] numbers");
    }
    h.landmarks.points[i] = {p[0].get<double>(), p[1].get<double>(),
                             p.size() == 3 ? p[2].get<double>() : 0.0};
  }
  if (const auto g = doc.find("gesture"); g != doc.end()) {
    const auto type =
        g->is_string() ? contracts::gesture_from_string(g->get<std::string>()) : std::nullopt;
    if (!type) bad(where, "'gesture' must be a gesture name (NONE, OPEN_PALM, ...)");
    h.gesture = *type;
  }
  if (doc.contains("confidence")) h.confidence = number(doc, "confidence", where);
  return h;
}

}  // namespace

json to_json(const HandResult& hand) {
  json points = json::array();
  for (const auto& p : hand.landmarks.points) points.push_back({p.x, p.y, p.z});
  return {{"handedness", contracts::to_string(hand.landmarks.handedness)},
          {"score", hand.landmarks.score},
          {"landmarks", std::move(points)},
          {"gesture", contracts::to_string(hand.gesture)},
          {"confidence", hand.confidence}};
}

json frame_message(const FrameResult& r) {
  json hands = json::array();
  for (const auto& h : r.hands) hands.push_back(to_json(h));
  return {
      {"type", "frame"},
      {"frame_id", r.frame_id},
      {"capture_time", contracts::format_utc(r.capture_utc)},
      {"source", r.source},
      {"width", r.width},
      {"height", r.height},
      {"latency_ms", to_ms(r.latency)},
      {"hands", std::move(hands)},
      {"gesture_event", r.gesture_event ? contracts::to_json(*r.gesture_event) : json(nullptr)}};
}

json heartbeat_message(const PipelineMetrics& m, contracts::UtcTime now) {
  json stages = json::object();
  for (std::size_t i = 0; i < kStageCount; ++i) {
    const std::string name(to_string(static_cast<Stage>(i)));
    stages[name + "_ms_p50"] = m.stages[i].p50_ms;
    stages[name + "_ms_p95"] = m.stages[i].p95_ms;
  }
  stages["latency_ms_p50"] = m.latency.p50_ms;
  stages["latency_ms_p95"] = m.latency.p95_ms;
  constexpr Stage kQueueOwners[kQueueCount] = {Stage::kPreprocess, Stage::kLandmarks,
                                               Stage::kClassify};
  json queues = json::object();
  for (std::size_t i = 0; i < kQueueCount; ++i) {
    queues[std::string(to_string(kQueueOwners[i]))] = {{"depth", m.queues[i].depth},
                                                       {"capacity", m.queues[i].capacity},
                                                       {"dropped", m.queues[i].dropped}};
  }
  return {
      {"type", "heartbeat"},
      {"timestamp", contracts::format_utc(now)},
      {"source", m.source},
      {"healthy", m.healthy},
      {"reason", m.reason},
      {"running", m.running},
      {"fps", m.fps},
      {"frames",
       {{"captured", m.frames_captured}, {"done", m.frames_done}, {"dropped", m.frames_dropped}}},
      {"stages", std::move(stages)},
      {"queues", std::move(queues)}};
}

json to_json(const RecognizedImage& record) {
  json hands = json::array();
  for (const auto& h : record.hands) hands.push_back(to_json(h));
  return {{"image", record.image},
          {"frame", record.frame},
          {"width", record.width},
          {"height", record.height},
          {"hands", std::move(hands)}};
}

std::vector<RecognizedImage> recognized_from_json(const json& doc) {
  if (!doc.is_array())
    bad("recognition file", "must be a JSON array of {image, width, height, hands}");
  std::vector<RecognizedImage> out;
  for (std::size_t i = 0; i < doc.size(); ++i) {
    const auto& e = doc[i];
    std::string where = "entry " + std::to_string(i);
    if (!e.is_object()) bad(where, "must be an object");
    RecognizedImage r;
    const auto image = e.find("image");
    if (image == e.end() || !image->is_string()) bad(where, "'image' must be a string");
    r.image = image->get<std::string>();
    where += " (" + r.image + ")";
    if (const auto f = e.find("frame"); f != e.end()) {
      if (!f->is_number_integer()) bad(where, "'frame' must be an integer");
      r.frame = f->get<std::int64_t>();
    }
    r.width = static_cast<int>(number(e, "width", where));
    r.height = static_cast<int>(number(e, "height", where));
    if (r.width <= 0 || r.height <= 0) bad(where, "'width' and 'height' must be > 0");
    const auto hands = e.find("hands");
    if (hands == e.end() || !hands->is_array()) bad(where, "'hands' must be an array");
    for (std::size_t k = 0; k < hands->size(); ++k) {
      r.hands.push_back(hand_from_json((*hands)[k], where + " hand " + std::to_string(k)));
    }
    out.push_back(std::move(r));
  }
  return out;
}

}  // namespace gbdcs::vision
