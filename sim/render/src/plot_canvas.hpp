// Plot drawing helpers shared by the trajectory plot's panels: a linear data -> pixel mapping,
// "nice" grid steps and a framed, labelled grid. Private to sim/render.
#pragma once

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <string>

namespace gbdcs::sim::detail {

// A panel maps the data box [x0, x1] x [y0, y1] onto `area`, y up.
struct Panel {
  cv::Rect area;
  double x0 = 0;
  double x1 = 1;
  double y0 = 0;
  double y1 = 1;

  double px(double x) const;
  double py(double y) const;
  cv::Point pixel(double x, double y) const;
};

// The step from {1, 2, 5} x 10^k that cuts `span` into about `target` intervals.
double nice_step(double span, int target);
// A tick label with as many decimals as `step` needs ("0.5", "-1", "2.25").
std::string tick_label(double value, double step);

inline const cv::Scalar kGridColour{225, 225, 225};
inline const cv::Scalar kAxisColour{90, 90, 90};
inline const cv::Scalar kTextColour{40, 40, 40};
constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
constexpr double kFontScale = 0.45;

// Grid lines every x_step / y_step (0: choose), tick labels, a frame, and axis titles.
void draw_grid(cv::Mat& image, const Panel& panel, double x_step, double y_step,
               const std::string& x_title, const std::string& y_title);
void put_text(cv::Mat& image, const std::string& text, cv::Point at, double scale = kFontScale,
              const cv::Scalar& colour = kTextColour);

}  // namespace gbdcs::sim::detail
