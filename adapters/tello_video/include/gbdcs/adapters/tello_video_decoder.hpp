// TelloVideoDecoder: the Tello's video stream (H.264 Annex-B, as it arrives on UDP 11111)
// back into images, through libavcodec.
//
// Inputs   push(datagram): one UDP datagram of the stream, in arrival order. A Tello cuts
//          each encoded frame (access unit: SPS/PPS/IDR or a P slice, start codes included)
//          into datagrams of max_datagram bytes (1460) and the last, shorter one ends the
//          frame; so a datagram shorter than max_datagram completes a frame, which goes to the
//          decoder at once (no frame of parser delay).
// Output   push() returns the frames it completed: CV_8UC3, BGR, the stream's own size.
//          Frames before the first SPS/PPS + IDR cannot be decoded (a receiver that joins a
//          running stream waits for the next key frame, about 1 s on a Tello): they are
//          counted in stats().undecodable, never thrown.
// Robust   a frame larger than max_frame_bytes (a lost "last datagram") is dropped and
//          counted; a stream that claims more than max_pixels per picture is refused by the
//          decoder (counted); random bytes never crash it (tests/adapters fuzz it).
// Threads  one caller at a time.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <opencv2/core/mat.hpp>
#include <span>
#include <string>
#include <vector>

namespace gbdcs::adapters {

struct TelloVideoDecoderOptions {
  std::size_t max_datagram = 1460;          // a datagram this long continues the frame
  std::size_t max_frame_bytes = 2u << 20;   // an encoded frame larger than this is dropped
  std::int64_t max_pixels = 1920LL * 1080;  // a picture larger than this is refused
};

struct TelloVideoDecoderStats {
  std::uint64_t datagrams = 0;
  std::uint64_t bytes = 0;
  std::uint64_t encoded_frames = 0;  // frames handed to the decoder
  std::uint64_t frames = 0;          // pictures decoded
  std::uint64_t undecodable = 0;     // frames the decoder refused (no key frame yet, corrupt)
  std::uint64_t oversized = 0;       // frames dropped for max_frame_bytes
  std::string last_error;            // the decoder's last complaint
};

class TelloVideoDecoder {
 public:
  // Throws std::runtime_error when libavcodec has no H.264 decoder.
  explicit TelloVideoDecoder(TelloVideoDecoderOptions options = {});
  ~TelloVideoDecoder();
  TelloVideoDecoder(const TelloVideoDecoder&) = delete;
  TelloVideoDecoder& operator=(const TelloVideoDecoder&) = delete;

  std::vector<cv::Mat> push(std::span<const std::uint8_t> datagram);
  // Decodes whatever is assembled (the end of a recorded stream).
  std::vector<cv::Mat> flush();
  const TelloVideoDecoderStats& stats() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace gbdcs::adapters
