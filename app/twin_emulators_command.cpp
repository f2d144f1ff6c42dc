// `gbdcs twin --tello [--tello-port 8889]`: the MuJoCo twin in real time, answering the Tello
// SDK on UDP (and, as they land, AirSim's RPC and the XFly profile) on loopback by default,
// so the real adapters and any third-party client can fly it. Runs until Ctrl-C or
// --duration; one status line per second on stderr.
#include <atomic>
#include <chrono>
#include <csignal>
#include <cmath>
#include <iomanip>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <memory>
#include <optional>
#include <thread>

#include "commands.hpp"
#include "gbdcs/sim/airsim_emulator.hpp"
#include "gbdcs/sim/tello_emulator.hpp"
#include "gbdcs/sim/tello_video_streamer.hpp"
#include "gbdcs/sim/twin_host.hpp"
#include "twin_emulators.hpp"

namespace gbdcs::app {
namespace {

struct EmulatorCmdOptions {
  bool tello = false;
  int tello_port = 8889;
  int tello_state_port = 8890;
  std::string tello_sdk = "2.0";
  bool tello_no_video = false;
  int tello_video_port = 11111;
  std::string tello_video_camera = "onboard";
  double tello_video_fps = 15;
  int tello_video_width = 480;
  bool airsim = false;
  int airsim_port = 41451;
  std::string airsim_vehicle = "Drone1";
  bool xfly = false;
  int xfly_port = 9889;
  int xfly_state_port = 9890;
  std::string xfly_profile;
  std::string bind = "127.0.0.1";
  double duration_s = 0;
  unsigned seed = 1;
  std::string faults;
};

EmulatorCmdOptions g_options;
std::atomic<bool> g_stop{false};

extern "C" void on_signal(int) { g_stop = true; }

}  // namespace

void add_twin_emulator_options(CLI::App* twin) {
  auto& o = g_options;
  twin->add_flag("--tello", o.tello,
                 "Serve the twin as a Tello (SDK 2.0 over UDP) in real time instead of flying "
                 "a script (docs/ADAPTERS.md)");
  twin->add_option("--tello-port", o.tello_port, "UDP port of the Tello commands (0: any)")
      ->capture_default_str()
      ->check(CLI::Range(0, 65535));
  twin->add_option("--tello-state-port", o.tello_state_port,
                   "The client's UDP port the Tello state goes to")
      ->capture_default_str()
      ->check(CLI::Range(1, 65535));
  twin->add_option("--tello-sdk", o.tello_sdk, "Tello SDK the emulator speaks")
      ->capture_default_str()
      ->check(CLI::IsMember({"2.0", "1.3"}));
  twin->add_flag("--tello-no-video", o.tello_no_video,
                 "Answer streamon/streamoff with ok but send no video (saves the rendering)");
  twin->add_option("--tello-video-port", o.tello_video_port,
                   "The client's UDP port the H.264 video goes to after streamon (a Tello's: "
                   "11111)")
      ->capture_default_str()
      ->check(CLI::Range(1, 65535));
  twin->add_option("--tello-video-camera", o.tello_video_camera,
                   "The twin's camera in the video: onboard (the Tello's front camera) or chase")
      ->capture_default_str()
      ->check(CLI::IsMember({"onboard", "chase", "overview"}));
  twin->add_option("--tello-video-fps", o.tello_video_fps,
                   "Video frame rate (a real Tello: 30; rendering on the CPU: keep it modest)")
      ->capture_default_str()
      ->check(CLI::Range(1.0, 60.0));
  twin->add_option("--tello-video-size", o.tello_video_width,
                   "Video width; the height is 3/4 of it (a real Tello: 960x720)")
      ->capture_default_str()
      ->check(CLI::Range(64, 1920));
  twin->add_flag("--airsim", o.airsim,
                 "Serve the twin as an AirSim multirotor (msgpack-RPC over TCP) in real time");
  twin->add_option("--airsim-port", o.airsim_port, "TCP port of the AirSim RPC (0: any)")
      ->capture_default_str()
      ->check(CLI::Range(0, 65535));
  twin->add_option("--airsim-vehicle", o.airsim_vehicle,
                   "Vehicle name the AirSim emulator answers to (besides \"\")")
      ->capture_default_str();
  twin->add_flag("--xfly", o.xfly,
                 "Serve the twin as an XFly (the assumed Tello-style text-over-UDP profile)");
  twin->add_option("--xfly-port", o.xfly_port, "UDP port of the XFly commands (0: any)")
      ->capture_default_str()
      ->check(CLI::Range(0, 65535));
  twin->add_option("--xfly-state-port", o.xfly_state_port,
                   "The client's UDP port the XFly state goes to")
      ->capture_default_str()
      ->check(CLI::Range(1, 65535));
  twin->add_option("--xfly-profile", o.xfly_profile,
                   "JSON file {\"commands\": {takeoff, land, ...}} renaming the XFly's command "
                   "words (docs/ADAPTERS.md)");
  twin->add_option("--bind", o.bind,
                   "Address the emulators listen on (loopback by default; 0.0.0.0 to let "
                   "another machine fly the twin)")
      ->capture_default_str();
  twin->add_option("--duration", o.duration_s,
                   "With an emulator: stop after this many seconds (0: until Ctrl-C)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 86400.0));
  twin->add_option("--faults", o.faults,
                   "With an emulator: a fault schedule JSON file (docs/TWIN.md; link_loss drops "
                   "the protocol traffic)");
}

bool twin_emulators_requested() { return g_options.tello || g_options.airsim || g_options.xfly; }

int run_twin_emulators() {
  const auto& o = g_options;
  contracts::SteadyClock clock;
  sim::TwinHostOptions host_options;
  host_options.seed = o.seed;
  if (!o.faults.empty()) host_options.twin.faults = sim::FaultSchedule::load(o.faults);
  sim::TwinHost host(clock, std::make_shared<const sim::TwinModel>(), host_options);

  std::optional<sim::TelloEmulator> tello;
  std::optional<sim::TelloVideoStreamer> tello_video;  // destroyed before the emulator
  if (o.tello) {
    sim::TelloEmulatorOptions t;
    t.bind_address = o.bind;
    t.command_port = o.tello_port;
    t.state_port = o.tello_state_port;
    t.sdk = o.tello_sdk;
    tello.emplace(host, t);
    std::cerr << "gbdcs twin: Tello SDK " << o.tello_sdk << " on udp://" << o.bind << ":"
              << tello->port() << " (state to the client's port " << o.tello_state_port
              << ")\n";
    if (!o.tello_no_video) {
      sim::TelloVideoStreamOptions v;
      v.client_port = o.tello_video_port;
      v.camera = o.tello_video_camera;
      v.fps = o.tello_video_fps;
      v.width = o.tello_video_width / 2 * 2;
      v.height = o.tello_video_width * 3 / 4 / 2 * 2;
      tello_video.emplace(host, v);
      tello_video->attach(*tello);
      std::cerr << "gbdcs twin: Tello video after streamon: H.264 " << v.width << "x" << v.height
                << " at " << v.fps << " fps of the " << v.camera
                << " camera to the client's UDP port " << v.client_port << "\n";
    }
  }
  std::optional<sim::AirSimEmulator> airsim;
  if (o.airsim) {
    sim::AirSimEmulatorOptions a;
    a.bind_address = o.bind;
    a.port = o.airsim_port;
    a.vehicle = o.airsim_vehicle;
    airsim.emplace(host, a);
    std::cerr << "gbdcs twin: AirSim RPC on tcp://" << o.bind << ":" << airsim->port()
              << " (vehicle \"" << o.airsim_vehicle << "\" or \"\")\n";
  }
  std::optional<sim::TelloEmulator> xfly;
  if (o.xfly) {
    nlohmann::json profile = nlohmann::json::object();
    if (!o.xfly_profile.empty()) {
      std::ifstream in(o.xfly_profile);
      if (!in) throw std::invalid_argument("--xfly-profile: cannot read " + o.xfly_profile);
      profile = nlohmann::json::parse(in, nullptr, false);
      if (profile.is_discarded() || !profile.is_object()) {
        throw std::invalid_argument("--xfly-profile " + o.xfly_profile +
                                    ": not a JSON object like {\"commands\": {...}}");
      }
    }
    profile["bind_address"] = o.bind;
    profile["command_port"] = o.xfly_port;
    profile["state_port"] = o.xfly_state_port;
    auto x = sim::TelloEmulatorOptions::from_json(profile);
    x.label = "xfly";
    xfly.emplace(host, x);
    std::cerr << "gbdcs twin: XFly profile on udp://" << o.bind << ":" << xfly->port()
              << " (state to the client's port " << o.xfly_state_port << ")\n";
  }
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  host.start();
  const auto start = std::chrono::steady_clock::now();
  auto next_status = start;
  while (!g_stop) {
    const auto now = std::chrono::steady_clock::now();
    if (o.duration_s > 0 && now - start >= std::chrono::duration<double>(o.duration_s)) break;
    if (now >= next_status) {
      next_status += std::chrono::seconds(1);
      const auto s = host.with_sim([](sim::TwinSim& sim) { return sim.status(); });
      std::cerr << "gbdcs twin: t=" << std::fixed << std::setprecision(1) << s.time_s << " s "
                << sim::to_string(s.mode) << " alt " << std::setprecision(2) << s.z_m
                << " m, heading " << std::setprecision(0) << s.heading_deg << " deg, battery "
                << std::setprecision(1) << s.battery_pct << " %";
      if (tello) {
        const auto st = tello->stats();
        std::cerr << "; tello " << st.datagrams << " datagrams, " << st.state_packets
                  << " states";
      }
      if (tello_video && tello_video->streaming()) {
        const auto st = tello_video->stats();
        std::cerr << "; video " << st.frames << " frames, " << st.datagrams << " datagrams";
      }
      if (airsim) {
        const auto st = airsim->stats();
        std::cerr << "; airsim " << st.connections << " connections, " << st.requests
                  << " requests";
      }
      std::cerr << "\n";
      std::cerr.unsetf(std::ios::fixed);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  host.stop();
  std::cerr << "gbdcs twin: stopped\n";
  return 0;
}

}  // namespace gbdcs::app
