// TelloVideoSource: a Tello's own camera as a vision::CaptureSource, so the operator can fly
// with the drone's camera (`--source tello:` in every subcommand that takes a camera).
//
// Protocol (Tello SDK 2.0): after "command", "streamon" makes the drone send its camera as a
//   raw H.264 Annex-B stream to the sender's address, UDP port 11111, each encoded frame cut
//   into datagrams of 1460 bytes (the last one shorter); "streamoff" stops it. A real Tello
//   sends 960x720 at 30 fps (about 1-4 Mbit/s); the twin's emulator (`gbdcs twin --tello`)
//   sends its on-board camera at 480x360, 15 fps (docs/ADAPTERS.md).
// Spec     tello:[ADDRESS][?key=value&...]   (tello-video: is the same)
//            ADDRESS        the drone, default 192.168.10.1
//            command_port   its command port, default 8889
//            video_port     the local UDP port the stream arrives on, default 11111 (0: any
//                           free port; the emulator must then be told the port)
//            bind           local address to bind, default 0.0.0.0
//            streamon       1 (default): send "command" + "streamon" on open and "streamoff"
//                           on close from this source's own UDP socket; 0: only listen (the
//                           stream was started by someone else)
//            timeout_s      wait this long for the first picture, default 5
//            stall_s        after that, a gap this long between pictures fails, default 3
// Output   live; BGR frames of the stream's size (order kBgr). next() returns the newest
//          decoded picture not yet returned (older ones are dropped and counted), waiting for
//          one if needed. Decoding runs on the source's own receiver thread (libavcodec).
// Errors   CaptureError naming the cause and the fix: a bad spec (key and allowed values), the
//          video port in use, no reply to "command"/"streamon" (which Wi-Fi, address, port),
//          an "error" reply, no datagram within timeout_s (firewall: let UDP 11111 in),
//          datagrams that never decode, a stream that stops.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include "gbdcs/contracts/clock.hpp"
#include "gbdcs/vision/capture.hpp"

namespace gbdcs::adapters {

struct TelloVideoOptions {
  std::string address = "192.168.10.1";
  int command_port = 8889;
  std::string bind_address = "0.0.0.0";
  int video_port = 11111;
  bool send_streamon = true;
  double first_frame_timeout_s = 5;
  double stall_timeout_s = 3;
  int reply_timeout_ms = 1000;
  int retries = 3;

  // Parses the part after "tello:" / "tello-video:"; throws vision::CaptureError naming the
  // key and the allowed values.
  static TelloVideoOptions from_spec(std::string_view rest);
};

struct TelloVideoStats {
  std::uint64_t datagrams = 0;
  std::uint64_t bytes = 0;
  std::uint64_t frames_decoded = 0;
  std::uint64_t frames_returned = 0;
  std::uint64_t frames_skipped = 0;  // decoded but replaced by a newer one before next()
  std::uint64_t undecodable = 0;
  double decode_ms_mean = 0;  // per decoded picture: last datagram in -> BGR image out
  double decode_ms_max = 0;
  int width = 0, height = 0;
};

class TelloVideoSource final : public vision::CaptureSource {
 public:
  // Binds the video port, then (send_streamon) asks the drone for the stream. Throws
  // vision::CaptureError. The clock must outlive the source.
  TelloVideoSource(TelloVideoOptions options, const contracts::Clock& clock);
  ~TelloVideoSource() override;
  TelloVideoSource(const TelloVideoSource&) = delete;
  TelloVideoSource& operator=(const TelloVideoSource&) = delete;

  std::optional<vision::Frame> next() override;
  bool live() const override { return true; }
  std::string describe() const override;

  std::uint16_t local_video_port() const;
  TelloVideoStats stats() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// True for "tello:" and "tello-video:" specs.
bool is_tello_video_spec(std::string_view spec);
// Opens a tello:/tello-video: spec.
std::unique_ptr<vision::CaptureSource> open_tello_video(std::string_view spec,
                                                        const contracts::Clock& clock);

}  // namespace gbdcs::adapters
