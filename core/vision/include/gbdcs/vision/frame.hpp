// Frame: one image travelling through the vision pipeline, with where and when it was taken.
//
//   rgb           the pixels, CV_8UC3. A capture source that reads through OpenCV delivers
//                 them in OpenCV's BGR order (order = kBgr); the preprocess stage converts to
//                 RGB, which is what the hand tracker takes. Sources that render RGB directly
//                 (the fixture renderer) say kRgb and skip the conversion.
//   frame_id      0, 1, 2, ... per source, in capture order; never reused, so a gap in the ids
//                 downstream is a dropped frame.
//   capture_time  Clock::now() of the injected clock when the source produced the frame.
//   capture_utc   Clock::utc_now() at the same moment, for messages and logs.
//   source        where the pixels came from: "camera:0", the video path, or the image file.
#pragma once

#include <cstdint>
#include <opencv2/core/mat.hpp>
#include <string>

#include "gbdcs/contracts/clock.hpp"

namespace gbdcs::vision {

enum class PixelOrder { kBgr, kRgb };

struct Frame {
  cv::Mat rgb;
  std::int64_t frame_id = 0;
  contracts::Duration capture_time{};
  contracts::UtcTime capture_utc{};
  std::string source;
  PixelOrder order = PixelOrder::kRgb;
};

}  // namespace gbdcs::vision
