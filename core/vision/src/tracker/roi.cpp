// The geometry of MediaPipe Hands; see roi.hpp for the conventions and the sources.
#include "gbdcs/vision/roi.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

namespace gbdcs::vision {

namespace {

double anchor_scale(double min_scale, double max_scale, std::size_t index, std::size_t count) {
  if (count == 1) return (min_scale + max_scale) * 0.5;
  return min_scale +
         (max_scale - min_scale) * static_cast<double>(index) / static_cast<double>(count - 1);
}

double sigmoid(double x) {
  return 1.0 / (1.0 + std::exp(-x));
}

}  // namespace

// ---- anchors --------------------------------------------------------------------------
std::vector<Anchor> generate_anchors(const AnchorOptions& o) {
  if (o.strides.empty() || o.input_width <= 0 || o.input_height <= 0) {
    throw std::invalid_argument("generate_anchors: need at least one stride and a positive size");
  }
  std::vector<Anchor> anchors;
  const std::size_t num_layers = o.strides.size();
  std::size_t layer = 0;
  while (layer < num_layers) {
    std::vector<double> widths;
    std::vector<double> heights;
    // Consecutive layers with the same stride share one feature map.
    std::size_t last = layer;
    while (last < num_layers && o.strides[last] == o.strides[layer]) {
      const double scale = anchor_scale(o.min_scale, o.max_scale, last, num_layers);
      for (double ratio : o.aspect_ratios) {
        widths.push_back(scale * std::sqrt(ratio));
        heights.push_back(scale / std::sqrt(ratio));
      }
      if (o.interpolated_scale_aspect_ratio > 0) {
        const double next = last + 1 == num_layers
                                ? 1.0
                                : anchor_scale(o.min_scale, o.max_scale, last + 1, num_layers);
        const double interpolated = std::sqrt(scale * next);
        widths.push_back(interpolated * std::sqrt(o.interpolated_scale_aspect_ratio));
        heights.push_back(interpolated / std::sqrt(o.interpolated_scale_aspect_ratio));
      }
      ++last;
    }
    const int stride = o.strides[layer];
    if (stride <= 0) throw std::invalid_argument("generate_anchors: strides must be positive");
    const int map_w = (o.input_width + stride - 1) / stride;
    const int map_h = (o.input_height + stride - 1) / stride;
    for (int y = 0; y < map_h; ++y) {
      for (int x = 0; x < map_w; ++x) {
        for (std::size_t k = 0; k < widths.size(); ++k) {
          Anchor a;
          a.x_center = (x + o.anchor_offset_x) / map_w;
          a.y_center = (y + o.anchor_offset_y) / map_h;
          a.width = o.fixed_anchor_size ? 1.0 : widths[k];
          a.height = o.fixed_anchor_size ? 1.0 : heights[k];
          anchors.push_back(a);
        }
      }
    }
    layer = last;
  }
  return anchors;
}

// ---- decoding and suppression ---------------------------------------------------------
std::vector<PalmDetection> decode_palm_tensors(std::span<const float> raw_boxes,
                                               std::span<const float> raw_scores,
                                               const std::vector<Anchor>& anchors,
                                               const DecodeOptions& o) {
  if (o.num_keypoints > kPalmKeypointCount ||
      o.keypoint_coord_offset + 2 * o.num_keypoints > o.num_coords ||
      o.box_coord_offset + 4 > o.num_coords) {
    throw std::invalid_argument(
        "decode_palm_tensors: num_coords too small for the box and keypoints");
  }
  if (raw_boxes.size() < o.num_boxes * o.num_coords || raw_scores.size() < o.num_boxes ||
      anchors.size() < o.num_boxes) {
    throw std::invalid_argument(
        "decode_palm_tensors: expected " + std::to_string(o.num_boxes) + " boxes x " +
        std::to_string(o.num_coords) + " values, scores and anchors; got " +
        std::to_string(raw_boxes.size()) + " values, " + std::to_string(raw_scores.size()) +
        " scores, " + std::to_string(anchors.size()) + " anchors");
  }
  std::vector<PalmDetection> out;
  const double clip = o.score_clipping_thresh;
  for (std::size_t i = 0; i < o.num_boxes; ++i) {
    const double raw = std::clamp(static_cast<double>(raw_scores[i]), -clip, clip);
    const double score = sigmoid(raw);
    if (!(score >= o.min_score_thresh)) continue;
    const Anchor& anchor = anchors[i];
    const float* v = raw_boxes.data() + i * o.num_coords;
    const std::size_t b = o.box_coord_offset;
    const double xc = v[b] / o.x_scale * anchor.width + anchor.x_center;
    const double yc = v[b + 1] / o.y_scale * anchor.height + anchor.y_center;
    const double w = v[b + 2] / o.w_scale * anchor.width;
    const double h = v[b + 3] / o.h_scale * anchor.height;
    if (!(w >= 0) || !(h >= 0)) continue;  // negative or NaN sizes (b/171391719)
    PalmDetection d;
    d.score = score;
    d.box = {xc - w / 2, yc - h / 2, w, h};
    for (std::size_t k = 0; k < o.num_keypoints; ++k) {
      const float* kp = v + o.keypoint_coord_offset + 2 * k;
      d.keypoints[k] = {kp[0] / o.x_scale * anchor.width + anchor.x_center,
                        kp[1] / o.y_scale * anchor.height + anchor.y_center};
    }
    out.push_back(d);
  }
  return out;
}

double intersection_over_union(const NormalizedBox& a, const NormalizedBox& b) {
  const double ix0 = std::max(a.xmin, b.xmin);
  const double iy0 = std::max(a.ymin, b.ymin);
  const double ix1 = std::min(a.xmin + a.width, b.xmin + b.width);
  const double iy1 = std::min(a.ymin + a.height, b.ymin + b.height);
  if (ix1 <= ix0 || iy1 <= iy0) return 0;
  const double inter = (ix1 - ix0) * (iy1 - iy0);
  const double uni = a.width * a.height + b.width * b.height - inter;
  return uni > 0 ? inter / uni : 0;
}

std::vector<PalmDetection> weighted_non_max_suppression(std::vector<PalmDetection> detections,
                                                        double min_suppression_threshold) {
  std::stable_sort(
      detections.begin(), detections.end(),
      [](const PalmDetection& l, const PalmDetection& r) { return l.score > r.score; });
  std::vector<PalmDetection> out;
  std::vector<PalmDetection> remaining = std::move(detections);
  while (!remaining.empty()) {
    const PalmDetection best = remaining.front();
    std::vector<PalmDetection> rest;
    double total = 0;
    double xmin = 0, ymin = 0, xmax = 0, ymax = 0;
    std::array<Point2, kPalmKeypointCount> kps{};
    for (const PalmDetection& d : remaining) {
      if (intersection_over_union(d.box, best.box) > min_suppression_threshold) {
        total += d.score;
        xmin += d.box.xmin * d.score;
        ymin += d.box.ymin * d.score;
        xmax += (d.box.xmin + d.box.width) * d.score;
        ymax += (d.box.ymin + d.box.height) * d.score;
        for (std::size_t k = 0; k < kPalmKeypointCount; ++k) {
          kps[k].x += d.keypoints[k].x * d.score;
          kps[k].y += d.keypoints[k].y * d.score;
        }
      } else {
        rest.push_back(d);
      }
    }
    PalmDetection merged = best;
    if (total > 0) {
      merged.box.xmin = xmin / total;
      merged.box.ymin = ymin / total;
      merged.box.width = xmax / total - merged.box.xmin;
      merged.box.height = ymax / total - merged.box.ymin;
      for (std::size_t k = 0; k < kPalmKeypointCount; ++k) {
        merged.keypoints[k] = {kps[k].x / total, kps[k].y / total};
      }
    }
    out.push_back(merged);
    // A zero-area best box overlaps nothing, not even itself: drop it so the loop ends.
    if (rest.size() == remaining.size()) rest.erase(rest.begin());
    remaining = std::move(rest);
  }
  return out;
}

// ---- letterbox ------------------------------------------------------------------------
LetterboxPadding letterbox_padding(int image_width, int image_height, int input_width,
                                   int input_height) {
  if (image_width <= 0 || image_height <= 0 || input_width <= 0 || input_height <= 0) {
    throw std::invalid_argument("letterbox_padding: sizes must be positive");
  }
  const double tensor_aspect = static_cast<double>(input_height) / input_width;
  const double image_aspect = static_cast<double>(image_height) / image_width;
  LetterboxPadding pad;
  if (tensor_aspect > image_aspect) {
    pad.top = pad.bottom = (1.0 - image_aspect / tensor_aspect) / 2.0;
  } else {
    pad.left = pad.right = (1.0 - tensor_aspect / image_aspect) / 2.0;
  }
  return pad;
}

RotatedRect letterbox_rect(int image_width, int image_height, int input_width, int input_height) {
  const LetterboxPadding pad =
      letterbox_padding(image_width, image_height, input_width, input_height);
  return {0.5, 0.5, 1.0 / (1.0 - pad.left - pad.right), 1.0 / (1.0 - pad.top - pad.bottom), 0.0};
}

Point2 remove_letterbox(const Point2& p, const LetterboxPadding& pad) {
  return {(p.x - pad.left) / (1.0 - pad.left - pad.right),
          (p.y - pad.top) / (1.0 - pad.top - pad.bottom)};
}

Point2 add_letterbox(const Point2& p, const LetterboxPadding& pad) {
  return {p.x * (1.0 - pad.left - pad.right) + pad.left,
          p.y * (1.0 - pad.top - pad.bottom) + pad.top};
}

PalmDetection remove_letterbox(const PalmDetection& d, const LetterboxPadding& pad) {
  PalmDetection out = d;
  const double sx = 1.0 - pad.left - pad.right;
  const double sy = 1.0 - pad.top - pad.bottom;
  out.box = {(d.box.xmin - pad.left) / sx, (d.box.ymin - pad.top) / sy, d.box.width / sx,
             d.box.height / sy};
  for (std::size_t k = 0; k < kPalmKeypointCount; ++k) {
    out.keypoints[k] = remove_letterbox(d.keypoints[k], pad);
  }
  return out;
}

// ---- ROIs -----------------------------------------------------------------------------
double normalize_radians(double angle) {
  constexpr double kPi = std::numbers::pi;
  return angle - 2 * kPi * std::floor((angle + kPi) / (2 * kPi));
}

double rotation_to_target(const Point2& from, const Point2& to, int image_width, int image_height,
                          double target_angle_rad) {
  const double x0 = from.x * image_width;
  const double y0 = from.y * image_height;
  const double x1 = to.x * image_width;
  const double y1 = to.y * image_height;
  return normalize_radians(target_angle_rad - std::atan2(-(y1 - y0), x1 - x0));
}

RotatedRect transform_rect(const RotatedRect& rect, int image_width, int image_height,
                           const RectTransform& t) {
  RotatedRect out = rect;
  double width = rect.width;
  double height = rect.height;
  const double c = std::cos(rect.rotation_rad);
  const double s = std::sin(rect.rotation_rad);
  const double w_px = image_width * width;
  const double h_px = image_height * height;
  out.center_x += (w_px * t.shift_x * c - h_px * t.shift_y * s) / image_width;
  out.center_y += (w_px * t.shift_x * s + h_px * t.shift_y * c) / image_height;
  if (t.square_long) {
    const double long_side = std::max(w_px, h_px);
    width = long_side / image_width;
    height = long_side / image_height;
  }
  out.width = width * t.scale_x;
  out.height = height * t.scale_y;
  return out;
}

RotatedRect detection_to_rect(const PalmDetection& d, int image_width, int image_height) {
  RotatedRect r;
  r.center_x = d.box.xmin + d.box.width / 2;
  r.center_y = d.box.ymin + d.box.height / 2;
  r.width = d.box.width;
  r.height = d.box.height;
  r.rotation_rad = rotation_to_target(d.keypoints[kPalmWrist], d.keypoints[kPalmMiddleMcp],
                                      image_width, image_height, std::numbers::pi / 2);
  return r;
}

RotatedRect palm_detection_to_roi(const PalmDetection& d, int image_width, int image_height) {
  return transform_rect(
      detection_to_rect(d, image_width, image_height), image_width, image_height,
      {.scale_x = 2.6, .scale_y = 2.6, .shift_x = 0, .shift_y = -0.5, .square_long = true});
}

RotatedRect landmarks_to_rect(const std::array<contracts::Point3, contracts::kLandmarkCount>& pts,
                              int image_width, int image_height) {
  using namespace contracts;
  static constexpr std::array<std::size_t, 12> kPartial = {
      kWrist,     kThumbCmc,  kThumbMcp, kThumbIp, kIndexMcp, kIndexPip,
      kMiddleMcp, kMiddlePip, kRingMcp,  kRingPip, kPinkyMcp, kPinkyPip};
  const Point2 wrist{pts[kWrist].x, pts[kWrist].y};
  // MediaPipe's kIndexFingerPIPJoint 4, kMiddleFingerPIPJoint 6, kRingFingerPIPJoint 8 index
  // the subset above: the index, middle and ring MCPs. The ROI turns with the palm.
  const Point2 mcp_mean{((pts[kIndexMcp].x + pts[kRingMcp].x) / 2 + pts[kMiddleMcp].x) / 2,
                        ((pts[kIndexMcp].y + pts[kRingMcp].y) / 2 + pts[kMiddleMcp].y) / 2};
  const double rotation =
      rotation_to_target(wrist, mcp_mean, image_width, image_height, std::numbers::pi / 2);
  const double reverse = normalize_radians(-rotation);

  double min_x = std::numeric_limits<double>::max(), max_x = std::numeric_limits<double>::lowest();
  double min_y = min_x, max_y = max_x;
  for (std::size_t i : kPartial) {
    min_x = std::min(min_x, pts[i].x);
    max_x = std::max(max_x, pts[i].x);
    min_y = std::min(min_y, pts[i].y);
    max_y = std::max(max_y, pts[i].y);
  }
  const double aligned_cx = (min_x + max_x) / 2;
  const double aligned_cy = (min_y + max_y) / 2;

  // The box of the landmarks in the hand's own (rotated) frame, in pixels.
  min_x = min_y = std::numeric_limits<double>::max();
  max_x = max_y = std::numeric_limits<double>::lowest();
  const double cr = std::cos(reverse), sr = std::sin(reverse);
  for (std::size_t i : kPartial) {
    const double x = (pts[i].x - aligned_cx) * image_width;
    const double y = (pts[i].y - aligned_cy) * image_height;
    const double px = x * cr - y * sr;
    const double py = x * sr + y * cr;
    min_x = std::min(min_x, px);
    max_x = std::max(max_x, px);
    min_y = std::min(min_y, py);
    max_y = std::max(max_y, py);
  }
  const double pcx = (min_x + max_x) / 2;
  const double pcy = (min_y + max_y) / 2;
  const double c = std::cos(rotation), s = std::sin(rotation);
  RotatedRect r;
  r.center_x = (pcx * c - pcy * s + image_width * aligned_cx) / image_width;
  r.center_y = (pcx * s + pcy * c + image_height * aligned_cy) / image_height;
  r.width = (max_x - min_x) / image_width;
  r.height = (max_y - min_y) / image_height;
  r.rotation_rad = rotation;
  return r;
}

RotatedRect landmarks_to_roi(const std::array<contracts::Point3, contracts::kLandmarkCount>& pts,
                             int image_width, int image_height) {
  return transform_rect(
      landmarks_to_rect(pts, image_width, image_height), image_width, image_height,
      {.scale_x = 2.0, .scale_y = 2.0, .shift_x = 0, .shift_y = -0.1, .square_long = true});
}

double rect_iou(const RotatedRect& a, const RotatedRect& b) {
  return intersection_over_union(
      {a.center_x - a.width / 2, a.center_y - a.height / 2, a.width, a.height},
      {b.center_x - b.width / 2, b.center_y - b.height / 2, b.width, b.height});
}

bool roi_is_usable(const RotatedRect& roi, int image_width, int image_height) {
  return std::isfinite(roi.center_x) && std::isfinite(roi.center_y) &&
         std::isfinite(roi.rotation_rad) && std::isfinite(roi.width) &&
         std::isfinite(roi.height) && roi.width * image_width >= kMinRoiPixels &&
         roi.height * image_height >= kMinRoiPixels;
}

// ---- crop geometry --------------------------------------------------------------------
Point2 apply(const Affine2D& m, const Point2& p) {
  return {m.a * p.x + m.b * p.y + m.c, m.d * p.x + m.e * p.y + m.f};
}

Affine2D invert(const Affine2D& m) {
  const double det = m.a * m.e - m.b * m.d;
  if (!(std::abs(det) > 1e-300)) throw std::invalid_argument("invert: singular affine transform");
  Affine2D r;
  r.a = m.e / det;
  r.b = -m.b / det;
  r.d = -m.d / det;
  r.e = m.a / det;
  r.c = -(r.a * m.c + r.b * m.f);
  r.f = -(r.d * m.c + r.e * m.f);
  return r;
}

Affine2D crop_to_image_transform(const RotatedRect& rect, int image_width, int image_height,
                                 int crop_width, int crop_height) {
  const double cx = rect.center_x * image_width;
  const double cy = rect.center_y * image_height;
  const double w = rect.width * image_width;
  const double h = rect.height * image_height;
  const double c = std::cos(rect.rotation_rad);
  const double s = std::sin(rect.rotation_rad);
  // crop (u, v) → rect-relative (u / cw - 0.5) * w, (v / ch - 0.5) * h → rotated → + centre.
  Affine2D m;
  m.a = c * w / crop_width;
  m.b = -s * h / crop_height;
  m.c = cx - c * w / 2 + s * h / 2;
  m.d = s * w / crop_width;
  m.e = c * h / crop_height;
  m.f = cy - s * w / 2 - c * h / 2;
  return m;
}

contracts::Point3 project_from_rect(const contracts::Point3& p, const RotatedRect& rect) {
  const double x = p.x - 0.5;
  const double y = p.y - 0.5;
  const double c = std::cos(rect.rotation_rad);
  const double s = std::sin(rect.rotation_rad);
  return {(c * x - s * y) * rect.width + rect.center_x,
          (s * x + c * y) * rect.height + rect.center_y, p.z * rect.width};
}

contracts::Point3 project_to_rect(const contracts::Point3& p, const RotatedRect& rect) {
  const double u = (p.x - rect.center_x) / rect.width;
  const double v = (p.y - rect.center_y) / rect.height;
  const double c = std::cos(rect.rotation_rad);
  const double s = std::sin(rect.rotation_rad);
  return {c * u + s * v + 0.5, -s * u + c * v + 0.5, p.z / rect.width};
}

}  // namespace gbdcs::vision
