#include "gbdcs/sim/trajectory_plot.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <opencv2/imgcodecs.hpp>

#include "test_scene.hpp"

namespace gbdcs::sim {
namespace {

constexpr double kRadius = 2.0;
constexpr double kCx = 1.0;
constexpr double kCy = -0.5;
constexpr int kSamples = 400;

std::vector<TrajectorySample> circle() {
  std::vector<TrajectorySample> samples;
  for (int i = 0; i < kSamples; ++i) {
    const double a = 2 * std::numbers::pi * i / kSamples;
    samples.push_back({.time_s = 0.05 * i,
                       .x_m = kCx + kRadius * std::cos(a),
                       .y_m = kCy + kRadius * std::sin(a),
                       .altitude_m = 1.0 + 0.1 * std::sin(3 * a),
                       .heading_deg = a * 180 / std::numbers::pi + 90,  // along the path
                       .battery_pct = 100.0 - 20.0 * i / kSamples});
  }
  return samples;
}

bool is_path(const cv::Vec3b& p) {
  const cv::Scalar& c = TrajectoryPlot::kPathColour;
  return std::abs(p[0] - c[0]) + std::abs(p[1] - c[1]) + std::abs(p[2] - c[2]) < 60;
}

// A path-coloured pixel within `radius` pixels of `at`.
bool path_near(const cv::Mat& image, cv::Point2d at, int radius) {
  for (int dy = -radius; dy <= radius; ++dy) {
    for (int dx = -radius; dx <= radius; ++dx) {
      const cv::Point p(static_cast<int>(std::lround(at.x)) + dx,
                        static_cast<int>(std::lround(at.y)) + dy);
      if (cv::Rect(0, 0, image.cols, image.rows).contains(p) && is_path(image.at<cv::Vec3b>(p))) {
        return true;
      }
    }
  }
  return false;
}

class TrajectoryPlotFrames : public ::testing::TestWithParam<PlotFrame> {};

TEST_P(TrajectoryPlotFrames, ACirclePlotsAsACircle) {
  TrajectoryPlot plot;
  const auto samples = circle();
  const cv::Mat image = plot.draw(samples, {.frame = GetParam()});
  ASSERT_EQ(image.type(), CV_8UC3);
  EXPECT_EQ(image.cols, 960);
  EXPECT_EQ(image.rows, 640 + 2 * 220);
  const PathLayout& layout = plot.path_layout();
  ASSERT_GT(layout.pixels_per_m, 10);

  // Samples halfway between heading arrows (which are drawn over the path) are on the line.
  for (int i = 12; i < kSamples - 12; i += 25) {
    const cv::Point2d p = layout.to_pixel(samples[i].x_m, samples[i].y_m);
    EXPECT_TRUE(path_near(image, p, 2)) << "sample " << i << " at " << p;
  }
  // Points off the circle are not: the centre, and 0.5 m outside it.
  EXPECT_FALSE(path_near(image, layout.to_pixel(kCx, kCy), 3));
  EXPECT_FALSE(path_near(image, layout.to_pixel(kCx + kRadius + 0.5, kCy), 3));

  // Every path-coloured pixel of the panel lies on the circle, and the circle is round
  // (equal axis scaling): its pixel bounding box is square.
  const double tolerance_m = 3.0 / layout.pixels_per_m;
  int min_x = image.cols;
  int max_x = 0;
  int min_y = image.rows;
  int max_y = 0;
  int count = 0;
  for (int y = layout.area.y; y < layout.area.y + layout.area.height; ++y) {
    for (int x = layout.area.x; x < layout.area.x + layout.area.width; ++x) {
      if (!is_path(image.at<cv::Vec3b>(y, x))) {
        continue;
      }
      const cv::Point2d world = layout.to_world({static_cast<double>(x), static_cast<double>(y)});
      EXPECT_NEAR(std::hypot(world.x - kCx, world.y - kCy), kRadius, tolerance_m) << x << "," << y;
      min_x = std::min(min_x, x);
      max_x = std::max(max_x, x);
      min_y = std::min(min_y, y);
      max_y = std::max(max_y, y);
      ++count;
    }
  }
  EXPECT_GT(count, 500);
  EXPECT_NEAR(max_x - min_x, max_y - min_y, 3);
  EXPECT_NEAR(max_x - min_x, 2 * kRadius * layout.pixels_per_m, 4);

  // Markers: green start dot at the first sample, over the red end square at the last (the
  // circle closes, so the square's corners show around the dot).
  const cv::Point start = layout.to_pixel(samples.front().x_m, samples.front().y_m);
  const cv::Point end = layout.to_pixel(samples.back().x_m, samples.back().y_m);
  ASSERT_LE(cv::norm(start - end), 6.0);
  const auto colour_at = [&image](cv::Point p) {
    const auto v = image.at<cv::Vec3b>(p);
    return cv::Scalar(v[0], v[1], v[2]);
  };
  EXPECT_EQ(colour_at(start + cv::Point(-3, 0)), TrajectoryPlot::kStartColour);
  // The square's corner away from the dot.
  const cv::Point away(end.x >= start.x ? 6 : -6, end.y >= start.y ? 6 : -6);
  EXPECT_EQ(colour_at(end + away), TrajectoryPlot::kEndColour);
}

INSTANTIATE_TEST_SUITE_P(BothFrames, TrajectoryPlotFrames,
                         ::testing::Values(PlotFrame::kContracts, PlotFrame::kMujoco),
                         [](const auto& param_info) {
                           return param_info.param == PlotFrame::kContracts ? "Contracts"
                                                                            : "Mujoco";
                         });

bool is_heading(const cv::Vec3b& p) {
  const cv::Scalar& c = TrajectoryPlot::kHeadingColour;
  return std::abs(p[0] - c[0]) + std::abs(p[1] - c[1]) + std::abs(p[2] - c[2]) < 60;
}

TEST(TrajectoryPlot, TheContractsFrameIsDrawnAsAMap) {
  // Forward along +x with heading 0, then a quarter turn clockwise (to the right, heading 90):
  // on the map the path goes up, and the arrows point up, then right.
  std::vector<TrajectorySample> samples;
  for (int i = 0; i <= 40; ++i) {
    samples.push_back({.time_s = 0.1 * i, .x_m = 0.05 * i, .heading_deg = i < 20 ? 0.0 : 90.0});
  }
  TrajectoryPlot plot;
  const cv::Mat image = plot.draw(samples, {.heading_every = 10});
  const PathLayout& layout = plot.path_layout();
  const cv::Point2d start = layout.to_pixel(0, 0);
  const cv::Point2d end = layout.to_pixel(2, 0);
  EXPECT_NEAR(end.x, start.x, 0.5);
  EXPECT_LT(end.y, start.y - 100) << "forward is up";
  EXPECT_GT(layout.to_pixel(0, 1).x, start.x + 50) << "right is right";
  const cv::Point2d up_arrow = layout.to_pixel(samples[10].x_m, 0) + cv::Point2d(0, -16);
  const cv::Point2d right_arrow = layout.to_pixel(samples[30].x_m, 0) + cv::Point2d(16, 0);
  EXPECT_TRUE(is_heading(image.at<cv::Vec3b>(cv::Point(up_arrow))));
  EXPECT_TRUE(is_heading(image.at<cv::Vec3b>(cv::Point(right_arrow))));
  // The MuJoCo frame (y left, counter-clockwise) puts the same numbers x to the right.
  plot.draw(samples, {.heading_every = 10, .frame = PlotFrame::kMujoco});
  EXPECT_GT(plot.path_layout().to_pixel(2, 0).x, plot.path_layout().to_pixel(0, 0).x + 100);
}

TEST(TrajectoryPlot, SavesAReadablePng) {
  TrajectoryPlot plot;
  EXPECT_THROW(plot.save(test::temp_path("early.png")), std::logic_error);
  const cv::Mat image = plot.draw(circle(), {.width = 800, .title = "circle"});
  const auto path = test::temp_path("trajectory.png");
  plot.save(path);
  const cv::Mat back = cv::imread(path.string(), cv::IMREAD_COLOR);
  ASSERT_EQ(back.size(), image.size());
  EXPECT_EQ(cv::norm(back, image, cv::NORM_INF), 0.0);
  EXPECT_THROW(plot.save("/nonexistent-folder/trajectory.png"), std::runtime_error);
}

TEST(TrajectoryPlot, OneSampleAndAStraightLineDraw) {
  TrajectoryPlot plot;
  EXPECT_NO_THROW(plot.draw({{.time_s = 0, .x_m = 0, .y_m = 0, .battery_pct = 100}}));
  std::vector<TrajectorySample> line;
  for (int i = 0; i < 50; ++i) {
    line.push_back({.time_s = 0.1 * i, .x_m = 0.1 * i, .altitude_m = 1, .battery_pct = 90});
  }
  const cv::Mat image = plot.draw(line);
  const PathLayout& layout = plot.path_layout();
  EXPECT_TRUE(path_near(image, layout.to_pixel(line[30].x_m, 0), 2));
}

TEST(TrajectoryPlot, RejectsBadInput) {
  TrajectoryPlot plot;
  EXPECT_THROW(plot.draw({}), std::invalid_argument);
  auto samples = circle();
  samples[7].altitude_m = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(plot.draw(samples), std::invalid_argument);
  EXPECT_THROW(plot.draw(circle(), {.width = 10}), std::invalid_argument);
  EXPECT_THROW(PlotOptions::from_json({{"colour", "red"}}), std::invalid_argument);
  EXPECT_EQ(PlotOptions::from_json({{"heading_every", 5}}).heading_every, 5);
  EXPECT_EQ(PlotOptions::from_json({{"frame", "mujoco"}}).frame, PlotFrame::kMujoco);
  EXPECT_THROW(PlotOptions::from_json({{"frame", "ned"}}), std::invalid_argument);
}

}  // namespace
}  // namespace gbdcs::sim
