#include "gbdcs/sim/trajectory_plot.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "gbdcs/sim/video_recorder.hpp"
#include "option_reader.hpp"
#include "plot_canvas.hpp"

namespace gbdcs::sim {

const cv::Scalar TrajectoryPlot::kPathColour{200, 90, 30};
const cv::Scalar TrajectoryPlot::kHeadingColour{0, 140, 255};
const cv::Scalar TrajectoryPlot::kStartColour{40, 170, 40};
const cv::Scalar TrajectoryPlot::kEndColour{40, 40, 220};

namespace {

using detail::Panel;

constexpr int kLeft = 70;
constexpr int kRight = 30;
const cv::Scalar kBackground{255, 255, 255};
const cv::Scalar kAltitudeColour{200, 90, 30};
const cv::Scalar kBatteryColour{60, 140, 20};

void check_options(const PlotOptions& o) {
  const auto in = [](int v, int lo, int hi) { return v >= lo && v <= hi; };
  if (!in(o.width, 400, 4000) || !in(o.path_height, 200, 4000) || !in(o.series_height, 100, 2000) ||
      o.heading_every < 0) {
    throw std::invalid_argument(
        "PlotOptions: width 400...4000, path_height 200...4000, series_height 100...2000 and "
        "heading_every >= 0 are required");
  }
}

void check_samples(const std::vector<TrajectorySample>& samples) {
  if (samples.empty()) {
    throw std::invalid_argument("TrajectoryPlot: no samples to plot");
  }
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const TrajectorySample& s = samples[i];
    for (const double v : {s.time_s, s.x_m, s.y_m, s.altitude_m, s.heading_deg, s.battery_pct}) {
      if (!std::isfinite(v)) {
        throw std::invalid_argument("TrajectoryPlot: sample " + std::to_string(i) +
                                    " has a non-finite value");
      }
    }
  }
}

template <typename Get>
std::pair<double, double> range_of(const std::vector<TrajectorySample>& samples, Get get) {
  const auto [lo, hi] = std::minmax_element(
      samples.begin(), samples.end(),
      [&get](const TrajectorySample& a, const TrajectorySample& b) { return get(a) < get(b); });
  return {get(*lo), get(*hi)};
}

// The x/y panel works in screen axes: u to the right, v up, in metres.
struct ScreenPath {
  std::vector<cv::Point2d> uv;
  std::vector<cv::Point2d> heading;  // unit vectors in (u, v)
};

ScreenPath to_screen(const std::vector<TrajectorySample>& samples, PlotFrame frame) {
  ScreenPath path;
  for (const auto& s : samples) {
    const double h = s.heading_deg * std::numbers::pi / 180;
    if (frame == PlotFrame::kContracts) {  // x up, y right; heading clockwise from up
      path.uv.emplace_back(s.y_m, s.x_m);
      path.heading.emplace_back(std::sin(h), std::cos(h));
    } else {  // x right, y up; heading counter-clockwise from right
      path.uv.emplace_back(s.x_m, s.y_m);
      path.heading.emplace_back(std::cos(h), std::sin(h));
    }
  }
  return path;
}

// The path's bounding box, padded, centred in `area` with one scale for both axes; the
// panel's data box is whatever that scale makes visible.
Panel path_panel(const std::vector<cv::Point2d>& uv, cv::Rect area) {
  double u_lo = uv.front().x;
  double u_hi = u_lo;
  double v_lo = uv.front().y;
  double v_hi = v_lo;
  for (const auto& p : uv) {
    u_lo = std::min(u_lo, p.x);
    u_hi = std::max(u_hi, p.x);
    v_lo = std::min(v_lo, p.y);
    v_hi = std::max(v_hi, p.y);
  }
  const double pad = std::max(0.25, 0.08 * std::max(u_hi - u_lo, v_hi - v_lo));
  const double ppm =
      std::min(area.width / (u_hi - u_lo + 2 * pad), area.height / (v_hi - v_lo + 2 * pad));
  const double cu = (u_lo + u_hi) / 2;
  const double cv = (v_lo + v_hi) / 2;
  const double half_w = area.width / ppm / 2;
  const double half_h = area.height / ppm / 2;
  return Panel{area, cu - half_w, cu + half_w, cv - half_h, cv + half_h};
}

std::vector<cv::Point> polyline(const std::vector<TrajectorySample>& samples, const Panel& panel,
                                double (*x_of)(const TrajectorySample&),
                                double (*y_of)(const TrajectorySample&)) {
  std::vector<cv::Point> points;
  points.reserve(samples.size());
  for (const auto& s : samples) {
    const cv::Point p = panel.pixel(x_of(s), y_of(s));
    if (points.empty() || points.back() != p) {
      points.push_back(p);
    }
  }
  return points;
}

void draw_path(cv::Mat& image, const ScreenPath& path, const Panel& panel,
               const PlotOptions& options) {
  const double step = detail::nice_step(std::max(panel.x1 - panel.x0, panel.y1 - panel.y0), 10);
  const bool contracts = options.frame == PlotFrame::kContracts;
  detail::draw_grid(image, panel, step, step, contracts ? "y (m), right" : "x (m)",
                    contracts ? "x (m), forward" : "y (m), left");

  std::vector<cv::Point> points;
  for (const auto& p : path.uv) {
    const cv::Point pixel = panel.pixel(p.x, p.y);
    if (points.empty() || points.back() != pixel) {
      points.push_back(pixel);
    }
  }
  if (points.size() > 1) {
    cv::polylines(image, points, false, TrajectoryPlot::kPathColour, 2, cv::LINE_AA);
  }

  const std::size_t n = path.uv.size();
  const std::size_t every = options.heading_every > 0
                                ? static_cast<std::size_t>(options.heading_every)
                                : std::max<std::size_t>(1, n / 16);
  for (std::size_t i = 0; i < n; i += every) {
    const cv::Point from = panel.pixel(path.uv[i].x, path.uv[i].y);
    const cv::Point to{from.x + static_cast<int>(std::lround(22 * path.heading[i].x)),
                       from.y - static_cast<int>(std::lround(22 * path.heading[i].y))};
    cv::arrowedLine(image, from, to, TrajectoryPlot::kHeadingColour, 2, cv::LINE_AA, 0, 0.35);
  }

  const cv::Point start = panel.pixel(path.uv.front().x, path.uv.front().y);
  const cv::Point end = panel.pixel(path.uv.back().x, path.uv.back().y);
  // End first: on a closed loop the start dot sits on the end square and both stay visible.
  cv::rectangle(image, cv::Rect(end.x - 6, end.y - 6, 13, 13), TrajectoryPlot::kEndColour,
                cv::FILLED);
  cv::circle(image, start, 7, TrajectoryPlot::kStartColour, cv::FILLED, cv::LINE_AA);

  // Legend, top right of the panel.
  const cv::Rect& a = panel.area;
  int x = a.x + a.width - 250;
  const int y = a.y - 8;
  cv::circle(image, {x, y - 4}, 5, TrajectoryPlot::kStartColour, cv::FILLED, cv::LINE_AA);
  detail::put_text(image, "start", {x + 9, y});
  x += 60;
  cv::rectangle(image, cv::Rect(x - 5, y - 9, 10, 10), TrajectoryPlot::kEndColour, cv::FILLED);
  detail::put_text(image, "end", {x + 9, y});
  x += 50;
  cv::arrowedLine(image, {x - 6, y - 4}, {x + 12, y - 4}, TrajectoryPlot::kHeadingColour, 2,
                  cv::LINE_AA, 0, 0.4);
  detail::put_text(image, "heading", {x + 17, y});
}

void draw_series(cv::Mat& image, const std::vector<TrajectorySample>& samples, cv::Rect area,
                 double (*value_of)(const TrajectorySample&), double lo, double hi,
                 const cv::Scalar& colour, const std::string& title) {
  double t0 = samples.front().time_s;
  double t1 = samples.back().time_s;
  if (!(t1 > t0)) {
    t1 = t0 + 1;
  }
  const Panel panel{area, t0, t1, lo, hi};
  detail::draw_grid(image, panel, 0, 0, "time (s)", title);
  const auto points = polyline(
      samples, panel, [](const TrajectorySample& s) { return s.time_s; }, value_of);
  if (points.size() > 1) {
    cv::polylines(image, points, false, colour, 2, cv::LINE_AA);
  } else {
    cv::circle(image, points.front(), 3, colour, cv::FILLED, cv::LINE_AA);
  }
}

double path_length_m(const std::vector<TrajectorySample>& samples) {
  double length = 0;
  for (std::size_t i = 1; i < samples.size(); ++i) {
    length += std::hypot(samples[i].x_m - samples[i - 1].x_m, samples[i].y_m - samples[i - 1].y_m);
  }
  return length;
}

}  // namespace

PlotOptions PlotOptions::from_json(const nlohmann::json& doc) {
  PlotOptions options;
  detail::OptionReader reader(doc, "PlotOptions");
  reader.read("width", options.width);
  reader.read("path_height", options.path_height);
  reader.read("series_height", options.series_height);
  reader.read("heading_every", options.heading_every);
  std::string frame = "contracts";
  reader.read("frame", frame);
  reader.read("title", options.title);
  reader.finish();
  contracts::require(frame == "contracts" || frame == "mujoco", "PlotOptions", "frame",
                     "must be \"contracts\" or \"mujoco\"");
  options.frame = frame == "mujoco" ? PlotFrame::kMujoco : PlotFrame::kContracts;
  check_options(options);
  return options;
}

cv::Point2d PathLayout::to_pixel(double x_m, double y_m) const {
  const bool contracts = frame == PlotFrame::kContracts;
  const double u = contracts ? y_m : x_m;
  const double v = contracts ? x_m : y_m;
  return {origin_px.x + pixels_per_m * u, origin_px.y - pixels_per_m * v};
}

cv::Point2d PathLayout::to_world(cv::Point2d pixel) const {
  const double u = (pixel.x - origin_px.x) / pixels_per_m;
  const double v = (origin_px.y - pixel.y) / pixels_per_m;
  return frame == PlotFrame::kContracts ? cv::Point2d(v, u) : cv::Point2d(u, v);
}

cv::Mat TrajectoryPlot::draw(const std::vector<TrajectorySample>& samples,
                             const PlotOptions& options) {
  check_options(options);
  check_samples(samples);
  const int width = options.width;
  const int height = options.path_height + 2 * options.series_height;
  cv::Mat image(height, width, CV_8UC3, kBackground);

  char summary[160];
  std::snprintf(summary, sizeof summary, "%s  -  %.1f s, %zu samples, path %.2f m",
                options.title.c_str(), samples.back().time_s - samples.front().time_s,
                samples.size(), path_length_m(samples));
  detail::put_text(image, summary, {kLeft, 24}, 0.6);

  const cv::Rect path_area(kLeft, 60, width - kLeft - kRight, options.path_height - 60 - 45);
  const ScreenPath screen = to_screen(samples, options.frame);
  const Panel path = path_panel(screen.uv, path_area);
  draw_path(image, screen, path, options);
  layout_.area = path_area;
  layout_.pixels_per_m = path_area.width / (path.x1 - path.x0);
  layout_.origin_px = {path.px(0), path.py(0)};
  layout_.frame = options.frame;

  const auto [alt_lo, alt_hi] = range_of(samples, [](const auto& s) { return s.altitude_m; });
  const auto [bat_lo, bat_hi] = range_of(samples, [](const auto& s) { return s.battery_pct; });
  const int series_top = options.path_height;
  const int series_h = options.series_height - 30 - 45;
  draw_series(
      image, samples, cv::Rect(kLeft, series_top + 30, path_area.width, series_h),
      [](const TrajectorySample& s) { return s.altitude_m; }, std::min(0.0, alt_lo),
      std::max(0.5, alt_hi * 1.1), kAltitudeColour, "altitude (m)");
  draw_series(
      image, samples,
      cv::Rect(kLeft, series_top + options.series_height + 30, path_area.width, series_h),
      [](const TrajectorySample& s) { return s.battery_pct; }, std::min(0.0, bat_lo),
      std::max(100.0, bat_hi), kBatteryColour, "battery (%)");

  image_ = image;
  return image;
}

void TrajectoryPlot::save(const std::filesystem::path& path) const {
  if (image_.empty()) {
    throw std::logic_error("TrajectoryPlot: save() before draw()");
  }
  save_png(path, image_);
}

}  // namespace gbdcs::sim
