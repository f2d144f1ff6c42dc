#include "gbdcs/adapters/airsim_adapter.hpp"

#include <algorithm>
#include <boost/asio.hpp>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <functional>
#include <map>
#include <mutex>
#include <numbers>
#include <optional>
#include <thread>

#include "gbdcs/adapters/airsim_rpc.hpp"

namespace gbdcs::adapters {

namespace asio = boost::asio;
using asio::ip::tcp;
using contracts::FlightState;
using control::Result;
using Packer = msgpack::packer<msgpack::sbuffer>;

namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;
constexpr auto kTickPeriod = std::chrono::milliseconds(10);
constexpr std::size_t kMaxBuffered = 4 << 20;  // a frame bigger than this is not AirSim's

double wrap_deg(double deg) {
  double w = std::fmod(deg, 360.0);
  if (w < 0) w += 360.0;
  return w >= 360.0 ? 0.0 : w;
}

}  // namespace

struct AirSimAdapter::Impl {
  struct Call {
    std::string method;
    bool done = false;      // answered, expired or its connection lost
    bool answered = false;  // ok/error/result hold the server's answer
    bool ok = false;
    std::string error;
    msgpack::object_handle result;
    bool deferred = false;  // nobody waits: a late error or `false` is logged
    bool is_state = false;
    contracts::Duration expires{0};  // on the injected clock
  };

  Impl(const contracts::Clock& c, AirSimOptions o)
      : clock(c), options(std::move(o)), socket(io), tick_timer(io), unpacker(make_unpacker()) {
    boost::system::error_code ec;
    const auto address = asio::ip::make_address(options.address, ec);
    if (ec) {
      throw std::invalid_argument("airsim options: 'address' '" + options.address +
                                  "' is not an IP address");
    }
    server = tcp::endpoint(address, static_cast<unsigned short>(options.port));
    schedule_tick();
    io_thread = std::thread([this] { io.run(); });
  }

  ~Impl() {
    io.stop();
    if (io_thread.joinable()) io_thread.join();
  }

  // Copies every string (no references into the buffer) and bounds what one frame may hold.
  static std::unique_ptr<msgpack::unpacker> make_unpacker() {
    return std::make_unique<msgpack::unpacker>(
        [](msgpack::type::object_type, std::size_t, void*) { return false; }, nullptr,
        MSGPACK_UNPACKER_INIT_BUFFER_SIZE,
        msgpack::unpack_limit(100000, 100000, 1 << 20, 1 << 22, 1 << 20, 64));
  }

  std::string where() const { return options.address + ":" + std::to_string(options.port); }
  std::string fix() const {
    return "start the AirSim environment (Unreal, a multirotor vehicle) or `gbdcs twin "
           "--airsim`, and check 'address'/'port' in the airsim options against "
           "settings.json's ApiServerPort";
  }

  // ---- connection (I/O thread) ------------------------------------------------------------

  void dial() {  // with `mutex` held; completes on the I/O thread
    dialing = true;
    ++dial_generation;
    const auto generation = dial_generation;
    asio::post(io, [this, generation] {
      boost::system::error_code ignored;
      socket.close(ignored);
      unpacker = make_unpacker();
      socket.async_connect(server, [this, generation](boost::system::error_code ec) {
        std::lock_guard lock(mutex);
        if (generation != dial_generation) return;
        dialing = false;
        dial_error = ec ? ec.message() : "";
        if (!ec) {
          boost::system::error_code e2;
          socket.set_option(tcp::no_delay(true), e2);
          socket_up = true;
          ++stats.connects;
          backoff_s = options.reconnect_min_s;
          read();
          if (connected) {  // a re-dial: ask for control again, fire and forget
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
        } else if (connected) {
          reconnect_at = clock.now() + contracts::from_seconds(backoff_s);
          backoff_s = std::min(backoff_s * 2, options.reconnect_max_s);
        }
        cv.notify_all();
      });
    });
  }

  void read() {
    socket.async_read_some(asio::buffer(read_buffer), [this](boost::system::error_code ec,
                                                             std::size_t n) {
      if (ec == asio::error::operation_aborted) return;
      if (ec) {
        lost_socket("the connection to AirSim at " + where() + " closed: " + ec.message());
        return;
      }
      if (!on_bytes(n)) return;
      read();
    });
  }

  void lost_socket(const std::string& why) {
    std::lock_guard lock(mutex);
    lost_socket_locked(why);
  }

  void lost_socket_locked(const std::string& why) {
    if (!socket_up) return;
    socket_up = false;
    boost::system::error_code ignored;
    socket.close(ignored);
    last_error = why + " (reconnecting)";
    stats.lost_requests += calls.size();
    for (auto& [id, c] : calls) {
      c->done = true;
      c->error = "connection lost";
    }
    calls.clear();
    cv.notify_all();
    reconnect_at = clock.now() + contracts::from_seconds(backoff_s);
  }

  // Feeds the unpacker; false when the stream is broken (the socket is dropped).
  bool on_bytes(std::size_t n) {
    std::vector<contracts::TelemetryFrame> frames;
    control::TelemetrySink to;
    {
      std::lock_guard lock(mutex);
      if (unpacker->nonparsed_size() + n > kMaxBuffered) {
        ++stats.malformed;
        stats.last_malformed = "a frame larger than 4 MiB";
        lost_socket_locked("AirSim sent a frame larger than 4 MiB");
        return false;
      }
      unpacker->reserve_buffer(n);
      std::copy_n(read_buffer.data(), n, unpacker->buffer());
      unpacker->buffer_consumed(n);
      try {
        msgpack::object_handle message;
        while (unpacker->next(message)) on_message(std::move(message), frames);
      } catch (const std::exception& e) {
        ++stats.malformed;
        stats.last_malformed = std::string("undecodable msgpack: ") + e.what();
        lost_socket_locked("AirSim sent undecodable msgpack (" + std::string(e.what()) + ")");
        return false;
      }
      to = sink;
    }
    if (to && !frames.empty()) {
      std::lock_guard order(sink_mutex);
      for (const auto& f : frames) to(f);
    }
    return true;
  }

  void on_message(msgpack::object_handle&& message,
                  std::vector<contracts::TelemetryFrame>& frames) {
    std::string why;
    auto response = airsim::decode_response(std::move(message), why);
    if (!response) {
      ++stats.malformed;
      stats.last_malformed = why;
      return;
    }
    ++stats.responses;
    const auto it = calls.find(response->msgid);
    if (it == calls.end()) return;  // abandoned (timed out) or from before a reconnect
    auto call = it->second;
    calls.erase(it);
    call->done = true;
    call->answered = true;
    call->ok = response->ok;
    call->error = response->error;
    call->result = std::move(response->result);
    if (call->is_state) {
      state_outstanding.reset();
      if (call->ok) on_state(call->result.get(), frames);
    } else if (call->deferred) {
      const auto& r = call->result.get();
      if (!call->ok) {
        last_error = call->method + ": AirSim answered: " + call->error;
      } else if (r.type == msgpack::type::BOOLEAN && !r.via.boolean &&
                 call->method != "moveByVelocityBodyFrame") {
        last_error = call->method + ": AirSim answered false (timed out or cancelled)";
      }
    }
    cv.notify_all();
  }

  void on_state(const msgpack::object& o, std::vector<contracts::TelemetryFrame>& frames) {
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

  std::shared_ptr<Call> call_locked(const std::string& method,
                                    const std::function<void(Packer&)>& params, bool deferred,
                                    bool is_state = false) {
    if (!socket_up) return nullptr;
    auto c = std::make_shared<Call>();
    c->method = method;
    c->deferred = deferred;
    c->is_state = is_state;
    const double life_s = deferred ? std::max(options.takeoff_timeout_s, options.land_timeout_s) + 5
                                   : options.rpc_timeout_ms / 1000.0;
    c->expires = clock.now() + contracts::from_seconds(life_s);
    const auto id = next_id++;
    const auto bytes = airsim::encode_request(id, method, [&](Packer& p) { params(p); });
    calls[id] = c;
    boost::system::error_code ec;
    asio::write(socket, asio::buffer(bytes), ec);
    if (!ec) ++stats.requests;
    if (ec) {
      calls.erase(id);
      lost_socket_locked("cannot send to AirSim at " + where() + ": " + ec.message());
      return nullptr;
    }
    return c;
  }

  // Calls and waits up to `wait`; the Call (done or not), or nullptr when nothing was sent.
  std::shared_ptr<Call> wait_locked(std::unique_lock<std::mutex>& lock, const std::string& method,
                                    const std::function<void(Packer&)>& params,
                                    std::chrono::milliseconds wait, bool deferred) {
    auto c = call_locked(method, params, false);
    if (!c) return nullptr;
    cv.wait_for(lock, wait, [&] { return c->done; });
    if (!c->done) {
      if (deferred) {
        c->deferred = true;
        c->expires = clock.now() + contracts::from_seconds(options.land_timeout_s + 5);
      }
    }
    return c;
  }

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

  // An error, `false` or no answer from a call that must succeed at once.
  Result check(const std::shared_ptr<Call>& c, const std::string& what, bool want_true) {
    if (!c) {
      last_error = what + ": not sent (" + last_error + ")";
      return Result::kNotConnected;
    }
    if (!c->done) {
      last_error = what + ": no answer from AirSim at " + where() + " in " +
                   std::to_string(options.rpc_timeout_ms) + " ms";
      return Result::kTimeout;
    }
    if (!c->answered) {
      last_error = what + ": " + (c->error.empty() ? "no answer from AirSim" : c->error) +
                   " (AirSim at " + where() + ")";
      return c->error.empty() ? Result::kTimeout : Result::kNotConnected;
    }
    if (!c->ok) {
      last_error = what + ": AirSim answered: " + c->error;
      return Result::kRejected;
    }
    const auto& r = c->result.get();
    if (want_true && !(r.type == msgpack::type::BOOLEAN && r.via.boolean)) {
      last_error = what + ": AirSim answered " + airsim::describe(r);
      return Result::kRejected;
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

  void schedule_tick() {
    tick_timer.expires_after(kTickPeriod);
    tick_timer.async_wait([this](boost::system::error_code ec) {
      if (ec) return;
      tick();
      schedule_tick();
    });
  }

  void tick() {
    std::vector<contracts::TelemetryFrame> frames;
    control::TelemetrySink to;
    {
      std::lock_guard lock(mutex);
      // Calls nobody waits for any more expire on the injected clock (simulated time in a
      // lockstep run); the blocking waits themselves are real time (a socket's).
      const auto expire_before = clock.now();
      for (auto it = calls.begin(); it != calls.end();) {
        if (it->second->expires < expire_before) {
          it->second->done = true;
          it = calls.erase(it);
        } else {
          ++it;
        }
      }
      stats.outstanding = calls.size();
      if (!connected) return;
      const auto now = clock.now();
      if (!socket_up && !dialing && now >= reconnect_at) dial();
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
    if (to && !frames.empty()) {
      std::lock_guard order(sink_mutex);
      for (const auto& f : frames) to(f);
    }
  }

  const contracts::Clock& clock;
  AirSimOptions options;
  asio::io_context io;
  tcp::socket socket;
  asio::steady_timer tick_timer;
  tcp::endpoint server;
  std::array<char, 65536> read_buffer{};
  std::thread io_thread;

  mutable std::mutex mutex;
  std::condition_variable cv;
  std::mutex sink_mutex;
  std::mutex command_mutex;
  control::TelemetrySink sink;
  std::unique_ptr<msgpack::unpacker> unpacker;
  std::map<std::uint32_t, std::shared_ptr<Call>> calls;
  std::uint32_t next_id = 1;

  bool socket_up = false;
  bool dialing = false;
  std::uint64_t dial_generation = 0;
  std::string dial_error;
  double backoff_s = 0.5;
  contracts::Duration reconnect_at{0};

  bool connected = false;
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
  std::string last_error;
  AirSimStats stats;
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
