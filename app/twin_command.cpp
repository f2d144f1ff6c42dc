// `gbdcs twin`: flies a command script on the MuJoCo twin through its TwinAdapter and prints
// the telemetry as JSON lines; optionally records an MP4 and a trajectory plot.
// `gbdcs bench twin`: physics speed without rendering and the 640x480 render time.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include "command_registry.hpp"
#include "commands.hpp"
#include "gbdcs/contracts/codec.hpp"
#include "gbdcs/sim/command_script.hpp"
#include "gbdcs/sim/renderer.hpp"
#include "gbdcs/sim/trajectory_plot.hpp"
#include "gbdcs/sim/twin_adapter.hpp"
#include "gbdcs/sim/video_recorder.hpp"
#include "twin_emulators.hpp"

namespace gbdcs::app {
namespace {

struct TwinCmdOptions {
  std::string script;
  std::string record;
  std::string plot;
  bool realtime = false;
  std::string camera = "chase";
  int width = 640;
  int height = 480;
  double fps = 30;
};

// Records frames of the twin's state on the calling thread (the Renderer's GL context is
// bound to the thread that made it).
class RunRecorder {
 public:
  RunRecorder(const TwinCmdOptions& o, const sim::TwinModel& model) : camera_(o.camera) {
    sim::RendererOptions ro;
    ro.width = o.width;
    ro.height = o.height;
    renderer_ = std::make_unique<sim::Renderer>(model.mj_model(), ro);
    const auto cameras = renderer_->camera_names();
    if (std::find(cameras.begin(), cameras.end(), camera_) == cameras.end()) {
      throw std::invalid_argument("--camera " + camera_ + ": the model has no such camera");
    }
    sim::VideoRecorderOptions vo;
    vo.fps = o.fps;
    video_ = std::make_unique<sim::VideoRecorder>(o.record, cv::Size(o.width, o.height), vo);
  }
  void capture(const sim::TwinAdapter& twin) {
    cv::Mat frame;
    twin.inspect([&](const sim::TwinSim& s) { frame = renderer_->render(s.data(), camera_); });
    video_->write(frame);
  }
  void close() { video_->close(); }
  const sim::VideoRecorder& video() const { return *video_; }

 private:
  std::string camera_;
  std::unique_ptr<sim::Renderer> renderer_;
  std::unique_ptr<sim::VideoRecorder> video_;
};

int run_twin(const TwinCmdOptions& o) {
  const auto script = o.script.empty() ? sim::CommandScript::builtin_demo()
                                       : sim::CommandScript::load_file(o.script);
  sim::TwinAdapterOptions options;
  options.seed = script.seed;
  options.realtime = o.realtime;
  options.twin.faults = script.faults;
  auto model = std::make_shared<const sim::TwinModel>();

  // Simulated time starts at the real UTC now, so the frames carry today's date.
  contracts::ManualClock manual_clock(
      std::chrono::time_point_cast<std::chrono::milliseconds>(std::chrono::system_clock::now()));
  contracts::SteadyClock steady_clock;
  const contracts::Clock& clock =
      o.realtime ? static_cast<const contracts::Clock&>(steady_clock) : manual_clock;
  const auto start = clock.now();
  const auto utc_start = clock.utc_now();
  sim::TwinAdapter twin(clock, model, options);

  std::optional<RunRecorder> recorder;
  if (!o.record.empty()) recorder.emplace(o, *model);

  std::mutex out_mutex;
  std::vector<sim::TrajectorySample> samples;
  twin.set_telemetry_sink([&](const contracts::TelemetryFrame& f) {
    std::lock_guard lock(out_mutex);
    std::cout << contracts::encode(f) << "\n";
    sim::TrajectorySample s;  // the plot's default frame is the contracts' one
    s.time_s = std::chrono::duration<double>(f.timestamp - utc_start).count();
    s.x_m = f.x_m;
    s.y_m = f.y_m;
    s.altitude_m = f.altitude_m;
    s.heading_deg = f.heading_deg;
    s.battery_pct = f.battery_pct;
    samples.push_back(s);
  });
  if (auto r = twin.connect(); r != control::Result::kOk) {
    std::cerr << "gbdcs twin: cannot connect: " << twin.last_error() << "\n";
    return 1;
  }
  std::cerr << "gbdcs twin: " << script.commands.size() << " commands over " << script.duration_s
            << " s (" << (o.realtime ? "real time" : "simulated time") << ", seed " << script.seed
            << ", " << script.faults.faults().size() << " faults)\n";

  sim::ScriptHooks hooks;
  hooks.wait_until = [&](double t_s) {
    const auto target = start + contracts::from_seconds(t_s);
    if (!o.realtime) {
      manual_clock.set(target);
      twin.poll();
      return;
    }
    for (auto now = clock.now(); now < target; now = clock.now()) {
      std::this_thread::sleep_for(
          std::min<contracts::Duration>(target - now, std::chrono::milliseconds(10)));
    }
  };
  int refused = 0;
  hooks.on_command = [&](const sim::ScriptCommand& c, control::Result r, const std::string& e) {
    if (r != control::Result::kOk) ++refused;
    std::lock_guard lock(out_mutex);
    std::cerr << "gbdcs twin: t=" << std::fixed << std::setprecision(2) << c.at_s << " "
              << sim::to_string(c.cmd);
    if (c.cmd == sim::ScriptCmd::kRc) {
      for (int v : c.rc) std::cerr << " " << v;
    }
    std::cerr << " -> " << control::to_string(r) << (e.empty() ? "" : " (" + e + ")") << "\n";
    std::cerr.unsetf(std::ios::fixed);
  };
  if (recorder) {
    hooks.frame_period_s = 1.0 / o.fps;
    hooks.on_frame = [&](double) { recorder->capture(twin); };
  }
  sim::run_script(script, twin, hooks);
  twin.disconnect();

  const auto status = twin.twin_status();
  std::cout.flush();  // the telemetry before the summary, also when both go to one pipe
  std::cerr << "gbdcs twin: done at " << status.time_s << " s: " << sim::to_string(status.mode)
            << ", battery " << std::round(status.battery_pct * 10) / 10 << " %, "
            << status.collisions << " collisions, " << refused << " commands refused\n";
  if (recorder) {
    recorder->close();
    std::cerr << "gbdcs twin: video " << o.record << " (" << recorder->video().frames_written()
              << " frames, " << recorder->video().codec() << ", camera " << o.camera << ")\n";
  }
  if (!o.plot.empty()) {
    if (samples.empty()) throw std::runtime_error("--plot: no telemetry to plot");
    sim::PlotOptions po;
    po.title = o.script.empty() ? "twin run (built-in script)" : "twin run: " + o.script;
    sim::TrajectoryPlot plot;
    plot.draw(samples, po);
    plot.save(o.plot);
    std::cerr << "gbdcs twin: plot " << o.plot << " (" << samples.size() << " samples)\n";
  }
  return 0;
}

// ---- bench ------------------------------------------------------------------------------

struct BenchTwinOptions {
  bool json = false;
  double sim_s = 60;
  int render_frames = 100;
};

double percentile(std::vector<double> v, double p) {
  std::sort(v.begin(), v.end());
  const auto i = static_cast<std::size_t>(std::ceil(p / 100.0 * static_cast<double>(v.size())));
  return v[std::clamp<std::size_t>(i, 1, v.size()) - 1];
}

int run_bench_twin(const BenchTwinOptions& o) {
  auto model = std::make_shared<const sim::TwinModel>();
  nlohmann::json out;
  out["physics_sim_s"] = o.sim_s;
  out["physics_realtime_factor"] = sim::measure_physics_realtime_factor(model, o.sim_s);

  // A drone in the air, seen by the chase camera: the frame `gbdcs twin --record` renders.
  sim::TwinSim twin(model, {}, 1);
  twin.takeoff();
  twin.step_to(3.0);
  sim::Renderer renderer(model->mj_model(), {});
  for (int i = 0; i < 3; ++i) renderer.render(twin.data(), "chase");
  std::vector<double> ms;
  for (int i = 0; i < o.render_frames; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    renderer.render(twin.data(), "chase");
    ms.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  out["render_frames"] = o.render_frames;
  out["render_640x480_ms_p50"] = percentile(ms, 50);
  out["render_640x480_ms_p95"] = percentile(ms, 95);
  if (o.json) {
    std::cout << out.dump() << "\n";
  } else {
    for (const auto& [k, v] : out.items())
      std::cout << std::left << std::setw(28) << k << v << "\n";
  }
  return 0;
}

}  // namespace

void add_twin_command(CLI::App& app) {
  static TwinCmdOptions o;
  auto* cmd = app.add_subcommand(
      "twin",
      "Fly a command script on the MuJoCo twin (through its TwinAdapter) and print the "
      "telemetry as JSON lines; optionally record an MP4 and a trajectory plot");
  cmd->add_option("--script", o.script,
                  "Command script JSON (docs/TWIN.md; default: a built-in take-off, forward, "
                  "yaw, land)");
  cmd->add_option("--record", o.record, "Write an MP4 of the run");
  cmd->add_option("--plot", o.plot, "Write a trajectory plot PNG");
  cmd->add_flag("--realtime", o.realtime, "Pace the run with the wall clock");
  cmd->add_option("--camera", o.camera, "Camera for --record")
      ->capture_default_str()
      ->check(CLI::IsMember({"chase", "onboard"}));
  cmd->add_option("--width", o.width, "Video width (px)")
      ->capture_default_str()
      ->check(CLI::Range(16, 4096));
  cmd->add_option("--height", o.height, "Video height (px)")
      ->capture_default_str()
      ->check(CLI::Range(16, 4096));
  cmd->add_option("--fps", o.fps, "Video frames per simulated second")
      ->capture_default_str()
      ->check(CLI::Range(1.0, 240.0));
  add_twin_emulator_options(cmd);
  cmd->callback([] {
    try {
      g_exit_code = twin_emulators_requested() ? run_twin_emulators() : run_twin(o);
    } catch (const std::exception& e) {
      std::cerr << "gbdcs twin: " << e.what() << "\n";
      g_exit_code = 2;
    }
  });

  static BenchTwinOptions b;
  auto* bench = group_command(app, "bench", "Benchmarks")->add_subcommand(
      "twin",
      "Twin physics speed (sim s per wall s, one thread, no rendering) and 640x480 "
      "render time");
  bench->add_flag("--json", b.json, "One JSON object");
  bench->add_option("--sim-s", b.sim_s, "Simulated seconds for the physics figure")
      ->capture_default_str()
      ->check(CLI::Range(1.0, 3600.0));
  bench->add_option("--frames", b.render_frames, "Timed renders")
      ->capture_default_str()
      ->check(CLI::Range(5, 10000));
  bench->callback([] {
    try {
      g_exit_code = run_bench_twin(b);
    } catch (const std::exception& e) {
      std::cerr << "gbdcs bench twin: " << e.what() << "\n";
      g_exit_code = 2;
    }
  });
}

}  // namespace gbdcs::app
