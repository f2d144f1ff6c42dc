#include "gbdcs/sim/twin_adapter.hpp"

#include <mujoco/mujoco.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>

#include "gbdcs/contracts/json_options.hpp"
#include "gbdcs/sim/renderer.hpp"

namespace gbdcs::sim {

using contracts::FlightState;
using control::Result;

namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;

int stick(double value, double maximum) {
  if (maximum <= 0 || !std::isfinite(value)) return 0;
  const double scaled = std::round(100.0 * value / maximum);
  return static_cast<int>(std::clamp(scaled, -100.0, 100.0));
}

double wrap_deg(double deg) {
  double w = std::fmod(deg, 360.0);
  if (w < 0) w += 360.0;
  return w >= 360.0 ? 0.0 : w;
}

}  // namespace

TwinAdapterOptions TwinAdapterOptions::from_json(const nlohmann::json& doc) {
  const std::string owner = "twin options";
  if (!doc.is_object()) {
    throw std::invalid_argument(owner + ": options must be a JSON object, got " +
                                std::string(doc.type_name()));
  }
  TwinAdapterOptions o;
  // Numbers through the shared reader; the other keys by hand, then the reader's unknown-key
  // check on what is left.
  nlohmann::json numbers = doc;
  if (auto it = doc.find("realtime"); it != doc.end()) {
    if (!it->is_boolean()) {
      throw std::invalid_argument(owner + ": 'realtime' must be true or false, got " + it->dump());
    }
    o.realtime = it->get<bool>();
    numbers.erase("realtime");
  }
  if (auto it = doc.find("seed"); it != doc.end()) {
    if (!it->is_number_unsigned() ||
        it->get<std::uint64_t>() > std::numeric_limits<std::uint32_t>::max()) {
      throw std::invalid_argument(owner + ": 'seed' must be an integer in [0, 4294967295], got " +
                                  it->dump());
    }
    o.seed = static_cast<std::uint32_t>(it->get<std::uint64_t>());
    numbers.erase("seed");
  }
  if (auto it = doc.find("model"); it != doc.end()) {
    if (!it->is_string()) {
      throw std::invalid_argument(owner + ": 'model' must be a path string, got " + it->dump());
    }
    o.model_path = it->get<std::string>();
    numbers.erase("model");
  }
  if (auto it = doc.find("twin"); it != doc.end()) {
    try {
      o.twin = TwinOptions::from_json(*it);
    } catch (const std::exception& e) {
      throw std::invalid_argument(owner + ": 'twin': " + e.what());
    }
    numbers.erase("twin");
  }
  contracts::JsonOptionReader r(numbers, owner);
  r.read("telemetry_hz", o.telemetry_hz);
  r.read("realtime_step_hz", o.realtime_step_hz);
  try {
    r.finish();
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string(e.what()) + " (also: realtime, seed, model, twin)");
  }
  contracts::require(o.telemetry_hz >= 20 && o.telemetry_hz <= 200, owner, "telemetry_hz",
                     "must be within [20, 200]");
  contracts::require(o.realtime_step_hz >= 10 && o.realtime_step_hz <= 2000, owner,
                     "realtime_step_hz", "must be within [10, 2000]");
  return o;
}

std::array<int, 4> motion_to_rc(const contracts::MotionPayload& motion,
                                const FlightControllerOptions& maxima) {
  return {stick(motion.vy_m_s, maxima.max_horizontal_m_s),
          stick(motion.vx_m_s, maxima.max_horizontal_m_s),
          stick(motion.vz_m_s, maxima.max_vertical_m_s),
          stick(motion.yaw_rate_deg_s, maxima.max_yaw_rate_deg_s)};
}

FlightState flight_state_of(TwinMode mode) {
  switch (mode) {
    case TwinMode::kLanded:
      return FlightState::kReady;
    case TwinMode::kTakingOff:
    case TwinMode::kFlying:
      return FlightState::kFlying;
    case TwinMode::kLanding:
    case TwinMode::kFalling:
      return FlightState::kLanding;
    case TwinMode::kCrashed:
      return FlightState::kFault;
  }
  return FlightState::kFault;
}

TwinAdapter::TwinAdapter(const contracts::Clock& clock, TwinAdapterOptions options)
    : TwinAdapter(clock,
                  std::make_shared<const TwinModel>(options.model_path.empty()
                                                        ? TwinModel::default_model_path()
                                                        : options.model_path),
                  options) {}

TwinAdapter::TwinAdapter(const contracts::Clock& clock, std::shared_ptr<const TwinModel> model,
                         TwinAdapterOptions options)
    : clock_(clock), options_(std::move(options)), model_(std::move(model)) {
  if (!model_) throw std::invalid_argument("TwinAdapter: no model");
  if (!(options_.telemetry_hz > 0) || !(options_.realtime_step_hz > 0)) {
    throw std::invalid_argument("TwinAdapter: telemetry_hz and realtime_step_hz must be positive");
  }
  origin_ = clock_.now();
  sim_ = std::make_unique<TwinSim>(model_, options_.twin, options_.seed);
}

TwinAdapter::~TwinAdapter() {
  stop_view();
  stop_thread();
}

double TwinAdapter::clock_sim_s() const {
  return contracts::to_seconds(clock_.now() - origin_);
}

// ---- time -------------------------------------------------------------------------------

void TwinAdapter::advance_locked(double t_s) {
  const double period = 1.0 / options_.telemetry_hz;
  const auto utc_now = clock_.utc_now();
  for (;;) {
    const double sample_t = static_cast<double>(next_sample_) * period;
    double next = sample_t;
    if (stop_pending_) next = std::min(next, stop_at_s_);
    if (next > t_s) break;
    sim_->step_to(next);
    if (sample_t <= next) {
      ++next_sample_;
      if (connected_) sample_locked(sample_t, t_s, utc_now);
    }
    if (stop_pending_ && stop_at_s_ <= next) {
      if (!sim_->link_lost(next)) {
        sim_->rc(0, 0, 0, 0);
        stop_pending_ = false;
      } else {
        stop_at_s_ = next + period;  // the radio is down: try again a frame later
      }
    }
  }
  sim_->step_to(t_s);
  while (!in_flight_.empty() && in_flight_.front().deliver_at_s <= t_s) {
    auto pending = std::move(in_flight_.front());
    in_flight_.pop_front();
    if (sim_->link_lost(pending.deliver_at_s)) continue;  // lost on the way
    ready_.push_back(std::move(pending.frame));
  }
}

void TwinAdapter::sample_locked(double t_s, double now_s, contracts::UtcTime utc_now) {
  if (sim_->link_lost(t_s)) return;  // nothing leaves the drone while the link is down
  PendingFrame p;
  p.frame = frame_locked(sim_->status());
  // The UTC time of the sample: the clock's UTC now minus how long ago (in sim time) it was.
  p.frame.timestamp =
      utc_now - std::chrono::round<std::chrono::milliseconds>(contracts::from_seconds(now_s - t_s));
  p.deliver_at_s = std::max(t_s + sim_->telemetry_delay_s(t_s), last_deliver_at_s_);
  last_deliver_at_s_ = p.deliver_at_s;
  in_flight_.push_back(std::move(p));
}

contracts::TelemetryFrame TwinAdapter::frame_locked(const TwinStatus& s) const {
  contracts::TelemetryFrame f;
  f.timestamp = clock_.utc_now();
  f.altitude_m = std::max(0.0, s.z_m);  // resting contact sinks it a fraction of a mm
  f.speed_m_s = s.speed_m_s;
  f.vx_m_s = s.body_vx_m_s;
  f.vy_m_s = s.body_vy_m_s;
  f.vz_m_s = s.vz_m_s;
  // Session frame: x forward and y right as the drone stood at the first connect().
  const double dx = s.x_m - origin_x_m_;
  const double dy = s.y_m - origin_y_m_;
  const double h0 = origin_heading_deg_ * kDegToRad;
  f.x_m = dx * std::cos(h0) + dy * std::sin(h0);
  f.y_m = -dx * std::sin(h0) + dy * std::cos(h0);
  f.heading_deg = wrap_deg(s.heading_deg - origin_heading_deg_);
  f.battery_pct = std::clamp(s.battery_pct, 0.0, 100.0);
  f.flight_state = ever_connected_ ? flight_state_of(s.mode) : FlightState::kInit;
  f.link = contracts::LinkState::kOk;
  return f;
}

void TwinAdapter::poll() {
  if (options_.realtime) return;  // the adapter's own thread advances and delivers
  std::lock_guard order(sink_mutex_);
  std::vector<contracts::TelemetryFrame> frames;
  control::TelemetrySink sink;
  {
    std::lock_guard lock(mutex_);
    advance_locked(clock_sim_s());
    frames.swap(ready_);
    sink = sink_;
  }
  if (sink) {
    for (const auto& f : frames) sink(f);
  }
}

// ---- commands ---------------------------------------------------------------------------

Result TwinAdapter::guard_locked(const char* what) {
  if (!connected_) {
    last_error_ = std::string(what) + ": not connected (call connect first)";
    return Result::kNotConnected;
  }
  // Commands act at the clock's now, even if nobody polled since it moved.
  advance_locked(std::max(clock_sim_s(), sim_->time_s()));
  if (sim_->link_lost(sim_->time_s())) {
    last_error_ = std::string(what) + ": link lost (the twin does not hear us)";
    return Result::kNotConnected;
  }
  return Result::kOk;
}

Result TwinAdapter::send_locked(const char* what, const std::function<CommandResult()>& command) {
  if (auto r = guard_locked(what); r != Result::kOk) return r;
  const CommandResult reply = command();
  if (!reply.ok) {
    last_error_ = std::string(what) + ": " + reply.error;
    return Result::kRejected;
  }
  stop_pending_ = false;  // a new command replaces a timed move
  return Result::kOk;
}

Result TwinAdapter::connect() {
  std::lock_guard lock(mutex_);
  advance_locked(std::max(clock_sim_s(), sim_->time_s()));
  if (sim_->link_lost(sim_->time_s())) {
    last_error_ = "connect: no answer from the twin (link lost)";
    return Result::kNotConnected;
  }
  if (!ever_connected_) {
    const auto s = sim_->status();
    origin_x_m_ = s.x_m;
    origin_y_m_ = s.y_m;
    origin_heading_deg_ = s.heading_deg;
    ever_connected_ = true;
  }
  connected_ = true;
  // The first frame is the next sample time from now; nothing from before the connect.
  next_sample_ =
      static_cast<std::int64_t>(std::ceil(sim_->time_s() * options_.telemetry_hz - 1e-9));
  in_flight_.clear();
  last_deliver_at_s_ = 0;
  if (options_.realtime) start_thread_locked();
  return Result::kOk;
}

Result TwinAdapter::disconnect() {
  stop_view();
  {
    std::lock_guard lock(mutex_);
    connected_ = false;
    in_flight_.clear();
  }
  stop_thread();
  return Result::kOk;
}

Result TwinAdapter::takeoff() {
  std::lock_guard lock(mutex_);
  return send_locked("takeoff", [this] { return sim_->takeoff(); });
}

Result TwinAdapter::land() {
  std::lock_guard lock(mutex_);
  return send_locked("land", [this] { return sim_->land(); });
}

Result TwinAdapter::hover() {
  std::lock_guard lock(mutex_);
  return send_locked("hover", [this] { return sim_->hover(); });
}

Result TwinAdapter::emergency_stop() {
  std::lock_guard lock(mutex_);
  return send_locked("emergency", [this] { return sim_->emergency(); });
}

Result TwinAdapter::rc(int a, int b, int c, int d) {
  std::lock_guard lock(mutex_);
  for (int v : {a, b, c, d}) {
    if (v < -100 || v > 100) {
      last_error_ = "rc: each value must be within [-100, 100]";
      return Result::kRejected;
    }
  }
  return send_locked("rc", [&] { return sim_->rc(a, b, c, d); });
}

Result TwinAdapter::move(const contracts::MotionPayload& motion) {
  std::lock_guard lock(mutex_);
  if (!(motion.duration_s >= 0) || !std::isfinite(motion.duration_s)) {
    last_error_ = "move: duration_s must be a finite number >= 0";
    return Result::kRejected;
  }
  const auto sticks = motion_to_rc(motion, sim_->options().controller);
  const auto r =
      send_locked("move", [&] { return sim_->rc(sticks[0], sticks[1], sticks[2], sticks[3]); });
  if (r == Result::kOk && motion.duration_s > 0) {
    stop_pending_ = true;
    stop_at_s_ = sim_->time_s() + motion.duration_s;
  }
  return r;
}

// ---- queries ----------------------------------------------------------------------------

FlightState TwinAdapter::state() const {
  std::lock_guard lock(mutex_);
  return ever_connected_ ? flight_state_of(sim_->mode()) : FlightState::kInit;
}

void TwinAdapter::set_telemetry_sink(control::TelemetrySink sink) {
  std::lock_guard lock(mutex_);
  sink_ = std::move(sink);
}

std::string TwinAdapter::last_error() const {
  std::lock_guard lock(mutex_);
  return last_error_;
}

void TwinAdapter::set_faults(FaultSchedule faults) {
  std::lock_guard lock(mutex_);
  sim_->set_faults(std::move(faults));
}

double TwinAdapter::sim_time_s() const {
  std::lock_guard lock(mutex_);
  return sim_->time_s();
}

TwinStatus TwinAdapter::twin_status() const {
  std::lock_guard lock(mutex_);
  return sim_->status();
}

contracts::TelemetryFrame TwinAdapter::snapshot() const {
  std::lock_guard lock(mutex_);
  return frame_locked(sim_->status());
}

void TwinAdapter::inspect(const std::function<void(const TwinSim&)>& fn) const {
  std::lock_guard lock(mutex_);
  fn(*sim_);
}

// ---- real time --------------------------------------------------------------------------

void TwinAdapter::start_thread_locked() {
  if (thread_.joinable()) return;
  {
    std::lock_guard tl(thread_mutex_);
    thread_stop_ = false;
  }
  thread_ = std::thread([this] { thread_main(); });
}

void TwinAdapter::stop_thread() {
  {
    std::lock_guard tl(thread_mutex_);
    thread_stop_ = true;
  }
  thread_cv_.notify_all();
  if (thread_.joinable() && thread_.get_id() != std::this_thread::get_id()) thread_.join();
}

void TwinAdapter::thread_main() {
  const auto period = std::chrono::duration_cast<std::chrono::nanoseconds>(
      std::chrono::duration<double>(1.0 / options_.realtime_step_hz));
  std::unique_lock tl(thread_mutex_);
  while (!thread_stop_) {
    tl.unlock();
    {
      std::lock_guard order(sink_mutex_);
      std::vector<contracts::TelemetryFrame> frames;
      control::TelemetrySink sink;
      {
        std::lock_guard lock(mutex_);
        advance_locked(std::max(clock_sim_s(), sim_->time_s()));
        frames.swap(ready_);
        sink = sink_;
      }
      if (sink) {
        for (const auto& f : frames) sink(f);
      }
    }
    tl.lock();
    thread_cv_.wait_for(tl, period, [this] { return thread_stop_; });
  }
}

// ---- view (the chase camera) -----------------------------------------------------------

Result TwinAdapter::start_view(const control::ViewOptions& options, control::ViewSink sink) {
  const bool ok = options.fps > 0 && options.fps <= 30 && options.width >= 16 &&
                  options.width <= 1920 && options.height >= 16 && options.height <= 1080 &&
                  options.jpeg_quality >= 1 && options.jpeg_quality <= 100 && sink;
  if (!ok) {
    std::lock_guard lock(mutex_);
    last_error_ =
        "view: fps must be in (0, 30], width 16...1920, height 16...1080, jpeg_quality "
        "1...100, and a sink given";
    return Result::kRejected;
  }
  stop_view();
  {
    std::lock_guard vl(view_mutex_);
    view_stop_ = false;
  }
  view_thread_ = std::thread([this, options, sink = std::move(sink)]() mutable {
    view_main(options, std::move(sink));
  });
  return Result::kOk;
}

void TwinAdapter::stop_view() {
  {
    std::lock_guard vl(view_mutex_);
    view_stop_ = true;
  }
  view_cv_.notify_all();
  if (view_thread_.joinable() && view_thread_.get_id() != std::this_thread::get_id()) {
    view_thread_.join();
  }
}

void TwinAdapter::view_main(control::ViewOptions options, control::ViewSink sink) {
  const mjModel* m = model_->mj_model();
  mjData* copy = nullptr;
  try {
    // The renderer's GL context belongs to this thread: made, used and destroyed here.
    RendererOptions ro;
    ro.width = options.width;
    ro.height = options.height;
    Renderer renderer(m, ro);
    copy = mj_makeData(m);
    if (!copy) throw std::runtime_error("mj_makeData failed (out of memory)");
    const std::vector<int> params{cv::IMWRITE_JPEG_QUALITY, options.jpeg_quality};
    const auto period = std::chrono::duration_cast<std::chrono::nanoseconds>(
        std::chrono::duration<double>(1.0 / options.fps));
    std::int64_t frame_id = 0;
    std::unique_lock vl(view_mutex_);
    while (!view_stop_) {
      vl.unlock();
      {
        std::lock_guard lock(mutex_);  // between steps: a consistent state
        mj_copyData(copy, m, sim_->data());
      }
      const cv::Mat bgr = renderer.render(copy, "chase");
      std::vector<unsigned char> jpeg;
      cv::imencode(".jpg", bgr, jpeg, params);
      control::DroneView view;
      view.jpeg.assign(jpeg.begin(), jpeg.end());
      view.width = bgr.cols;
      view.height = bgr.rows;
      view.camera = "chase";
      view.frame_id = frame_id++;
      sink(view);
      vl.lock();
      view_cv_.wait_for(vl, period, [this] { return view_stop_; });
    }
  } catch (const std::exception& e) {
    std::lock_guard lock(mutex_);
    last_error_ = std::string("view: ") + e.what();
  }
  if (copy) mj_deleteData(copy);
}

}  // namespace gbdcs::sim
