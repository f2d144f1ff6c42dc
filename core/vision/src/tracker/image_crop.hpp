// Image → model input: the rotated-rect crop of ImageToTensorCalculator, bilinear, written as
// float RGB in [0, 1] straight into the model's NHWC input buffer. Private to the tracker.
#pragma once

#include <opencv2/core.hpp>
#include <string_view>

#include "gbdcs/vision/roi.hpp"

namespace gbdcs::vision::detail {

enum class CropBorder { kZero, kReplicate };

// Crops `rect` (normalised to `rgb`) to a width x height float RGB image at `dst`
// (width * height * 3 floats, row-major, channels last). `rgb` must be CV_8UC3.
void crop_to_tensor(const cv::Mat& rgb, const RotatedRect& rect, int width, int height,
                    CropBorder border, float* dst);

// Throws std::invalid_argument naming `who` unless `rgb` is a non-empty CV_8UC3 image.
void check_rgb_image(const cv::Mat& rgb, std::string_view who);

}  // namespace gbdcs::vision::detail
