// Our landmarks against a reference's: images by basename, hands by position.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>

#include "gbdcs/vision/vision_messages.hpp"

namespace gbdcs::vision {
namespace {

using nlohmann::json;

std::string key_of(const RecognizedImage& r) {
  std::string key = std::filesystem::path(r.image).filename().string();
  if (r.frame != 0) key += "#" + std::to_string(r.frame);
  return key;
}

struct Pixel {
  double x = 0;
  double y = 0;
};

Pixel centroid(const contracts::Landmarks& h, int w, int hgt) {
  Pixel c;
  for (const auto& p : h.points) {
    c.x += p.x * w;
    c.y += p.y * hgt;
  }
  c.x /= contracts::kLandmarkCount;
  c.y /= contracts::kLandmarkCount;
  return c;
}

double bbox_diagonal(const contracts::Landmarks& h, int w, int hgt) {
  double x0 = std::numeric_limits<double>::max(), y0 = x0;
  double x1 = std::numeric_limits<double>::lowest(), y1 = x1;
  for (const auto& p : h.points) {
    x0 = std::min(x0, p.x * w);
    x1 = std::max(x1, p.x * w);
    y0 = std::min(y0, p.y * hgt);
    y1 = std::max(y1, p.y * hgt);
  }
  return std::hypot(x1 - x0, y1 - y0);
}

ImageComparison compare_image(const RecognizedImage& ours, const RecognizedImage& ref) {
  ImageComparison c;
  c.image = key_of(ref);
  c.hands_ours = ours.hands.size();
  c.hands_ref = ref.hands.size();
  const int w = ref.width;
  const int h = ref.height;
  struct Candidate {
    double distance;
    std::size_t ours;
    std::size_t ref;
  };
  std::vector<Candidate> candidates;
  for (std::size_t i = 0; i < ours.hands.size(); ++i) {
    for (std::size_t j = 0; j < ref.hands.size(); ++j) {
      const auto a = centroid(ours.hands[i].landmarks, w, h);
      const auto b = centroid(ref.hands[j].landmarks, w, h);
      const double d = std::hypot(a.x - b.x, a.y - b.y);
      if (d <= bbox_diagonal(ref.hands[j].landmarks, w, h)) candidates.push_back({d, i, j});
    }
  }
  std::sort(candidates.begin(), candidates.end(),
            [](const Candidate& a, const Candidate& b) { return a.distance < b.distance; });
  std::vector<bool> ours_used(ours.hands.size()), ref_used(ref.hands.size());
  double sum = 0;
  for (const auto& cand : candidates) {
    if (ours_used[cand.ours] || ref_used[cand.ref]) continue;
    ours_used[cand.ours] = ref_used[cand.ref] = true;
    const auto& a = ours.hands[cand.ours].landmarks;
    const auto& b = ref.hands[cand.ref].landmarks;
    const auto [mean, max] = landmark_distance_pct(a, b, w, h);
    c.matches.push_back({cand.ours, cand.ref, mean, max, a.handedness == b.handedness});
    sum += mean;
  }
  if (!c.matches.empty()) c.mean_distance_pct = sum / static_cast<double>(c.matches.size());
  c.detection_agrees = c.matches.size() == c.hands_ours && c.matches.size() == c.hands_ref;
  return c;
}

json optional_number(const std::optional<double>& v) {
  return v ? json(*v) : json(nullptr);
}

}  // namespace

std::pair<double, double> landmark_distance_pct(const contracts::Landmarks& ours,
                                                const contracts::Landmarks& ref, int width,
                                                int height) {
  const double diagonal = bbox_diagonal(ref, width, height);
  if (!(diagonal > 0))
    return {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  double sum = 0;
  double max = 0;
  for (std::size_t k = 0; k < contracts::kLandmarkCount; ++k) {
    const double dx = (ours.points[k].x - ref.points[k].x) * width;
    const double dy = (ours.points[k].y - ref.points[k].y) * height;
    const double d = std::hypot(dx, dy);
    sum += d;
    max = std::max(max, d);
  }
  return {100 * sum / contracts::kLandmarkCount / diagonal, 100 * max / diagonal};
}

LandmarkComparison compare_landmarks(const std::vector<RecognizedImage>& ours,
                                     const std::vector<RecognizedImage>& ref) {
  LandmarkComparison out;
  std::map<std::string, const RecognizedImage*> ours_by_key;
  for (const auto& r : ours) ours_by_key.emplace(key_of(r), &r);
  std::map<std::string, bool> ref_keys;
  double sum = 0;
  for (const auto& r : ref) {
    const auto key = key_of(r);
    ref_keys[key] = true;
    const auto it = ours_by_key.find(key);
    if (it == ours_by_key.end()) {
      out.only_in_ref.push_back(key);
      continue;
    }
    auto c = compare_image(*it->second, r);
    out.hands_matched += c.matches.size();
    out.hands_only_ours += c.hands_ours - c.matches.size();
    out.hands_only_ref += c.hands_ref - c.matches.size();
    if (c.detection_agrees) ++out.images_detection_agree;
    for (const auto& m : c.matches) {
      sum += m.mean_distance_pct;
      out.max_distance_pct = std::max(out.max_distance_pct.value_or(0), m.mean_distance_pct);
      out.max_landmark_distance_pct =
          std::max(out.max_landmark_distance_pct.value_or(0), m.max_distance_pct);
    }
    out.images.push_back(std::move(c));
  }
  for (const auto& [key, record] : ours_by_key) {
    if (!ref_keys.contains(key)) out.only_in_ours.push_back(key);
  }
  if (out.hands_matched > 0) out.mean_distance_pct = sum / static_cast<double>(out.hands_matched);
  return out;
}

json to_json(const LandmarkComparison& c) {
  json images = json::array();
  for (const auto& i : c.images) {
    json matches = json::array();
    for (const auto& m : i.matches) {
      matches.push_back({{"ours", m.ours},
                         {"ref", m.ref},
                         {"mean_distance_pct", m.mean_distance_pct},
                         {"max_distance_pct", m.max_distance_pct},
                         {"handedness_agrees", m.handedness_agrees}});
    }
    images.push_back({{"image", i.image},
                      {"hands_ours", i.hands_ours},
                      {"hands_ref", i.hands_ref},
                      {"detection_agrees", i.detection_agrees},
                      {"mean_distance_pct", optional_number(i.mean_distance_pct)},
                      {"matches", std::move(matches)}});
  }
  return {{"images", std::move(images)},
          {"images_compared", c.images.size()},
          {"images_detection_agree", c.images_detection_agree},
          {"only_in_ours", c.only_in_ours},
          {"only_in_ref", c.only_in_ref},
          {"hands_matched", c.hands_matched},
          {"hands_only_ours", c.hands_only_ours},
          {"hands_only_ref", c.hands_only_ref},
          {"mean_distance_pct", optional_number(c.mean_distance_pct)},
          {"max_distance_pct", optional_number(c.max_distance_pct)},
          {"max_landmark_distance_pct", optional_number(c.max_landmark_distance_pct)}};
}

}  // namespace gbdcs::vision
