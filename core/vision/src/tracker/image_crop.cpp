#include "tracker/image_crop.hpp"

#include <opencv2/core/check.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>

namespace gbdcs::vision::detail {

void crop_to_tensor(const cv::Mat& rgb, const RotatedRect& rect, int width, int height,
                    CropBorder border, float* dst) {
  // crop_to_image_transform works on continuous coordinates (pixel centres at i + 0.5);
  // warpAffine on pixel indices (centres at i): src_index = A(dst_index + 0.5) - 0.5.
  const Affine2D m = crop_to_image_transform(rect, rgb.cols, rgb.rows, width, height);
  const cv::Matx23d dst_to_src(m.a, m.b, m.c + 0.5 * (m.a + m.b) - 0.5,  //
                               m.d, m.e, m.f + 0.5 * (m.d + m.e) - 0.5);
  cv::Mat crop;
  cv::warpAffine(
      rgb, crop, dst_to_src, cv::Size(width, height), cv::INTER_LINEAR | cv::WARP_INVERSE_MAP,
      border == CropBorder::kZero ? cv::BORDER_CONSTANT : cv::BORDER_REPLICATE, cv::Scalar::all(0));
  cv::Mat out(height, width, CV_32FC3, dst);
  crop.convertTo(out, CV_32FC3, 1.0 / 255.0);
}

void check_rgb_image(const cv::Mat& rgb, std::string_view who) {
  if (rgb.empty()) {
    throw std::invalid_argument(std::string(who) + ": the image is empty");
  }
  if (rgb.type() != CV_8UC3) {
    throw std::invalid_argument(std::string(who) + ": expected an 8-bit 3-channel RGB image " +
                                "(CV_8UC3), got " + cv::typeToString(rgb.type()) + " " +
                                std::to_string(rgb.cols) + "x" + std::to_string(rgb.rows));
  }
}

}  // namespace gbdcs::vision::detail
