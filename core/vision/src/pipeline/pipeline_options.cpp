// PipelineOptions from JSON, the stage names, and the per-frame HandClassifier.
#include <cmath>
#include <nlohmann/json.hpp>

#include "gbdcs/contracts/json_options.hpp"
#include "gbdcs/vision/vision_pipeline.hpp"

namespace gbdcs::vision {
namespace {
constexpr const char* kOwner = "PipelineOptions";
}

std::string_view to_string(Stage s) {
  switch (s) {
    case Stage::kCapture:
      return "capture";
    case Stage::kPreprocess:
      return "preprocess";
    case Stage::kLandmarks:
      return "landmarks";
    case Stage::kClassify:
      return "classify";
  }
  return "?";
}

PipelineOptions pipeline_options_from_json(const nlohmann::json& doc) {
  PipelineOptions o;
  if (!doc.is_object())
    throw std::invalid_argument(std::string(kOwner) + ": must be a JSON object");
  // The reader knows numbers; the string and the nested objects are taken here.
  nlohmann::json numbers = doc;
  contracts::JsonOptionReader reader(numbers, kOwner);
  if (auto it = doc.find("policy"); it != doc.end()) {
    const std::string p = it->is_string() ? it->get<std::string>() : "";
    if (p == "drop_oldest") {
      o.policy = OverflowPolicy::kDropOldest;
    } else if (p == "block") {
      o.policy = OverflowPolicy::kBlock;
    } else if (p != "auto") {
      reader.fail("policy", "must be \"auto\", \"drop_oldest\" or \"block\"");
    }
    numbers.erase("policy");
  }
  if (auto it = doc.find("engine"); it != doc.end()) {
    o.engine = gesture::gesture_engine_options_from_json(*it);
    numbers.erase("engine");
  }
  if (auto it = doc.find("recognizer"); it != doc.end()) {
    o.recognizer = gesture::rule_based_options_from_json(*it);
    numbers.erase("recognizer");
  }
  reader.read("queue_capacity", o.queue_capacity);
  reader.read("resize_width", o.resize_width);
  reader.read("resize_height", o.resize_height);
  reader.read("stall_timeout_s", o.stall_timeout_s);
  reader.read("timing_window", o.timing_window);
  reader.finish();
  validate(o);
  return o;
}

void validate(const PipelineOptions& o) {
  using contracts::require;
  require(o.queue_capacity >= 1 && o.queue_capacity <= 1000, kOwner, "queue_capacity",
          "must be in [1, 1000] frames");
  require(o.resize_width >= 0 && o.resize_width <= 8192, kOwner, "resize_width",
          "must be in [0, 8192] px (0 = keep)");
  require(o.resize_height >= 0 && o.resize_height <= 8192, kOwner, "resize_height",
          "must be in [0, 8192] px (0 = keep)");
  require(std::isfinite(o.stall_timeout_s) && o.stall_timeout_s > 0, kOwner, "stall_timeout_s",
          "must be a finite number of seconds > 0");
  require(o.timing_window >= 1 && o.timing_window <= 100000, kOwner, "timing_window",
          "must be in [1, 100000] samples");
  gesture::validate(o.engine);
  gesture::validate(o.recognizer);
}

HandClassifier::HandClassifier(gesture::RuleBasedOptions options)
    : options_(options), recognizer_(options) {}

void HandClassifier::set_frame_size(int width_px, int height_px) {
  if (width_px <= 0 || height_px <= 0) return;
  const double aspect = static_cast<double>(width_px) / height_px;
  if (aspect == options_.aspect_ratio) return;
  options_.aspect_ratio = aspect;
  recognizer_ = gesture::RuleBasedRecognizer(options_);
}

gesture::Recognition HandClassifier::recognize(const contracts::Landmarks& hand) const {
  return recognizer_.recognize(hand);
}

std::vector<HandResult> HandClassifier::classify(
    const std::vector<contracts::Landmarks>& hands) const {
  std::vector<HandResult> out;
  out.reserve(hands.size());
  for (const auto& hand : hands) {
    const auto r = recognizer_.recognize(hand);
    out.push_back({hand, r.gesture, r.confidence});
  }
  return out;
}

}  // namespace gbdcs::vision
