#include "eval_tally.hpp"

#include <cmath>
#include <iomanip>
#include <iostream>
#include <optional>
#include <sstream>

namespace gbdcs::app {

using nlohmann::json;

std::size_t class_index(contracts::GestureType g) {
  for (std::size_t i = 0; i < kClasses; ++i)
    if (contracts::kAllGestures[i] == g) return i;
  return 0;
}

namespace {

std::optional<double> ratio(std::int64_t a, std::int64_t b) {
  if (b == 0) return std::nullopt;
  return static_cast<double>(a) / static_cast<double>(b);
}

json opt(const std::optional<double>& v) { return v ? json(*v) : json(nullptr); }

}  // namespace

json summary_json(const Tally& t) {
  json per_class = json::object();
  for (std::size_t c = 0; c < kClasses; ++c) {
    std::int64_t tp = t.confusion[c][c], predicted = 0, actual = 0;
    for (std::size_t o = 0; o < kClasses; ++o) {
      predicted += t.confusion[o][c];
      actual += t.confusion[c][o];
    }
    if (predicted == 0 && actual == 0) continue;
    per_class[std::string(contracts::to_string(contracts::kAllGestures[c]))] = {
        {"precision", opt(ratio(tp, predicted))},
        {"recall", opt(ratio(tp, actual))},
        {"support_frames", actual},
        {"predicted_frames", predicted}};
  }
  json labels = json::array();
  json matrix = json::array();
  for (std::size_t c = 0; c < kClasses; ++c) {
    labels.push_back(contracts::to_string(contracts::kAllGestures[c]));
    matrix.push_back(t.confusion[c]);
  }
  json by_point = json::array();
  if (const auto errors = t.offsets.error_pct_by_point()) {
    for (double v : *errors) by_point.push_back(v);
  } else {
    by_point = json(std::vector<json>(contracts::kLandmarkCount, nullptr));
  }
  json offset_by_point = nullptr;
  if (const auto mean = t.offsets.mean_offsets()) {
    offset_by_point = json::array();
    for (const auto& m : *mean) offset_by_point.push_back({m.along_pct, m.across_pct});
  }
  const auto without_offsets = t.offsets.error_pct_without_offsets();
  return {{"accuracy", opt(ratio(t.correct(), t.scored()))},
          {"landmark_error_pct_by_point", by_point},
          {"landmark_offset_pct_by_point", offset_by_point},
          {"landmark_error_pct_mean_without_offsets", opt(without_offsets)},
          {"deliberate_accuracy", opt(ratio(t.reads.deliberate_correct, t.reads.deliberate_scored))},
          {"false_positive_rate", opt(ratio(t.reads.false_positives, t.reads.non_deliberate_scored))},
          {"detection_rate", opt(ratio(t.detected_frames, t.visible_frames))},
          {"truth_deliberate_accuracy",
           opt(ratio(t.truth_reads.deliberate_correct, t.truth_reads.deliberate_scored))},
          {"truth_false_positive_rate",
           opt(ratio(t.truth_reads.false_positives, t.truth_reads.non_deliberate_scored))},
          {"landmark_error_pct_mean", opt(t.offsets.error_pct())},
          {"landmark_error_pct_max",
           t.offsets.hands() > 0 ? json(t.landmark_error_max_pct) : json(nullptr)},
          {"frames_scored", t.scored()},
          {"deliberate_frames", t.reads.deliberate_scored},
          {"non_deliberate_frames", t.reads.non_deliberate_scored},
          {"false_positive_frames", t.reads.false_positives},
          {"visible_frames", t.visible_frames},
          {"detected_frames", t.detected_frames},
          {"per_class", per_class},
          {"by_pose", t.by_pose},
          {"confusion", {{"labels", labels}, {"matrix", matrix}}}};
}

namespace {

std::string fmt_pct(const json& v) {
  if (v.is_null()) return "-";
  std::ostringstream s;
  s << std::fixed << std::setprecision(2) << 100 * v.get<double>() << " %";
  return s.str();
}

}  // namespace

void print_summary(const std::string& title, const json& s) {
  std::cout << title << "\n"
            << "  detection rate      " << fmt_pct(s["detection_rate"]) << " ("
            << s["detected_frames"] << " of " << s["visible_frames"] << " fully visible)\n"
            << "  landmark error      ";
  if (s["landmark_error_pct_mean"].is_null()) {
    std::cout << "- (no ground truth)\n";
  } else {
    std::cout << std::fixed << std::setprecision(2) << s["landmark_error_pct_mean"].get<double>()
              << " % of hand size mean, " << s["landmark_error_pct_max"].get<double>()
              << " % worst\n";
    if (!s["landmark_error_pct_mean_without_offsets"].is_null()) {
      // The landmark shifted furthest on average, and the error the scatter alone makes.
      std::size_t far = 0;
      double far_pct = -1;
      const auto& by_point = s["landmark_offset_pct_by_point"];
      for (std::size_t k = 0; k < by_point.size(); ++k) {
        const double d = std::hypot(by_point[k][0].get<double>(), by_point[k][1].get<double>());
        if (d > far_pct) {
          far = k;
          far_pct = d;
        }
      }
      std::cout << "    without offsets   " << std::setprecision(2)
                << s["landmark_error_pct_mean_without_offsets"].get<double>()
                << " % (each landmark's mean shift taken away; the largest, landmark " << far
                << ", " << by_point[far][0].get<double>() << " % along its bone, "
                << by_point[far][1].get<double>() << " % across)\n";
    }
  }
  std::cout << "  accuracy            " << fmt_pct(s["accuracy"]) << " of " << s["frames_scored"]
            << " frames\n"
            << "  deliberate accuracy " << fmt_pct(s["deliberate_accuracy"]) << " of "
            << s["deliberate_frames"] << "\n"
            << "  false positives     " << fmt_pct(s["false_positive_rate"]) << " ("
            << s["false_positive_frames"] << " of " << s["non_deliberate_frames"]
            << " non-deliberate)\n";
  if (!s["truth_deliberate_accuracy"].is_null() || !s["truth_false_positive_rate"].is_null()) {
    std::cout << "  on true landmarks   " << fmt_pct(s["truth_deliberate_accuracy"])
              << " deliberate accuracy, " << fmt_pct(s["truth_false_positive_rate"])
              << " false positives (the recogniser alone)\n";
  }
}

void print_classes(const json& s) {
  std::cout << "\n  " << std::left << std::setw(12) << "class" << std::right << std::setw(11)
            << "precision" << std::setw(10) << "recall" << std::setw(9) << "frames\n";
  for (const auto& [name, c] : s["per_class"].items()) {
    std::cout << "  " << std::left << std::setw(12) << name << std::right << std::setw(11)
              << fmt_pct(c["precision"]) << std::setw(10) << fmt_pct(c["recall"]) << std::setw(8)
              << c["support_frames"].get<long>() << "\n";  // json's << reads setw as indent
  }
  std::cout << "\n  confusion (rows: truth, columns: predicted)\n  " << std::setw(12) << "";
  const auto& labels = s["confusion"]["labels"];
  const auto& matrix = s["confusion"]["matrix"];
  for (const auto& l : labels) std::cout << std::setw(6) << l.get<std::string>().substr(0, 5);
  std::cout << "\n";
  for (std::size_t r = 0; r < labels.size(); ++r) {
    std::int64_t row_total = 0;
    for (const auto& v : matrix[r]) row_total += v.get<std::int64_t>();
    if (row_total == 0) continue;
    std::cout << "  " << std::left << std::setw(12) << labels[r].get<std::string>() << std::right;
    for (const auto& v : matrix[r]) std::cout << std::setw(6) << v.get<std::int64_t>();
    std::cout << "\n";
  }
}

}  // namespace gbdcs::app
