// TelloVideoStreamer: the twin's camera as a Tello's video stream. After the client sends
// "streamon" to the TelloEmulator, it renders the twin's on-board (or chase) camera off
// screen (sim/render, OSMesa), encodes it as H.264 Annex-B (H264Encoder, libx264) and sends
// each frame to the client's address, UDP client_port (11111), in datagrams of at most
// max_datagram (1460) bytes, the last one shorter, as a real Tello does. "streamoff" stops it.
//
// A real Tello streams 960x720 at 30 fps; the default here is 480x360 at 15 fps, which the
// CPU renderer and the encoder keep up with on a small machine (docs/ADAPTERS.md).
// Options  TelloVideoStreamOptions (JSON: the same keys): width, height, fps, camera
//          ("onboard" | "chase" | any camera of the twin's model), bitrate_kbps,
//          keyframe_interval (frames), client_port, max_datagram.
// Time     frames are paced on the wall clock (a video stream is real time); each frame shows
//          the twin's state at the moment it is rendered (a copy taken under the host's lock,
//          so the stepping thread never waits for the renderer).
// Faults   during a link loss (the attached emulator's set_link_lost, or a link_loss in the
//          twin's fault schedule) no datagram is sent, as over an out-of-range Wi-Fi.
// Threads  one worker thread owns the Renderer (OSMesa) and the encoder; attach() hooks the
//          emulator's streamon/streamoff; stop the streamer (destructor) before the emulator
//          and the host it renders.
#pragma once

#include <cstdint>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "gbdcs/sim/tello_emulator.hpp"
#include "gbdcs/sim/twin_host.hpp"

namespace gbdcs::sim {

struct TelloVideoStreamOptions {
  int width = 480;
  int height = 360;
  double fps = 15;
  std::string camera = "onboard";
  int bitrate_kbps = 700;
  int keyframe_interval = 15;
  int client_port = 11111;
  int max_datagram = 1460;

  // Unknown keys or wrong types throw std::invalid_argument naming the key.
  static TelloVideoStreamOptions from_json(const nlohmann::json& doc);
};

struct TelloVideoStreamStats {
  std::uint64_t frames = 0;      // encoded and sent
  std::uint64_t datagrams = 0;
  std::uint64_t bytes = 0;
  std::uint64_t late_frames = 0;  // skipped because rendering fell behind the frame rate
  std::uint64_t suppressed = 0;   // frames not sent during a link loss
  double render_ms_mean = 0;
  double encode_ms_mean = 0;
  std::string encoder;  // "libx264"
  std::string last_error;  // a render/encode failure (the stream then stops)
};

class TelloVideoStreamer {
 public:
  TelloVideoStreamer(TwinHost& host, TelloVideoStreamOptions options = {});
  ~TelloVideoStreamer();
  TelloVideoStreamer(const TelloVideoStreamer&) = delete;
  TelloVideoStreamer& operator=(const TelloVideoStreamer&) = delete;

  // streamon from `emulator`'s client starts the stream to that client's address, streamoff
  // stops it.
  void attach(TelloEmulator& emulator);
  void start(const std::string& client_address);
  void stop();
  bool streaming() const;
  void set_client_port(int port);  // tests: the client's ephemeral video port
  TelloVideoStreamStats stats() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace gbdcs::sim
