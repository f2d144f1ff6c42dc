#include "plot_canvas.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/imgproc.hpp>

namespace gbdcs::sim::detail {

double Panel::px(double x) const {
  return area.x + (x - x0) / (x1 - x0) * area.width;
}

double Panel::py(double y) const {
  return area.y + area.height - (y - y0) / (y1 - y0) * area.height;
}

cv::Point Panel::pixel(double x, double y) const {
  return {static_cast<int>(std::lround(px(x))), static_cast<int>(std::lround(py(y)))};
}

double nice_step(double span, int target) {
  if (!(span > 0) || target < 1) {
    return 1;
  }
  const double raw = span / target;
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  for (const double factor : {1.0, 2.0, 5.0}) {
    if (factor * magnitude >= raw) {
      return factor * magnitude;
    }
  }
  return 10 * magnitude;
}

std::string tick_label(double value, double step) {
  const int decimals = std::clamp(static_cast<int>(std::ceil(-std::log10(step) - 1e-9)), 0, 6);
  if (std::abs(value) < step * 1e-6) {
    value = 0;  // no "-0"
  }
  char text[32];
  std::snprintf(text, sizeof text, "%.*f", decimals, value);
  return text;
}

void put_text(cv::Mat& image, const std::string& text, cv::Point at, double scale,
              const cv::Scalar& colour) {
  cv::putText(image, text, at, kFont, scale, colour, 1, cv::LINE_AA);
}

namespace {

cv::Size text_size(const std::string& text, double scale = kFontScale) {
  int baseline = 0;
  return cv::getTextSize(text, kFont, scale, 1, &baseline);
}

}  // namespace

void draw_grid(cv::Mat& image, const Panel& panel, double x_step, double y_step,
               const std::string& x_title, const std::string& y_title) {
  if (x_step <= 0) {
    x_step = nice_step(panel.x1 - panel.x0, 8);
  }
  if (y_step <= 0) {
    y_step = nice_step(panel.y1 - panel.y0, 5);
  }
  const cv::Rect& a = panel.area;
  for (double x = std::ceil(panel.x0 / x_step) * x_step; x <= panel.x1 + 1e-9 * x_step;
       x += x_step) {
    const int column = panel.pixel(x, 0).x;
    cv::line(image, {column, a.y}, {column, a.y + a.height}, kGridColour, 1);
    const std::string label = tick_label(x, x_step);
    put_text(image, label, {column - text_size(label).width / 2, a.y + a.height + 16});
  }
  for (double y = std::ceil(panel.y0 / y_step) * y_step; y <= panel.y1 + 1e-9 * y_step;
       y += y_step) {
    const int row = panel.pixel(0, y).y;
    cv::line(image, {a.x, row}, {a.x + a.width, row}, kGridColour, 1);
    const std::string label = tick_label(y, y_step);
    put_text(image, label, {a.x - 6 - text_size(label).width, row + 5});
  }
  cv::rectangle(image, a, kAxisColour, 1);
  put_text(image, x_title, {a.x + a.width - text_size(x_title).width, a.y + a.height + 34});
  put_text(image, y_title, {a.x, a.y - 8});
}

}  // namespace gbdcs::sim::detail
