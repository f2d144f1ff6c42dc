#include "gbdcs/adapters/airsim_adapter.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <mutex>
#include <numbers>
#include <optional>
#include <vector>

#include "airsim_link.hpp"
#include "gbdcs/adapters/airsim_rpc.hpp"

// The DroneAdapter mapping: flight states, NED to the session frame, the move stream and the
// link watchdog. The connection, request matching and reconnects are AirSimLink's
// (airsim_link.hpp).

namespace gbdcs::adapters {

using contracts::FlightState;
using control::Result;
using Packer = detail::AirSimLink::Packer;

namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;

double wrap_deg(double deg) {
  double w = std::fmod(deg, 360.0);
  if (w < 0) w += 360.0;
  return w >= 360.0 ? 0.0 : w;
}

}  // namespace

struct AirSimAdapter::Impl final : detail::AirSimLink {
  Impl(const contracts::Clock& c, AirSimOptions o) : AirSimLink(c, std::move(o)) { start(); }
  ~Impl() override { stop(); }

  // ---- link hooks (I/O thread, lock held) -------------------------------------------------

  void on_redialled_locked() override {  // ask for control again, fire and forget
    call_locked("enableApiControl", [&](Packer& p) {
      p.pack_array(2);
      p.pack(true);
      p.pack(options.vehicle);
    }, true);
    call_locked("armDisarm", [&](Packer& p) {
      p.pack_array(2);
      p.pack(true);
      p.pack(options.vehicle);
    }, true);
  }

  void on_state_response_locked(const Call& call,
                                std::vector<contracts::TelemetryFrame>& frames) override {
    state_outstanding.reset();
    if (!call.ok) return;
    const msgpack::object& o = call.result.get();
    std::string why;
    const auto s = airsim::decode_multirotor_state(o, why);
    if (!s) {
      ++stats.malformed;
      stats.last_malformed = "getMultirotorState: " + why;
      return;
    }
    ++stats.states;
    const auto now = clock.now();
    last_state_at = now;
    have_state = true;
    if (link_lost) {
      link_lost = false;
      last_error = "link restored: AirSim answers again";
    }
    const double yaw = airsim::yaw_deg_of(s->orientation);
    if (!origin_set) {
      origin_set = true;
      origin = s->position_ned_m;
      origin_yaw_deg = yaw;
      if (s->landed_state == 1) origin.z = 0;  // flying at connect: AirSim's z is from home
    }
    const double dx = s->position_ned_m.x - origin.x, dy = s->position_ned_m.y - origin.y;
    const double y0 = origin_yaw_deg * kDegToRad, h = yaw * kDegToRad;
    const auto& v = s->velocity_ned_m_s;
    contracts::TelemetryFrame f;
    f.timestamp = clock.utc_now();
    f.altitude_m = std::max(0.0, origin.z - s->position_ned_m.z);
    f.x_m = dx * std::cos(y0) + dy * std::sin(y0);
    f.y_m = -dx * std::sin(y0) + dy * std::cos(y0);
    f.vx_m_s = v.x * std::cos(h) + v.y * std::sin(h);
    f.vy_m_s = -v.x * std::sin(h) + v.y * std::cos(h);
    f.vz_m_s = -v.z;
    f.speed_m_s = std::sqrt(v.x * v.x + v.y * v.y + v.z * v.z);
    f.heading_deg = wrap_deg(yaw - origin_yaw_deg);
    f.battery_pct = 100;  // AirSim's multirotor state has no battery

    if (s->landed_state == 1) {
      landed_since.reset();
      flown = true;
      if (flight == FlightState::kReady) flight = FlightState::kFlying;
    } else {
      if (!landed_since) landed_since = now;
      const double landed_s = contracts::to_seconds(now - *landed_since);
      if (flight == FlightState::kLanding && f.altitude_m < 0.15) {
        flight = FlightState::kReady;
        moving = false;
      } else if (flight == FlightState::kFlying && flown && landed_s >= 1.0) {
        flight = FlightState::kReady;
        moving = false;
        last_error = "AirSim reports the vehicle landed";
      }
    }
    f.flight_state = flight;
    f.link = contracts::LinkState::kOk;
    frames.push_back(f);
  }

  // ---- calls ------------------------------------------------------------------------------

  Result guard(const char* what) {
    if (!connected) {
      last_error = std::string(what) + ": not connected (call connect first)";
      return Result::kNotConnected;
    }
    if (link_lost || !socket_up) {
      last_error = std::string(what) + ": link lost (AirSim at " + where() +
                   (socket_up ? " does not answer)" : " is not connected; reconnecting)");
      return Result::kNotConnected;
    }
    return Result::kOk;
  }

  void pack_vehicle_only(Packer& p) const {
    p.pack_array(1);
    p.pack(options.vehicle);
  }

  void send_move_locked() {
    call_locked("moveByVelocityBodyFrame", [&](Packer& p) {
      p.pack_array(7);
      p.pack_float(static_cast<float>(velocity[0]));
      p.pack_float(static_cast<float>(velocity[1]));
      p.pack_float(static_cast<float>(-velocity[2]));  // NED: z down
      p.pack_float(static_cast<float>(options.move_chunk_s));
      p.pack_int(0);  // DrivetrainType::MaxDegreeOfFreedom
      airsim::pack_yaw_mode(p, true, velocity[3]);
      p.pack(options.vehicle);
    }, true);
    next_move_at = clock.now() + contracts::from_seconds(options.move_resend_s);
  }

  void send_hover_locked() {
    call_locked("hover", [&](Packer& p) { pack_vehicle_only(p); }, true);
  }

  // ---- the clock's timers -----------------------------------------------------------------

  void tick() override {
    std::vector<contracts::TelemetryFrame> frames;
    control::TelemetrySink to;
    {
      std::lock_guard lock(mutex);
      expire_calls_locked();
      if (!connected) return;
      const auto now = clock.now();
      redial_if_due_locked(now);
      const double since =
          contracts::to_seconds(now - (have_state ? last_state_at : connected_at));
      if (!link_lost && since > options.link_timeout_s) {
        link_lost = true;
        ++stats.link_losses;
        last_error = "link lost: no state from AirSim at " + where() + " for " +
                     std::to_string(since).substr(0, 4) + " s";
        contracts::TelemetryFrame f;
        f.timestamp = clock.utc_now();
        f.flight_state = flight;
        f.link = contracts::LinkState::kLost;
        frames.push_back(f);
        to = sink;
      }
      if (!socket_up) return;
      // A state request unanswered for link_timeout_s is given up (lost on the way).
      if (state_outstanding &&
          contracts::to_seconds(now - *state_outstanding) > options.link_timeout_s) {
        for (auto it = calls.begin(); it != calls.end(); ++it) {
          if (it->second->is_state) {
            calls.erase(it);
            break;
          }
        }
        state_outstanding.reset();
      }
      if (!state_outstanding && now >= next_state_at) {
        if (call_locked("getMultirotorState", [&](Packer& p) { pack_vehicle_only(p); }, false,
                        true)) {
          state_outstanding = now;
        }
        next_state_at = now + contracts::from_seconds(1.0 / options.telemetry_hz);
      }
      if (moving && !link_lost) {
        if (stop_at && now >= *stop_at) {
          moving = false;
          stop_at.reset();
          send_hover_locked();
        } else if (now >= next_move_at) {
          send_move_locked();
        }
      }
    }
    deliver(frames, to);
  }

  bool link_lost = false;
  FlightState flight = FlightState::kInit;
  bool flown = false;
  std::optional<contracts::Duration> landed_since;
  contracts::Duration connected_at{0}, last_state_at{0}, next_state_at{0}, next_move_at{0};
  std::optional<contracts::Duration> state_outstanding;
  std::optional<contracts::Duration> stop_at;
  bool moving = false;
  std::array<double, 4> velocity{};  // vx forward, vy right, vz up (m/s), yaw rate (deg/s)
  bool have_state = false;
  bool origin_set = false;
  airsim::Vector3 origin;
  double origin_yaw_deg = 0;
  std::mutex command_mutex;  // one command call at a time (emergency jumps the queue)
};

// ---- the adapter --------------------------------------------------------------------------

AirSimAdapter::AirSimAdapter(const contracts::Clock& clock, AirSimOptions options)
    : impl_(std::make_unique<Impl>(clock, std::move(options))) {}

AirSimAdapter::~AirSimAdapter() = default;

Result AirSimAdapter::connect() {
  auto& d = *impl_;
  std::lock_guard serial(d.command_mutex);
  std::unique_lock lock(d.mutex);
  if (d.connected && !d.link_lost && d.socket_up) return Result::kOk;
  d.backoff_s = d.options.reconnect_min_s;
  if (!d.socket_up) {
    if (!d.dialing) d.dial();
    const bool answered = d.cv.wait_for(lock, std::chrono::milliseconds(d.options.connect_timeout_ms),
                                        [&] { return !d.dialing; });
    if (!answered || !d.socket_up) {
      d.last_error = "connect: cannot reach AirSim at " + d.where() + ": " +
                     (answered ? d.dial_error : "no answer in " +
                                                    std::to_string(d.options.connect_timeout_ms) +
                                                    " ms") +
                     " (" + d.fix() + ")";
      if (!answered) ++d.dial_generation;  // ignore that attempt's late outcome
      d.dialing = false;
      return answered ? Result::kError : Result::kTimeout;
    }
  }
  const auto wait = std::chrono::milliseconds(d.options.rpc_timeout_ms);
  auto ping = d.wait_locked(lock, "ping", [](Packer& p) { p.pack_array(0); }, wait, false);
  if (auto r = d.check(ping, "connect: ping", true); r != Result::kOk) return r;
  auto control = d.wait_locked(lock, "enableApiControl", [&](Packer& p) {
    p.pack_array(2);
    p.pack(true);
    p.pack(d.options.vehicle);
  }, wait, false);
  if (auto r = d.check(control, "connect: enableApiControl", false); r != Result::kOk) {
    d.last_error += " (is 'vehicle' \"" + d.options.vehicle + "\" a vehicle in settings.json?)";
    return r == Result::kRejected ? Result::kError : r;
  }
  auto arm = d.wait_locked(lock, "armDisarm", [&](Packer& p) {
    p.pack_array(2);
    p.pack(true);
    p.pack(d.options.vehicle);
  }, wait, false);
  if (auto r = d.check(arm, "connect: armDisarm", true); r != Result::kOk) return r;
  const auto now = d.clock.now();
  d.connected = true;
  d.link_lost = false;
  d.connected_at = now;
  d.have_state = false;
  d.next_state_at = now;
  if (d.flight == FlightState::kInit) d.flight = FlightState::kReady;
  return Result::kOk;
}

Result AirSimAdapter::disconnect() {
  auto& d = *impl_;
  std::lock_guard serial(d.command_mutex);
  std::lock_guard lock(d.mutex);
  if (!d.connected) return Result::kOk;
  if (d.moving && d.socket_up) d.send_hover_locked();
  d.moving = false;
  d.connected = false;
  if (d.socket_up) {
    d.call_locked("enableApiControl", [&](Packer& p) {
      p.pack_array(2);
      p.pack(false);
      p.pack(d.options.vehicle);
    }, true);
  }
  return Result::kOk;
}

Result AirSimAdapter::takeoff() {
  auto& d = *impl_;
  std::lock_guard serial(d.command_mutex);
  std::unique_lock lock(d.mutex);
  if (auto r = d.guard("takeoff"); r != Result::kOk) return r;
  if (d.flight != FlightState::kReady) {
    d.last_error = "takeoff: drone is " + std::string(contracts::to_string(d.flight));
    return Result::kRejected;
  }
  auto c = d.wait_locked(lock, "takeoff", [&](Packer& p) {
    p.pack_array(2);
    p.pack_float(static_cast<float>(d.options.takeoff_timeout_s));
    p.pack(d.options.vehicle);
  }, std::chrono::milliseconds(d.options.ack_wait_ms), true);
  if (!c) return Result::kNotConnected;
  if (c->done) {
    if (auto r = d.check(c, "takeoff", true); r != Result::kOk) return r;
  }
  d.flight = FlightState::kFlying;
  d.landed_since.reset();
  d.flown = false;
  return Result::kOk;
}

Result AirSimAdapter::land() {
  auto& d = *impl_;
  std::lock_guard serial(d.command_mutex);
  std::unique_lock lock(d.mutex);
  if (auto r = d.guard("land"); r != Result::kOk) return r;
  if (d.flight != FlightState::kFlying) {
    d.last_error = "land: drone is " + std::string(contracts::to_string(d.flight));
    return Result::kRejected;
  }
  d.moving = false;
  d.stop_at.reset();
  auto c = d.wait_locked(lock, "land", [&](Packer& p) {
    p.pack_array(2);
    p.pack_float(static_cast<float>(d.options.land_timeout_s));
    p.pack(d.options.vehicle);
  }, std::chrono::milliseconds(d.options.ack_wait_ms), true);
  if (!c) return Result::kNotConnected;
  if (c->done) {
    if (auto r = d.check(c, "land", true); r != Result::kOk) return r;
  }
  d.flight = FlightState::kLanding;
  return Result::kOk;
}

Result AirSimAdapter::hover() {
  auto& d = *impl_;
  std::lock_guard serial(d.command_mutex);
  std::unique_lock lock(d.mutex);
  if (auto r = d.guard("hover"); r != Result::kOk) return r;
  if (d.flight != FlightState::kFlying) {
    d.last_error = "hover: drone is " + std::string(contracts::to_string(d.flight));
    return Result::kRejected;
  }
  d.moving = false;
  d.stop_at.reset();
  auto c = d.wait_locked(lock, "hover", [&](Packer& p) { d.pack_vehicle_only(p); },
                         std::chrono::milliseconds(d.options.rpc_timeout_ms), false);
  return d.check(c, "hover", false);
}

Result AirSimAdapter::move(const contracts::MotionPayload& m) {
  auto& d = *impl_;
  std::lock_guard serial(d.command_mutex);
  std::lock_guard lock(d.mutex);
  if (auto r = d.guard("move"); r != Result::kOk) return r;
  if (d.flight != FlightState::kFlying) {
    d.last_error = "move: drone is " + std::string(contracts::to_string(d.flight));
    return Result::kRejected;
  }
  for (double v : {m.vx_m_s, m.vy_m_s, m.vz_m_s, m.yaw_rate_deg_s, m.duration_s}) {
    if (!std::isfinite(v)) {
      d.last_error = "move: every value must be a finite number";
      return Result::kRejected;
    }
  }
  if (m.duration_s < 0) {
    d.last_error = "move: duration_s must be >= 0";
    return Result::kRejected;
  }
  const auto& o = d.options;
  d.velocity = {std::clamp(m.vx_m_s, -o.max_horizontal_m_s, o.max_horizontal_m_s),
                std::clamp(m.vy_m_s, -o.max_horizontal_m_s, o.max_horizontal_m_s),
                std::clamp(m.vz_m_s, -o.max_vertical_m_s, o.max_vertical_m_s),
                std::clamp(m.yaw_rate_deg_s, -o.max_yaw_rate_deg_s, o.max_yaw_rate_deg_s)};
  d.moving = true;
  d.send_move_locked();
  if (m.duration_s > 0) {
    d.stop_at = d.clock.now() + contracts::from_seconds(m.duration_s);
  } else {
    d.stop_at.reset();
  }
  return Result::kOk;
}

Result AirSimAdapter::emergency_stop() {
  auto& d = *impl_;
  std::unique_lock lock(d.mutex);  // not behind command_mutex: never waits for another command
  if (!d.connected) {
    d.last_error = "emergency: not connected";
    return Result::kNotConnected;
  }
  d.moving = false;
  d.stop_at.reset();
  d.call_locked("cancelLastTask", [&](Packer& p) { d.pack_vehicle_only(p); }, true);
  auto c = d.wait_locked(lock, "armDisarm", [&](Packer& p) {
    p.pack_array(2);
    p.pack(false);
    p.pack(d.options.vehicle);
  }, std::chrono::milliseconds(d.options.rpc_timeout_ms), false);
  const auto r = d.check(c, "emergency (armDisarm false)", true);
  if (r == Result::kOk && (d.flight == FlightState::kFlying || d.flight == FlightState::kLanding)) {
    d.flight = FlightState::kLanding;
  }
  if (r != Result::kOk && d.link_lost) return Result::kNotConnected;
  return r;
}

FlightState AirSimAdapter::state() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->flight;
}

void AirSimAdapter::set_telemetry_sink(control::TelemetrySink sink) {
  std::lock_guard lock(impl_->mutex);
  impl_->sink = std::move(sink);
}

void AirSimAdapter::poll() { impl_->tick(); }

std::string AirSimAdapter::last_error() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->last_error;
}

AirSimStats AirSimAdapter::stats() const {
  std::lock_guard lock(impl_->mutex);
  auto s = impl_->stats;
  s.outstanding = impl_->calls.size();
  return s;
}

}  // namespace gbdcs::adapters
