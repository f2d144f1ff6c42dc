// H264Encoder: BGR images to an H.264 Annex-B stream as a Tello sends it, through libavcodec
// (libx264 when present: preset ultrafast, tune zerolatency, no B-frames), and the cutting of
// each encoded frame into Tello-sized datagrams.
//
// Inputs   encode(bgr): CV_8UC3 BGR of exactly width x height.
// Output   the encoded frame (access unit) with its start codes; every key frame (each
//          keyframe_interval frames, and the first) repeats SPS and PPS, so a receiver that
//          joins late decodes from the next key frame, as with a real Tello.
// Errors   no H.264 encoder in this FFmpeg, or bad options -> std::runtime_error /
//          std::invalid_argument naming the fix; a wrong-sized image -> std::invalid_argument.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <opencv2/core/mat.hpp>
#include <string>
#include <vector>

namespace gbdcs::sim {

struct H264EncoderOptions {
  int width = 480;
  int height = 360;
  double fps = 15;
  int bitrate_kbps = 700;
  int keyframe_interval = 15;  // frames between key frames (1 s at 15 fps)
};

class H264Encoder {
 public:
  explicit H264Encoder(H264EncoderOptions options = {});
  ~H264Encoder();
  H264Encoder(const H264Encoder&) = delete;
  H264Encoder& operator=(const H264Encoder&) = delete;

  std::vector<std::uint8_t> encode(const cv::Mat& bgr);
  std::string codec_name() const;  // "libx264", or the fallback encoder's name

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Cuts one encoded frame into datagrams of max_datagram bytes; the last one is shorter, which
// is how a receiver finds the end of the frame. A frame that is an exact multiple of
// max_datagram gets a final one-byte datagram holding a zero (H.264's trailing_zero_8bits).
std::vector<std::vector<std::uint8_t>> split_datagrams(const std::vector<std::uint8_t>& frame,
                                                       std::size_t max_datagram = 1460);

}  // namespace gbdcs::sim
