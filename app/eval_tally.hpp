// The tallies of `gbdcs eval` (eval_command.cpp): frames scored per class and per shown pose,
// detection and landmark error, their JSON summary and the terminal table.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include "gbdcs/contracts/messages.hpp"
#include "gbdcs/sim/landmark_offsets.hpp"

namespace gbdcs::app {

constexpr std::size_t kClasses = contracts::kAllGestures.size();

std::size_t class_index(contracts::GestureType g);

// Scored frames and how they were read: deliberate ones read as shown, non-deliberate ones
// read as any gesture (a false positive).
struct Reads {
  std::int64_t deliberate_scored = 0;
  std::int64_t deliberate_correct = 0;
  std::int64_t non_deliberate_scored = 0;
  std::int64_t false_positives = 0;

  void score(contracts::GestureType truth, contracts::GestureType read, bool deliberate) {
    if (deliberate) {
      ++deliberate_scored;
      if (read == truth) ++deliberate_correct;
    } else {
      ++non_deliberate_scored;
      if (read != contracts::GestureType::kNone) ++false_positives;
    }
  }
  void add(const Reads& o) {
    deliberate_scored += o.deliberate_scored;
    deliberate_correct += o.deliberate_correct;
    non_deliberate_scored += o.non_deliberate_scored;
    false_positives += o.false_positives;
  }
};

struct Tally {
  std::int64_t visible_frames = 0;   // hand fully visible (rendered) or expected (photos)
  std::int64_t detected_frames = 0;  // ... where the tracker found it
  Reads reads;  // what the tracker and recogniser read
  // The recogniser on the true landmarks of the same scored frames (rendered fixtures): what
  // the tracker could reach at best; below 1 means the pose or its label is at fault.
  Reads truth_reads;
  double landmark_error_max_pct = 0;  // the worst matched hand's mean landmark error
  // Every matched hand's landmarks against the truth, in their bones' axes: the landmark error
  // (mean, per landmark) and how much of it is a shift every frame shares (a labelling
  // convention, or the model's bias on the picture) and how much scatter.
  sim::LandmarkOffsets offsets;
  std::array<std::array<std::int64_t, kClasses>, kClasses> confusion{};  // [true][predicted]
  // Scored frames per shown pose (rendered fixtures: FIST, RELAXED, ...; "NO_HAND"), by the
  // gesture read: which poses the recogniser confuses, not only which gestures.
  std::map<std::string, std::map<std::string, std::int64_t>> by_pose;

  void add(const Tally& o) {
    for (const auto& [pose, counts] : o.by_pose)
      for (const auto& [g, n] : counts) by_pose[pose][g] += n;
    visible_frames += o.visible_frames;
    detected_frames += o.detected_frames;
    reads.add(o.reads);
    truth_reads.add(o.truth_reads);
    landmark_error_max_pct = std::max(landmark_error_max_pct, o.landmark_error_max_pct);
    offsets.add(o.offsets);
    for (std::size_t t = 0; t < kClasses; ++t)
      for (std::size_t p = 0; p < kClasses; ++p) confusion[t][p] += o.confusion[t][p];
  }
  void score(contracts::GestureType truth, contracts::GestureType predicted, bool deliberate) {
    confusion[class_index(truth)][class_index(predicted)]++;
    reads.score(truth, predicted, deliberate);
  }
  std::int64_t scored() const { return reads.deliberate_scored + reads.non_deliberate_scored; }
  std::int64_t correct() const {
    std::int64_t c = 0;
    for (std::size_t i = 0; i < kClasses; ++i) c += confusion[i][i];
    return c;
  }
};

// The summary `eval --json` prints: accuracy, false-positive and detection rates, landmark
// error, per-class precision and recall, the confusion matrix and the reads per pose.
nlohmann::json summary_json(const Tally& t);

// The same summary as a table on stdout.
void print_summary(const std::string& title, const nlohmann::json& s);
void print_classes(const nlohmann::json& s);

}  // namespace gbdcs::app
