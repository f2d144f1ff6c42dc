// The geometry of MediaPipe Hands, as pure functions: SSD anchors, palm tensor decoding,
// weighted non-max suppression, detection → hand ROI, landmarks → next ROI, the affine map
// between an image and a model crop, and letterbox padding. No I/O, no OpenCV, no model:
// every function is checked on synthetic numbers in tests/vision/tracker_roi_test.cpp.
//
// Conventions (MediaPipe's)
//   Normalised coordinates: x right, y down, [0, 1] over the image width / height.
//   RotatedRect: centre, width, height normalised to the image; rotation in radians,
//     clockwise on screen (y down), applied about the centre. A rect that is square in pixels
//     has width * image_width == height * image_height.
//   Pixel coordinates are continuous: pixel (i, j) covers [i, i+1) x [j, j+1), its centre is
//     (i + 0.5, j + 0.5). The crop maps its pixel centres onto the rect the same way, so a
//     crop of a rect covering the whole image is exactly a resize.
// Sources (mediapipe/modules/palm_detection/palm_detection_cpu.pbtxt,
//   hand_landmark/palm_detection_detection_to_roi.pbtxt, hand_landmark_landmarks_to_roi.pbtxt
//   and the calculators they name): SsdAnchorsCalculator, TensorsToDetectionsCalculator,
//   NonMaxSuppressionCalculator (WEIGHTED), DetectionLetterboxRemovalCalculator,
//   DetectionsToRectsCalculator, RectTransformationCalculator, HandLandmarksToRectCalculator,
//   LandmarkProjectionCalculator, ImageToTensorCalculator (PadRoi, keep_aspect_ratio).
#pragma once

#include <array>
#include <cstddef>
#include <span>
#include <vector>

#include "gbdcs/contracts/messages.hpp"

namespace gbdcs::vision {

struct Point2 {
  double x = 0;
  double y = 0;
};

struct RotatedRect {
  double center_x = 0;  // normalised to the image
  double center_y = 0;
  double width = 0;
  double height = 0;
  double rotation_rad = 0;
};

// ---- palm detection: anchors, decoding, suppression ------------------------------------
struct Anchor {
  double x_center = 0;  // normalised to the model input
  double y_center = 0;
  double width = 0;
  double height = 0;
};

// SsdAnchorsCalculator options; the defaults are palm_detection_{lite,full}'s.
struct AnchorOptions {
  int input_width = 192;
  int input_height = 192;
  double min_scale = 0.1484375;
  double max_scale = 0.75;
  double anchor_offset_x = 0.5;
  double anchor_offset_y = 0.5;
  std::vector<int> strides = {8, 16, 16, 16};  // one per layer; num_layers = strides.size()
  std::vector<double> aspect_ratios = {1.0};
  double interpolated_scale_aspect_ratio = 1.0;  // > 0 adds one anchor per layer
  bool fixed_anchor_size = true;                 // width = height = 1
};
// 2016 anchors for the defaults: 24x24 cells x 2 (stride 8) + 12x12 cells x 6 (stride 16).
std::vector<Anchor> generate_anchors(const AnchorOptions& options = {});

inline constexpr std::size_t kPalmKeypointCount = 7;
// Palm keypoints, in the model's order.
enum PalmKeypoint : std::size_t {
  kPalmWrist = 0,
  kPalmIndexMcp = 1,
  kPalmMiddleMcp = 2,
  kPalmRingMcp = 3,
  kPalmPinkyMcp = 4,
  kPalmThumbCmc = 5,
  kPalmThumbMcp = 6,
};

struct NormalizedBox {
  double xmin = 0;
  double ymin = 0;
  double width = 0;
  double height = 0;
};

// A palm found by the detector: score in [0, 1], box and keypoints normalised (to the model
// input while decoding, to the image once the letterbox is removed).
struct PalmDetection {
  double score = 0;
  NormalizedBox box;
  std::array<Point2, kPalmKeypointCount> keypoints{};
};

// TensorsToDetectionsCalculator options; the defaults are the palm detector's.
struct DecodeOptions {
  std::size_t num_boxes = 2016;
  std::size_t num_coords = 18;  // 4 box values + 7 keypoints x 2
  std::size_t box_coord_offset = 0;
  std::size_t keypoint_coord_offset = 4;
  std::size_t num_keypoints = kPalmKeypointCount;
  double x_scale = 192;
  double y_scale = 192;
  double w_scale = 192;
  double h_scale = 192;
  double score_clipping_thresh = 100;  // raw score clipped to [-t, t] before the sigmoid
  double min_score_thresh = 0.5;       // after the sigmoid
};
// raw_boxes: num_boxes x num_coords, each (x_center, y_center, w, h, kp0x, kp0y, ...) in input
// pixels relative to the anchor (reverse_output_order); raw_scores: num_boxes logits.
// Returns the boxes scoring >= min_score_thresh with a non-negative size, in anchor order.
// Throws std::invalid_argument when the spans or anchors are smaller than num_boxes needs.
std::vector<PalmDetection> decode_palm_tensors(std::span<const float> raw_boxes,
                                               std::span<const float> raw_scores,
                                               const std::vector<Anchor>& anchors,
                                               const DecodeOptions& options = {});

double intersection_over_union(const NormalizedBox& a, const NormalizedBox& b);

// MediaPipe's WEIGHTED non-max suppression: take the best remaining detection, average the
// box and keypoints of every remaining detection overlapping it by IoU > threshold (itself
// included), weighted by score; the merged detection keeps the best score. Output is in
// decreasing score order.
std::vector<PalmDetection> weighted_non_max_suppression(std::vector<PalmDetection> detections,
                                                        double min_suppression_threshold = 0.3);

// ---- letterbox ------------------------------------------------------------------------
// Fractions of the model input that are padding on each side (ImageToTensor keep_aspect_ratio).
struct LetterboxPadding {
  double left = 0;
  double top = 0;
  double right = 0;
  double bottom = 0;
};
LetterboxPadding letterbox_padding(int image_width, int image_height, int input_width,
                                   int input_height);
// The rect (normalised to the image) whose crop is the letterboxed model input: the image
// centred, padded on the short side.
RotatedRect letterbox_rect(int image_width, int image_height, int input_width, int input_height);
Point2 remove_letterbox(const Point2& p, const LetterboxPadding& pad);  // input → image
Point2 add_letterbox(const Point2& p, const LetterboxPadding& pad);     // image → input
PalmDetection remove_letterbox(const PalmDetection& d, const LetterboxPadding& pad);

// ---- ROIs -----------------------------------------------------------------------------
double normalize_radians(double angle);  // into [-pi, pi)

// Rotation (radians) that turns the vector from → to (normalised points, measured in pixels
// of a width x height image) to point at target_angle (counter-clockwise from +x, y up):
// target 90° means the vector points up in the crop.
double rotation_to_target(const Point2& from, const Point2& to, int image_width, int image_height,
                          double target_angle_rad);

// RectTransformationCalculator.
struct RectTransform {
  double scale_x = 1;
  double scale_y = 1;
  double shift_x = 0;  // fractions of the rect's width / height, along the rect's own axes
  double shift_y = 0;
  bool square_long = false;  // make the rect square in pixels, on its long side
};
RotatedRect transform_rect(const RotatedRect& rect, int image_width, int image_height,
                           const RectTransform& transform);

// DetectionsToRects (box centre and size, rotation wrist → middle-finger MCP to 90°) then
// RectTransformation {scale 2.6, shift_y -0.5, square_long}: the landmark model's ROI.
RotatedRect detection_to_rect(const PalmDetection& d, int image_width, int image_height);
RotatedRect palm_detection_to_roi(const PalmDetection& d, int image_width, int image_height);

// HandLandmarksToRectCalculator on landmarks {0,1,2,3,5,6,9,10,13,14,17,18}: rotation from the
// wrist to the mean of ((index MCP + ring MCP) / 2, middle MCP), target 90°; the box of those
// landmarks in the rotated frame. (The calculator calls these joints "PIP", but its indices 4,
// 6 and 8 count within that 12-landmark subset, where they are the three MCPs.)
RotatedRect landmarks_to_rect(const std::array<contracts::Point3, contracts::kLandmarkCount>& pts,
                              int image_width, int image_height);
// landmarks_to_rect then RectTransformation {scale 2.0, shift_y -0.1, square_long}: the ROI
// for the next frame (hand_landmark_landmarks_to_roi.pbtxt).
RotatedRect landmarks_to_roi(const std::array<contracts::Point3, contracts::kLandmarkCount>& pts,
                             int image_width, int image_height);

// IoU of the axis-aligned boxes of two rects, ignoring rotation (AssociationNormRectCalculator).
double rect_iou(const RotatedRect& a, const RotatedRect& b);

// Whether a ROI can be cropped: every field finite and at least kMinRoiPixels wide and high in
// an image of that size. Landmarks of a hand the model barely sees can collapse, and a
// degenerate ROI would make the next crop's transform singular.
inline constexpr double kMinRoiPixels = 8;
bool roi_is_usable(const RotatedRect& roi, int image_width, int image_height);

// ---- crop geometry --------------------------------------------------------------------
// x' = a x + b y + c, y' = d x + e y + f.
struct Affine2D {
  double a = 1, b = 0, c = 0;
  double d = 0, e = 1, f = 0;
};
Point2 apply(const Affine2D& m, const Point2& p);
Affine2D invert(const Affine2D& m);  // throws std::invalid_argument when singular

// Continuous crop pixel coordinates → continuous image pixel coordinates for a rect cropped to
// crop_width x crop_height (the crop's top edge is the rect's top edge after rotation).
Affine2D crop_to_image_transform(const RotatedRect& rect, int image_width, int image_height,
                                 int crop_width, int crop_height);

// LandmarkProjectionCalculator: a point normalised to the crop (x, y in [0, 1], z in crop
// widths) → normalised to the image (z in image widths).
contracts::Point3 project_from_rect(const contracts::Point3& p, const RotatedRect& rect);
// Its inverse (for tests and drawing): normalised image → normalised crop.
contracts::Point3 project_to_rect(const contracts::Point3& p, const RotatedRect& rect);

}  // namespace gbdcs::vision
