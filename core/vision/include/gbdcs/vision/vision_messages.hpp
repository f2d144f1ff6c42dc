// The JSON the vision commands write and read back.
//
// Worker messages (`gbdcs vision`, one JSON object a line; schemas in core/contracts/schemas/)
//   frame_message      {"type": "frame", frame_id, capture_time (UTC), source, width, height,
//                       latency_ms, hands: [hand], gesture_event: GestureEvent | null}
//                      -> vision_frame.schema.json
//   heartbeat_message  {"type": "heartbeat", timestamp, source, healthy, reason, running, fps,
//                       frames: {captured, done, dropped},
//                       stages: {capture_ms_p50, capture_ms_p95, ..., classify_ms_p95,
//                                latency_ms_p50, latency_ms_p95},
//                       queues: {preprocess|landmarks|classify: {depth, capacity, dropped}}}
//                      -> vision_heartbeat.schema.json
//   hand               {handedness, score, landmarks: [[x, y, z] x 21], gesture, confidence}
//
// Recognition records (`gbdcs recognize --json`: a JSON array of these; the MediaPipe reference
// tool writes the same shape without frame, gesture and confidence)
//   {"image", "frame", "width", "height", "hands": [hand]}
//
// Landmark comparison (`gbdcs eval landmarks OURS REF`)
//   Images are matched by file basename (and frame); hands within an image by the distance
//   between their landmark centroids (greedy, nearest first; a pair further apart than the
//   reference hand's bounding-box diagonal is two different hands). For a matched pair the
//   distance of each landmark is the image-plane (x, y) distance in pixels of the reference
//   image, as a percentage of the reference hand's bounding-box diagonal; z is not compared
//   (its scale is the model's own).
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "gbdcs/contracts/clock.hpp"
#include "gbdcs/vision/vision_pipeline.hpp"

namespace gbdcs::vision {

nlohmann::json to_json(const HandResult& hand);
nlohmann::json frame_message(const FrameResult& result);
nlohmann::json heartbeat_message(const PipelineMetrics& metrics, contracts::UtcTime now);

// ---- recognition records ------------------------------------------------------------------
struct RecognizedImage {
  std::string image;
  std::int64_t frame = 0;
  int width = 0;
  int height = 0;
  std::vector<HandResult> hands;  // gesture NONE / confidence 0 when the file has none
};

nlohmann::json to_json(const RecognizedImage& record);
// Reads an array of records (ours or the reference's). Throws std::invalid_argument naming the
// entry and the field that is wrong.
std::vector<RecognizedImage> recognized_from_json(const nlohmann::json& doc);

// ---- landmark comparison ------------------------------------------------------------------
struct HandMatch {
  std::size_t ours = 0;  // index in the image's hands
  std::size_t ref = 0;
  double mean_distance_pct = 0;  // mean over the 21 landmarks, % of the ref bbox diagonal
  double max_distance_pct = 0;   // worst landmark
  bool handedness_agrees = true;
};

struct ImageComparison {
  std::string image;  // basename (with "#frame" for frames after the first)
  std::size_t hands_ours = 0;
  std::size_t hands_ref = 0;
  std::vector<HandMatch> matches;
  std::optional<double> mean_distance_pct;  // over the matched hands; none if no match
  bool detection_agrees = true;             // every hand in each file is matched in the other
};

struct LandmarkComparison {
  std::vector<ImageComparison> images;  // images present in both files, in the ref's order
  std::vector<std::string> only_in_ours;
  std::vector<std::string> only_in_ref;
  std::size_t hands_matched = 0;
  std::size_t hands_only_ours = 0;  // found by us, not by the reference (false positives)
  std::size_t hands_only_ref = 0;   // missed by us
  std::size_t images_detection_agree = 0;
  std::optional<double> mean_distance_pct;          // mean over matched hands of their mean
  std::optional<double> max_distance_pct;           // worst matched hand's mean
  std::optional<double> max_landmark_distance_pct;  // worst single landmark
};

LandmarkComparison compare_landmarks(const std::vector<RecognizedImage>& ours,
                                     const std::vector<RecognizedImage>& ref);
nlohmann::json to_json(const LandmarkComparison& comparison);

// Mean and max image-plane distance between two hands' landmarks, % of the ref bbox diagonal
// in pixels of a width x height image. Exposed for tests.
std::pair<double, double> landmark_distance_pct(const contracts::Landmarks& ours,
                                                const contracts::Landmarks& ref, int width,
                                                int height);

}  // namespace gbdcs::vision
