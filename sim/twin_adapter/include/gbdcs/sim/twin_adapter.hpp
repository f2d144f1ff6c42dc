// TwinAdapter: the MuJoCo twin (sim::TwinSim) behind control::DroneAdapter, so the core flies
// it exactly like the dummy or a real drone. Registered in the app as "twin".
//
// States : INIT -connect-> READY -takeoff-> FLYING (taking off or flying) -land-> LANDING ->
//          READY on touch-down. emergency_stop cuts the motors: LANDING while it falls, READY
//          on the ground, FAULT when it crashed (FAULT refuses everything).
// Commands (Tello semantics on the twin): takeoff, land, emergency, hover (rc 0 0 0 0: brake
//          and hold); move(MotionPayload) -> rc a b c d = 100 * (vy, vx, vz, yaw rate) / the
//          twin's configured maxima (TwinOptions::controller), rounded and clamped to +-100,
//          held for duration_s of simulated time then rc 0 0 0 0 (duration_s 0: until the next
//          command). Any command cancels a pending timed stop. A refusal of the twin is
//          kRejected with its reason in last_error(); nothing throws across the interface.
// Telemetry: sampled every 1/telemetry_hz s of SIMULATED time while connected; a frame
//          carries the UTC time of its sample (from the injected Clock), altitude (>= 0), 3-D
//          speed, body velocity, x/y and heading relative to the pose at the first connect(),
//          battery, flight state and link OK.
// Time   : simulated time = clock.now() - clock.now() at construction.
//          lockstep (default): poll() advances the twin to the clock's now and delivers the
//            frames due (scenario runner, `gbdcs fly`, tests on a ManualClock).
//          realtime: connect() starts a thread that advances to clock.now() realtime_step_hz
//            times a second and delivers frames itself; poll() does nothing.
// Faults : the schedule (TwinOptions::faults or set_faults()) runs on simulated time. TwinSim
//          applies the physical ones; the adapter applies the radio: during link_loss every
//          command returns kNotConnected (a timed stop falls due then is sent when the link is
//          back) and frames sampled or due then are lost; telemetry_delay delivers each frame
//          delay + seeded jitter late, never out of order.
// Options (JSON keys, defaults): telemetry_hz 30 (20...200), realtime false,
//          realtime_step_hz 200 (10...2000), seed 1, model "" (TwinModel::default_model_path()),
//          twin {} (TwinOptions::from_json: controller, battery, crash_speed_m_s,
//          auto_land_after_s, faults).
// View   : control::DroneViewSource: start_view() renders the twin's "chase" camera
//          (sim/render, OSMesa on the CPU) on a thread of its own at options.fps (wall time; 0 < fps <= 30, 16...1920 x
//          16...1080 px), from a copy of the state taken under the lock between steps, JPEG
//          encoded, to the sink; stop_view(), disconnect() and the destructor end it. A
//          renderer that cannot start (no OSMesa) ends the view with last_error() set.
// Threads: every call may come from any thread; one mutex serialises them. The sink is called
//          without the lock held (from poll() or the realtime thread).
#pragma once

#include <array>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "gbdcs/contracts/clock.hpp"
#include "gbdcs/control/drone_adapter.hpp"
#include "gbdcs/control/drone_view.hpp"
#include "gbdcs/sim/twin_sim.hpp"

namespace gbdcs::sim {

struct TwinAdapterOptions {
  double telemetry_hz = 30;
  bool realtime = false;
  double realtime_step_hz = 200;
  std::uint32_t seed = 1;
  std::string model_path;  // empty: TwinModel::default_model_path()
  TwinOptions twin;

  static TwinAdapterOptions from_json(const nlohmann::json& doc);  // throws std::invalid_argument
};

// The rc sticks for a motion: a = right, b = forward, c = up, d = yaw clockwise, each
// round(100 * value / maximum) clamped to [-100, 100].
std::array<int, 4> motion_to_rc(const contracts::MotionPayload& motion,
                                const FlightControllerOptions& maxima);

contracts::FlightState flight_state_of(TwinMode mode);

class TwinAdapter final : public control::DroneAdapter, public control::DroneViewSource {
 public:
  TwinAdapter(const contracts::Clock& clock, TwinAdapterOptions options = {});
  // Shares an already loaded model (tests, several twins); options.model_path is ignored.
  TwinAdapter(const contracts::Clock& clock, std::shared_ptr<const TwinModel> model,
              TwinAdapterOptions options = {});
  ~TwinAdapter() override;
  TwinAdapter(const TwinAdapter&) = delete;
  TwinAdapter& operator=(const TwinAdapter&) = delete;

  std::string_view name() const override { return "twin"; }
  control::Result connect() override;
  control::Result disconnect() override;
  control::Result takeoff() override;
  control::Result land() override;
  control::Result hover() override;
  control::Result move(const contracts::MotionPayload& motion) override;
  control::Result emergency_stop() override;
  contracts::FlightState state() const override;
  void set_telemetry_sink(control::TelemetrySink sink) override;
  void poll() override;
  std::string last_error() const override;
  control::Result start_view(const control::ViewOptions& options,
                             control::ViewSink sink) override;
  void stop_view() override;

  // Twin-specific: the Tello rc command itself (each -100...100), held until the next command.
  control::Result rc(int a, int b, int c, int d);
  void set_faults(FaultSchedule faults);
  double sim_time_s() const;
  TwinStatus twin_status() const;
  // The frame the adapter would send now (no fault applied), for tools and tests.
  contracts::TelemetryFrame snapshot() const;
  // Runs `fn` on the twin with the lock held, between steps (e.g. render its mjData).
  void inspect(const std::function<void(const TwinSim&)>& fn) const;
  const TwinAdapterOptions& options() const { return options_; }

 private:
  struct PendingFrame {
    double deliver_at_s = 0;
    contracts::TelemetryFrame frame;
  };

  double clock_sim_s() const;
  void advance_locked(double t_s);
  void sample_locked(double t_s, double now_s, contracts::UtcTime utc_now);
  contracts::TelemetryFrame frame_locked(const TwinStatus& s) const;
  control::Result guard_locked(const char* what);
  control::Result send_locked(const char* what, const std::function<CommandResult()>& command);
  void start_thread_locked();
  void stop_thread();
  void thread_main();
  void view_main(control::ViewOptions options, control::ViewSink sink);

  const contracts::Clock& clock_;
  TwinAdapterOptions options_;
  std::shared_ptr<const TwinModel> model_;
  contracts::Duration origin_;

  mutable std::mutex mutex_;
  std::unique_ptr<TwinSim> sim_;
  control::TelemetrySink sink_;
  bool connected_ = false;
  bool ever_connected_ = false;
  double origin_x_m_ = 0, origin_y_m_ = 0, origin_heading_deg_ = 0;
  std::int64_t next_sample_ = 0;  // index k of the next sample at k / telemetry_hz
  bool stop_pending_ = false;     // a timed move ends with rc 0 0 0 0 at stop_at_s_
  double stop_at_s_ = 0;
  std::deque<PendingFrame> in_flight_;  // sampled, not yet delivered (telemetry delay)
  double last_deliver_at_s_ = 0;
  std::vector<contracts::TelemetryFrame> ready_;  // delivered, waiting for the sink
  std::string last_error_;

  std::mutex sink_mutex_;  // frames reach the sink in order, one caller at a time
  std::mutex thread_mutex_;
  std::condition_variable thread_cv_;
  bool thread_stop_ = false;
  std::thread thread_;

  std::mutex view_mutex_;
  std::condition_variable view_cv_;
  bool view_stop_ = false;
  std::thread view_thread_;
};

}  // namespace gbdcs::sim
