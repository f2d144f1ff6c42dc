#include "gbdcs/adapters/tello_adapter.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <mutex>
#include <numbers>
#include <optional>
#include <vector>

#include "gbdcs/adapters/tello_state.hpp"
#include "tello_link.hpp"

// The DroneAdapter mapping: flight states, the rc stream, telemetry from the state stream and
// the link watchdog. The sockets and the reply matching are TelloLink's (tello_link.hpp).

namespace gbdcs::adapters {

using contracts::FlightState;
using control::Result;
using detail::is_error_reply;

namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;
constexpr int kStopBurst = 3;         // rc 0 0 0 0 sent this many times when the sticks centre
constexpr double kLandSettleS = 0.5;  // at ground height this long: landed
constexpr double kAutoLandSettleS = 1.0;

double wrap_deg(double deg) {
  double w = std::fmod(deg, 360.0);
  if (w < 0) w += 360.0;
  return w >= 360.0 ? 0.0 : w;
}

int stick(double value, double maximum) {
  if (maximum <= 0 || !std::isfinite(value)) return 0;
  return static_cast<int>(std::clamp(std::round(100.0 * value / maximum), -100.0, 100.0));
}

}  // namespace

struct TelloAdapter::Impl final : detail::TelloLink {
  Impl(const contracts::Clock& c, TelloOptions o) : TelloLink(c, std::move(o)) { start(); }
  ~Impl() override { stop(); }

  // ---- link hooks (I/O thread) ------------------------------------------------------------

  void on_late_reply_locked(const Pending& p) override {
    if (is_error_reply(p.reply)) {
      last_error = p.command + ": the " + options.drone_label + " answered '" + p.reply +
                   "' after accepting it";
      if (p.command == options.words.takeoff && flight == FlightState::kFlying && !climbed) {
        flight = FlightState::kReady;  // it never left the ground
      }
    }
    if (!is_error_reply(p.reply) && p.command == options.words.takeoff) {
      climbed = true;  // the take-off is complete
    }
  }

  void on_state_datagram(std::string_view datagram) override {
    std::string why;
    auto decoded = decode_state(datagram, why);
    std::vector<contracts::TelemetryFrame> frames;
    control::TelemetrySink to;
    {
      std::lock_guard lock(mutex);
      if (!decoded) {
        ++stats.malformed_packets;
        stats.last_malformed = why;
        return;
      }
      ++stats.state_packets;
      if (!connected) return;
      const auto now = clock.now();
      if (link_lost) {
        link_lost = false;
        last_error = "link restored: state from the " + options.drone_label + " again";
        send_locked(options.words.handshake, /*expect_reply=*/true);  // in case it rebooted
      }
      update_from_state_locked(*decoded, now);
      frames.push_back(frame_locked(contracts::LinkState::kOk));
      to = sink;
    }
    deliver(frames, to);
  }

  void deliver(const std::vector<contracts::TelemetryFrame>& frames,
               const control::TelemetrySink& to) {
    if (frames.empty() || !to) return;
    std::lock_guard order(sink_mutex);
    for (const auto& f : frames) to(f);
  }

  // ---- state ------------------------------------------------------------------------------

  void update_from_state_locked(const TelloState& s, contracts::Duration now) {
    const double yaw = s.yaw_deg;
    if (!have_state) {
      have_state = true;
      if (!origin_set) {
        origin_yaw_deg = yaw;
        origin_set = true;
      }
      last_state_at = now;
    }
    const double dt = std::clamp(contracts::to_seconds(now - last_state_at), 0.0, 1.0);
    last_state_at = now;
    const double unit = options.velocity_unit_m_s;
    const double wx = s.vgx * unit, wy = s.vgy * unit;
    const double y0 = origin_yaw_deg * kDegToRad;
    const double sx = wx * std::cos(y0) + wy * std::sin(y0);
    const double sy = -wx * std::sin(y0) + wy * std::cos(y0);
    x_m += sx * dt;
    y_m += sy * dt;
    const double h = yaw * kDegToRad;
    body_vx = wx * std::cos(h) + wy * std::sin(h);
    body_vy = -wx * std::sin(h) + wy * std::cos(h);
    vz = -s.vgz * unit;
    heading_deg = wrap_deg(yaw - origin_yaw_deg);
    height_cm = s.h_cm;
    battery_pct = s.bat_pct;

    const bool on_ground = s.h_cm <= options.ground_height_cm;
    if (!on_ground) {
      ground_since.reset();
      if (s.h_cm > 3 * std::max(options.ground_height_cm, 10.0)) {
        climbed = true;
        if (flight == FlightState::kReady) flight = FlightState::kFlying;  // already airborne
      }
      return;
    }
    if (!ground_since) ground_since = now;
    const double grounded_s = contracts::to_seconds(now - *ground_since);
    if (flight == FlightState::kLanding && grounded_s >= kLandSettleS) {
      flight = FlightState::kReady;
      stop_sticks_locked();
    } else if (flight == FlightState::kFlying && climbed && grounded_s >= kAutoLandSettleS) {
      flight = FlightState::kReady;
      stop_sticks_locked();
      last_error = "the " + options.drone_label +
                   " landed by itself (auto-land after 15 s without a command, or low battery)";
    }
  }

  contracts::TelemetryFrame frame_locked(contracts::LinkState link) {
    contracts::TelemetryFrame f;
    f.timestamp = clock.utc_now();
    f.altitude_m = std::max(0.0, height_cm / 100.0);
    f.vx_m_s = body_vx;
    f.vy_m_s = body_vy;
    f.vz_m_s = vz;
    f.speed_m_s = std::sqrt(body_vx * body_vx + body_vy * body_vy + vz * vz);
    f.x_m = x_m;
    f.y_m = y_m;
    f.heading_deg = heading_deg;
    f.battery_pct = std::clamp(battery_pct, 0.0, 100.0);
    f.flight_state = flight;
    f.link = link;
    ++stats.frames;
    return f;
  }

  // ---- sending ----------------------------------------------------------------------------

  void send_rc_locked(const std::array<int, 4>& s) {
    send_locked(options.words.rc + " " + std::to_string(s[0]) + " " + std::to_string(s[1]) + " " +
                    std::to_string(s[2]) + " " + std::to_string(s[3]),
                false);
    rc_next_at = clock.now() + contracts::from_seconds(1.0 / options.rc_hz);
  }

  void stop_sticks_locked() {
    const bool were_moving = sticks != std::array<int, 4>{0, 0, 0, 0};
    sticks = {0, 0, 0, 0};
    stop_at.reset();
    if (were_moving) stop_burst = kStopBurst;
  }

  // The common checks: connected and the link up.
  Result guard(const char* what) {
    if (!connected) {
      last_error = std::string(what) + ": not connected (call connect first)";
      return Result::kNotConnected;
    }
    if (link_lost) {
      last_error = std::string(what) + ": link lost (no state from the " + options.drone_label +
                   "; " + fix_text() + ")";
      return Result::kNotConnected;
    }
    return Result::kOk;
  }

  // ---- the clock's timers -----------------------------------------------------------------

  void tick() override {
    std::vector<contracts::TelemetryFrame> frames;
    control::TelemetrySink to;
    {
      std::lock_guard lock(mutex);
      expire_pending_locked();
      if (!connected) return;
      const auto now = clock.now();
      const double since_state =
          contracts::to_seconds(now - (have_state ? last_state_at : connected_at));
      if (!link_lost && since_state > options.link_timeout_s) {
        link_lost = true;
        ++stats.link_losses;
        last_error = have_state
                         ? "link lost: no state from the " + options.drone_label + " for " +
                               std::to_string(static_cast<int>(since_state * 10) / 10.0).substr(0, 4) +
                               " s (out of Wi-Fi range, or its battery died?)"
                         : "no state datagrams on local UDP port " +
                               std::to_string(local_state_port()) +
                               " since connect: let UDP " +
                               std::to_string(local_state_port()) +
                               " in through the firewall, or check 'state_port' in the " +
                               options.name + " options";
        frames.push_back(frame_locked(contracts::LinkState::kLost));
        to = sink;
      }
      if (!link_lost) {
        if (stop_at && now >= *stop_at) {
          stop_sticks_locked();
          stop_burst = kStopBurst;
          rc_next_at = now;
        }
        const bool moving = sticks != std::array<int, 4>{0, 0, 0, 0};
        if ((moving || stop_burst > 0) && now >= rc_next_at) {
          send_rc_locked(sticks);
          if (!moving) --stop_burst;
        }
        if (contracts::to_seconds(now - last_sent_at) >= options.keepalive_s && pending.empty()) {
          send_locked(options.words.keepalive, true);
        }
      }
    }
    deliver(frames, to);
  }

  control::TelemetrySink sink;
  std::mutex sink_mutex;
  std::mutex command_mutex;  // one command call at a time (emergency jumps the queue)

  bool connected = false;
  bool link_lost = false;
  bool stop_unsupported = false;
  FlightState flight = FlightState::kInit;
  bool climbed = false;
  std::array<int, 4> sticks{0, 0, 0, 0};
  int stop_burst = 0;
  std::optional<contracts::Duration> stop_at;
  contracts::Duration rc_next_at{0};
  contracts::Duration connected_at{0};
  contracts::Duration last_state_at{0};
  std::optional<contracts::Duration> ground_since;
  bool have_state = false;
  bool origin_set = false;
  double origin_yaw_deg = 0;
  double x_m = 0, y_m = 0, body_vx = 0, body_vy = 0, vz = 0, heading_deg = 0;
  double height_cm = 0, battery_pct = 100;
};

// ---- the adapter --------------------------------------------------------------------------

TelloAdapter::TelloAdapter(const contracts::Clock& clock, TelloOptions options)
    : impl_(std::make_unique<Impl>(clock, std::move(options))) {}

TelloAdapter::~TelloAdapter() = default;

std::string_view TelloAdapter::name() const { return impl_->options.name; }

const TelloOptions& TelloAdapter::options() const { return impl_->options; }

std::uint16_t TelloAdapter::local_state_port() const {
  return impl_->local_state_port();
}

std::uint16_t TelloAdapter::local_command_port() const {
  return impl_->local_command_port();
}

TelloStats TelloAdapter::stats() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->stats;
}

std::array<int, 4> TelloAdapter::sticks_for(const contracts::MotionPayload& m) const {
  const auto& o = impl_->options;
  return {stick(m.vy_m_s, o.max_horizontal_m_s), stick(m.vx_m_s, o.max_horizontal_m_s),
          stick(m.vz_m_s, o.max_vertical_m_s), stick(m.yaw_rate_deg_s, o.max_yaw_rate_deg_s)};
}

Result TelloAdapter::connect() {
  auto& d = *impl_;
  std::lock_guard serial(d.command_mutex);
  std::unique_lock lock(d.mutex);
  if (d.connected && !d.link_lost) return Result::kOk;
  const auto wait = std::chrono::milliseconds(d.options.reply_timeout_ms);
  std::optional<std::string> reply;
  for (int attempt = 0; attempt < d.options.handshake_retries && !reply; ++attempt) {
    reply = d.request_locked(lock, d.options.words.handshake, wait, false);
  }
  if (!reply) {
    if (!d.send_failed) {
      d.last_error = "connect: no reply from the " + d.options.drone_label + " at " +
                     d.endpoint_text() + " to '" + d.options.words.handshake + "' (" +
                     std::to_string(d.options.handshake_retries) + " tries, " +
                     std::to_string(d.options.reply_timeout_ms) + " ms each): " + d.fix_text();
    }
    return Result::kTimeout;
  }
  if (is_error_reply(*reply)) {
    d.last_error = "connect: the " + d.options.drone_label + " answered '" + *reply + "' to '" +
                   d.options.words.handshake + "' (restart the drone and try again)";
    return Result::kError;
  }
  const auto now = d.clock.now();
  d.connected = true;
  d.link_lost = false;
  d.connected_at = now;
  d.have_state = false;
  if (d.flight == FlightState::kInit) d.flight = FlightState::kReady;
  return Result::kOk;
}

Result TelloAdapter::disconnect() {
  auto& d = *impl_;
  std::lock_guard serial(d.command_mutex);
  std::lock_guard lock(d.mutex);
  if (!d.connected) return Result::kOk;
  if (d.sticks != std::array<int, 4>{0, 0, 0, 0}) d.send_rc_locked({0, 0, 0, 0});
  d.sticks = {0, 0, 0, 0};
  d.stop_at.reset();
  d.stop_burst = 0;
  d.connected = false;
  if (d.flight == FlightState::kFlying) {
    d.last_error = "disconnected while flying: the " + d.options.drone_label +
                   " hovers and lands by itself after 15 s";
  }
  return Result::kOk;
}

Result TelloAdapter::takeoff() {
  auto& d = *impl_;
  std::lock_guard serial(d.command_mutex);
  std::unique_lock lock(d.mutex);
  if (auto r = d.guard("takeoff"); r != Result::kOk) return r;
  if (d.flight != FlightState::kReady) {
    d.last_error = "takeoff: drone is " + std::string(contracts::to_string(d.flight));
    return Result::kRejected;
  }
  auto reply = d.request_locked(lock, d.options.words.takeoff,
                                std::chrono::milliseconds(d.options.ack_wait_ms), true);
  if (d.send_failed) return Result::kError;
  if (reply && is_error_reply(*reply)) {
    d.last_error = "takeoff: the " + d.options.drone_label + " answered '" + *reply +
                   "' (battery too low, too hot, or not level?)";
    return Result::kRejected;
  }
  d.flight = FlightState::kFlying;
  d.climbed = reply.has_value();  // "ok" already: the climb is done
  d.ground_since.reset();
  d.sticks = {0, 0, 0, 0};
  return Result::kOk;
}

Result TelloAdapter::land() {
  auto& d = *impl_;
  std::lock_guard serial(d.command_mutex);
  std::unique_lock lock(d.mutex);
  if (auto r = d.guard("land"); r != Result::kOk) return r;
  if (d.flight != FlightState::kFlying) {
    d.last_error = "land: drone is " + std::string(contracts::to_string(d.flight));
    return Result::kRejected;
  }
  d.sticks = {0, 0, 0, 0};
  d.stop_at.reset();
  d.stop_burst = 0;
  auto reply = d.request_locked(lock, d.options.words.land,
                                std::chrono::milliseconds(d.options.ack_wait_ms), true);
  if (d.send_failed) return Result::kError;
  if (reply && is_error_reply(*reply)) {
    d.last_error = "land: the " + d.options.drone_label + " answered '" + *reply + "'";
    return Result::kRejected;
  }
  d.flight = FlightState::kLanding;
  d.ground_since.reset();
  return Result::kOk;
}

Result TelloAdapter::hover() {
  auto& d = *impl_;
  std::lock_guard serial(d.command_mutex);
  std::unique_lock lock(d.mutex);
  if (auto r = d.guard("hover"); r != Result::kOk) return r;
  if (d.flight != FlightState::kFlying) {
    d.last_error = "hover: drone is " + std::string(contracts::to_string(d.flight));
    return Result::kRejected;
  }
  d.sticks = {0, 0, 0, 0};
  d.stop_at.reset();
  d.send_rc_locked(d.sticks);
  d.stop_burst = kStopBurst - 1;
  if (d.options.words.stop.empty() || d.stop_unsupported || d.long_command_pending_locked()) {
    return Result::kOk;
  }
  auto reply = d.request_locked(lock, d.options.words.stop,
                                std::chrono::milliseconds(d.options.reply_timeout_ms), false);
  if (!reply) {
    d.last_error = "hover: no reply to '" + d.options.words.stop + "' (rc 0 0 0 0 was sent)";
    return Result::kTimeout;
  }
  if (is_error_reply(*reply)) d.stop_unsupported = true;  // SDK 1.3: rc 0 0 0 0 is the hover
  return Result::kOk;
}

Result TelloAdapter::move(const contracts::MotionPayload& motion) {
  auto& d = *impl_;
  std::lock_guard serial(d.command_mutex);
  std::lock_guard lock(d.mutex);
  if (auto r = d.guard("move"); r != Result::kOk) return r;
  if (d.flight != FlightState::kFlying) {
    d.last_error = "move: drone is " + std::string(contracts::to_string(d.flight));
    return Result::kRejected;
  }
  if (!std::isfinite(motion.duration_s) || motion.duration_s < 0) {
    d.last_error = "move: duration_s must be a finite number >= 0";
    return Result::kRejected;
  }
  const auto s = sticks_for(motion);
  d.sticks = s;
  d.send_rc_locked(s);
  d.stop_burst = s == std::array<int, 4>{0, 0, 0, 0} ? kStopBurst - 1 : 0;
  if (motion.duration_s > 0) {
    d.stop_at = d.clock.now() + contracts::from_seconds(motion.duration_s);
  } else {
    d.stop_at.reset();
  }
  return Result::kOk;
}

Result TelloAdapter::emergency_stop() {
  auto& d = *impl_;
  // Not behind command_mutex: an emergency never waits for another command's reply.
  std::unique_lock lock(d.mutex);
  if (!d.connected) {
    d.last_error = "emergency: not connected";
    return Result::kNotConnected;
  }
  d.abandon_all_locked();  // their replies can no longer be told apart
  d.sticks = {0, 0, 0, 0};
  d.stop_at.reset();
  d.stop_burst = 0;
  const auto wait = std::chrono::milliseconds(d.options.reply_timeout_ms);
  std::optional<std::string> reply;
  for (int attempt = 0; attempt < 2 && !(reply && !is_error_reply(*reply)); ++attempt) {
    reply = d.request_locked(lock, d.options.words.emergency, wait, false);
  }
  const bool airborne = d.height_cm > d.options.ground_height_cm;
  if (d.flight == FlightState::kFlying || d.flight == FlightState::kLanding) {
    d.flight = airborne ? FlightState::kLanding : FlightState::kReady;
  }
  d.ground_since.reset();
  if (d.link_lost) {
    d.last_error = "emergency: sent, but the link is lost (no state from the " +
                   d.options.drone_label + ")";
    return Result::kNotConnected;
  }
  if (!reply) {
    d.last_error = "emergency: no reply from the " + d.options.drone_label + " (sent twice; " +
                   d.fix_text() + ")";
    return Result::kTimeout;
  }
  if (is_error_reply(*reply)) {
    d.last_error = "emergency: the " + d.options.drone_label + " answered '" + *reply + "'";
    return Result::kError;
  }
  return Result::kOk;
}

Result TelloAdapter::query(const std::string& command, std::string& reply) {
  auto& d = *impl_;
  std::lock_guard serial(d.command_mutex);
  std::unique_lock lock(d.mutex);
  if (auto r = d.guard("query"); r != Result::kOk) return r;
  auto answer = d.request_locked(lock, command,
                                 std::chrono::milliseconds(d.options.reply_timeout_ms), false);
  if (!answer) {
    d.last_error = "'" + command + "': no reply from the " + d.options.drone_label;
    return Result::kTimeout;
  }
  reply = *answer;
  if (is_error_reply(*answer)) {
    d.last_error = "'" + command + "': the " + d.options.drone_label + " answered '" + *answer +
                   "'";
    return Result::kRejected;
  }
  return Result::kOk;
}

FlightState TelloAdapter::state() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->flight;
}

void TelloAdapter::set_telemetry_sink(control::TelemetrySink sink) {
  std::lock_guard lock(impl_->mutex);
  impl_->sink = std::move(sink);
}

void TelloAdapter::poll() { impl_->tick(); }

std::string TelloAdapter::last_error() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->last_error;
}

}  // namespace gbdcs::adapters
