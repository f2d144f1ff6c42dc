// TrajectoryPlot: a PNG summary of a twin run, drawn with OpenCV only.
//
// Inputs   samples {time_s, x_m, y_m, altitude_m, heading_deg, battery_pct}, in time order
//          (at least one; every value finite).
// Output   a CV_8UC3 BGR image, options.width wide:
//            top     the x/y path seen from above, equal scaling on both axes, a metre grid
//                    with labels, a green start dot, a red end square and a heading arrow
//                    every `heading_every` samples;
//            below   altitude (m) over time, then battery (%) over time, with axes and labels.
// Options  PlotOptions (JSON: the same keys)
//            width              pixels, default 960 (400 ... 4000)
//            path_height        pixels of the x/y panel, default 640 (200 ... 4000)
//            series_height      pixels of each time panel, default 220 (100 ... 2000)
//            heading_every      samples between arrows; 0 (default) = about 16 over the run
//            frame              what x_m, y_m and heading_deg mean:
//                               "contracts" (default; TwinStatus, TelemetryFrame): x forward,
//                                 y right, heading clockwise from +x; drawn as a map, x up
//                                 and y to the right, so heading 0 points up, 90 right;
//                               "mujoco": x forward, y left, heading counter-clockwise from
//                                 +x; drawn x to the right, y up.
//                               Both show the same flight from above, turned by 90 degrees.
//            title              text at the top, default "twin run"
// Errors   no samples, a non-finite value, a bad option -> std::invalid_argument naming it;
//          save() to an unwritable path -> std::runtime_error naming the path.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <opencv2/core/mat.hpp>
#include <opencv2/core/types.hpp>
#include <string>
#include <vector>

namespace gbdcs::sim {

struct TrajectorySample {
  double time_s = 0;
  double x_m = 0;
  double y_m = 0;
  double altitude_m = 0;
  double heading_deg = 0;
  double battery_pct = 0;
};

enum class PlotFrame { kContracts, kMujoco };

struct PlotOptions {
  int width = 960;
  int path_height = 640;
  int series_height = 220;
  int heading_every = 0;
  PlotFrame frame = PlotFrame::kContracts;
  std::string title = "twin run";

  static PlotOptions from_json(const nlohmann::json& doc);
};

// Where the x/y panel put the world (in the samples' frame), both ways.
struct PathLayout {
  cv::Rect area;            // the panel's plotting area in the image
  cv::Point2d origin_px;    // the pixel of world (0, 0) (may lie outside the area)
  double pixels_per_m = 1;  // the same on both axes
  PlotFrame frame = PlotFrame::kContracts;

  cv::Point2d to_pixel(double x_m, double y_m) const;
  cv::Point2d to_world(cv::Point2d pixel) const;  // (x_m, y_m)
};

class TrajectoryPlot {
 public:
  // Colours (BGR) of the plotted marks, so tests and docs can find them.
  static const cv::Scalar kPathColour;
  static const cv::Scalar kHeadingColour;
  static const cv::Scalar kStartColour;
  static const cv::Scalar kEndColour;

  cv::Mat draw(const std::vector<TrajectorySample>& samples, const PlotOptions& options = {});
  // Writes the last drawn image as a PNG; std::logic_error before the first draw().
  void save(const std::filesystem::path& path) const;

  const cv::Mat& image() const { return image_; }
  const PathLayout& path_layout() const { return layout_; }

 private:
  cv::Mat image_;
  PathLayout layout_;
};

}  // namespace gbdcs::sim
