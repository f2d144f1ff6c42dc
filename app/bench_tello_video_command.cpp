// `gbdcs bench tello-video`: the Tello video path end to end on this machine, in one process:
// the twin (real time) behind its Tello emulator streams its camera after streamon (render
// with OSMesa, encode with libx264, UDP datagrams of 1460 bytes over loopback) to the
// adapter's video source (`tello:`), which decodes it with libavcodec. Reports the frame
// rate received and the time of each stage; --json prints one JSON document.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <iostream>
#include <nlohmann/json.hpp>
#include <vector>

#include "command_registry.hpp"
#include "commands.hpp"
#include "gbdcs/adapters/tello_video_source.hpp"
#include "gbdcs/contracts/clock.hpp"
#include "gbdcs/sim/tello_emulator.hpp"
#include "gbdcs/sim/tello_video_streamer.hpp"
#include "gbdcs/sim/twin_host.hpp"

namespace gbdcs::app {
namespace {

struct BenchTelloVideoOptions {
  int frames = 150;
  int width = 480;
  double fps = 15;
  std::string camera = "onboard";
  bool json = false;
};

// A loopback UDP port that swallows the datagrams sent before the source's port is known.
class Parking {
 public:
  Parking() : fd_(::socket(AF_INET, SOCK_DGRAM, 0)) {
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ::bind(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a);
  }
  ~Parking() { ::close(fd_); }
  int port() const {
    sockaddr_in a{};
    socklen_t n = sizeof a;
    ::getsockname(fd_, reinterpret_cast<sockaddr*>(&a), &n);
    return ntohs(a.sin_port);
  }

 private:
  int fd_;
};

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(p * static_cast<double>(v.size() - 1))];
}

int run_bench_tello_video(const BenchTelloVideoOptions& o) {
  using Wall = std::chrono::steady_clock;
  contracts::SteadyClock clock;
  sim::TwinHost host(clock, std::make_shared<const sim::TwinModel>());
  sim::TelloEmulatorOptions eo;
  eo.command_port = 0;
  sim::TelloEmulator emulator(host, eo);
  Parking parking;
  emulator.set_state_port(parking.port());
  sim::TelloVideoStreamOptions so;
  so.width = o.width / 2 * 2;
  so.height = o.width * 3 / 4 / 2 * 2;
  so.fps = o.fps;
  so.camera = o.camera;
  so.client_port = parking.port();
  sim::TelloVideoStreamer streamer(host, so);
  streamer.attach(emulator);
  host.start();
  host.with_sim([](sim::TwinSim& s) { return s.takeoff(); });  // a moving picture

  adapters::TelloVideoOptions vo;
  vo.address = "127.0.0.1";
  vo.command_port = emulator.port();
  vo.bind_address = "127.0.0.1";
  vo.video_port = 0;
  vo.reply_timeout_ms = 3000;
  vo.first_frame_timeout_s = 30;
  vo.stall_timeout_s = 10;
  const auto opened = Wall::now();
  adapters::TelloVideoSource source(vo, clock);
  streamer.set_client_port(source.local_video_port());
  std::vector<double> gaps_ms;
  double first_frame_ms = 0;
  auto last = Wall::now();
  for (int i = 0; i < o.frames; ++i) {
    auto f = source.next();
    const auto now = Wall::now();
    if (i == 0) first_frame_ms = std::chrono::duration<double, std::milli>(now - opened).count();
    else gaps_ms.push_back(std::chrono::duration<double, std::milli>(now - last).count());
    last = now;
  }
  const auto vs = source.stats();
  const auto ss = streamer.stats();
  host.stop();
  double mean_gap = 0;
  for (double g : gaps_ms) mean_gap += g;
  mean_gap = gaps_ms.empty() ? 0 : mean_gap / static_cast<double>(gaps_ms.size());
  const double seconds = mean_gap * static_cast<double>(gaps_ms.size()) / 1000.0;
  nlohmann::json doc = {
      {"frames", o.frames},
      {"width_px", vs.width},
      {"height_px", vs.height},
      {"fps_target", o.fps},
      {"fps_received", mean_gap > 0 ? 1000.0 / mean_gap : 0.0},
      {"frame_gap_ms_p95", percentile(gaps_ms, 0.95)},
      {"first_frame_ms", first_frame_ms},
      {"decode_ms_mean", vs.decode_ms_mean},
      {"decode_ms_max", vs.decode_ms_max},
      {"render_ms_mean", ss.render_ms_mean},
      {"encode_ms_mean", ss.encode_ms_mean},
      {"late_frames", ss.late_frames},
      {"frames_skipped_by_source", vs.frames_skipped},
      {"datagrams_per_frame", vs.frames_decoded ? static_cast<double>(vs.datagrams) /
                                                      static_cast<double>(vs.frames_decoded)
                                                : 0.0},
      {"bitrate_kbps", seconds > 0 ? static_cast<double>(vs.bytes) * 8 / 1000 / seconds : 0.0},
      {"encoder", ss.encoder}};
  if (o.json) {
    std::cout << doc.dump(2) << "\n";
  } else {
    std::cout << "tello video " << vs.width << "x" << vs.height << " (" << ss.encoder << "): "
              << doc["fps_received"].get<double>() << " fps received of " << o.fps
              << ", first frame after " << first_frame_ms << " ms; per frame: render "
              << ss.render_ms_mean << " ms, encode " << ss.encode_ms_mean << " ms, decode "
              << vs.decode_ms_mean << " ms (max " << vs.decode_ms_max << ")\n";
  }
  return 0;
}

void add_bench_tello_video(CLI::App& app) {
  static BenchTelloVideoOptions o;
  auto* cmd = group_command(app, "bench", "Benchmarks")
                  ->add_subcommand("tello-video",
                                   "The Tello video path on loopback: the twin's emulator "
                                   "streams H.264 after streamon, the tello: source decodes; "
                                   "frame rate and per-stage times");
  cmd->add_option("--frames", o.frames, "Frames to receive")
      ->capture_default_str()
      ->check(CLI::Range(2, 100000));
  cmd->add_option("--width", o.width, "Video width (height 3/4 of it; a real Tello: 960)")
      ->capture_default_str()
      ->check(CLI::Range(64, 1920));
  cmd->add_option("--fps", o.fps, "Frame rate the emulator streams (a real Tello: 30)")
      ->capture_default_str()
      ->check(CLI::Range(1.0, 60.0));
  cmd->add_option("--camera", o.camera, "The twin's camera")
      ->capture_default_str()
      ->check(CLI::IsMember({"onboard", "chase", "overview"}));
  cmd->add_flag("--json", o.json, "One JSON document");
  cmd->callback([] {
    try {
      g_exit_code = run_bench_tello_video(o);
    } catch (const std::exception& e) {
      std::cerr << "gbdcs bench tello-video: " << e.what() << "\n";
      g_exit_code = 2;
    }
  });
}

const CommandRegistration kBenchTelloVideo{61, &add_bench_tello_video};

}  // namespace
}  // namespace gbdcs::app
