#include "gbdcs/sim/airsim_emulator.hpp"

#include <utility>  // before Boost 1.74 Asio (std::exchange in awaitable.hpp)
#include <algorithm>
#include <atomic>
#include <boost/asio.hpp>
#include <cmath>
#include <deque>
#include <msgpack.hpp>
#include <mutex>
#include <numbers>
#include <optional>
#include <set>
#include <stdexcept>
#include <thread>

namespace gbdcs::sim {

namespace asio = boost::asio;
using asio::ip::tcp;
using Packer = msgpack::packer<msgpack::sbuffer>;

namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;
constexpr std::size_t kMaxFrame = 1 << 20;

struct CallError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// The arguments of one call, checked as rpclib would.
class Args {
 public:
  Args(const std::string& method, const msgpack::object& params) : method_(method) {
    if (params.type != msgpack::type::ARRAY) throw CallError("params is not an array");
    ptr_ = params.via.array.ptr;
    size_ = params.via.array.size;
  }
  void expect(std::uint32_t n) const {
    if (size_ != n) {
      throw CallError("rpclib: function '" + method_ + "' (taking " + std::to_string(n) +
                      " arg(s)) called with " + std::to_string(size_) + " arg(s)");
    }
  }
  double number(std::uint32_t i) const {
    const auto& o = ptr_[i];
    switch (o.type) {
      case msgpack::type::FLOAT32:
      case msgpack::type::FLOAT64:
        if (std::isfinite(o.via.f64)) return o.via.f64;
        break;
      case msgpack::type::POSITIVE_INTEGER:
        return static_cast<double>(o.via.u64);
      case msgpack::type::NEGATIVE_INTEGER:
        return static_cast<double>(o.via.i64);
      default:
        break;
    }
    throw bad(i, "a finite number");
  }
  bool boolean(std::uint32_t i) const {
    if (ptr_[i].type != msgpack::type::BOOLEAN) throw bad(i, "a boolean");
    return ptr_[i].via.boolean;
  }
  std::string string(std::uint32_t i) const {
    if (ptr_[i].type != msgpack::type::STR) throw bad(i, "a string");
    return std::string(ptr_[i].via.str.ptr, ptr_[i].via.str.size);
  }
  const msgpack::object& at(std::uint32_t i) const { return ptr_[i]; }
  std::uint32_t size() const { return size_; }
  CallError bad(std::uint32_t i, const char* want) const {
    return CallError("rpclib: function '" + method_ + "' threw an exception: argument " +
                     std::to_string(i + 1) + " must be " + want);
  }

 private:
  std::string method_;
  const msgpack::object* ptr_ = nullptr;
  std::uint32_t size_ = 0;
};

const msgpack::object* field(const msgpack::object& map, const char* key) {
  if (map.type != msgpack::type::MAP) return nullptr;
  for (std::uint32_t i = 0; i < map.via.map.size; ++i) {
    const auto& kv = map.via.map.ptr[i];
    if (kv.key.type == msgpack::type::STR &&
        std::string_view(kv.key.via.str.ptr, kv.key.via.str.size) == key) {
      return &kv.val;
    }
  }
  return nullptr;
}

void pack_vector(Packer& p, double x, double y, double z) {
  p.pack_map(3);
  p.pack(std::string("x_val"));
  p.pack_float(static_cast<float>(x));
  p.pack(std::string("y_val"));
  p.pack_float(static_cast<float>(y));
  p.pack(std::string("z_val"));
  p.pack_float(static_cast<float>(z));
}

void pack_state(Packer& p, const TwinStatus& s) {
  // NED: x forward at start (north), y right (east), z down; yaw clockwise.
  const double yaw = s.heading_deg * kDegToRad / 2, pitch = s.pitch_deg * kDegToRad / 2,
               roll = s.roll_deg * kDegToRad / 2;
  const double cy = std::cos(yaw), sy = std::sin(yaw), cp = std::cos(pitch), sp = std::sin(pitch),
               cr = std::cos(roll), sr = std::sin(roll);
  p.pack_map(9);
  p.pack(std::string("collision"));
  p.pack_map(8);
  p.pack(std::string("has_collided"));
  p.pack(s.collisions > 0);
  p.pack(std::string("normal"));
  pack_vector(p, 0, 0, 0);
  p.pack(std::string("impact_point"));
  pack_vector(p, 0, 0, 0);
  p.pack(std::string("position"));
  pack_vector(p, s.x_m, s.y_m, -s.z_m);
  p.pack(std::string("penetration_depth"));
  p.pack_float(0);
  p.pack(std::string("time_stamp"));
  p.pack_uint64(0);
  p.pack(std::string("object_name"));
  p.pack(std::string(""));
  p.pack(std::string("object_id"));
  p.pack_int(-1);
  p.pack(std::string("kinematics_estimated"));
  p.pack_map(6);
  p.pack(std::string("position"));
  pack_vector(p, s.x_m, s.y_m, -s.z_m);
  p.pack(std::string("orientation"));
  p.pack_map(4);
  p.pack(std::string("w_val"));
  p.pack_float(static_cast<float>(cr * cp * cy + sr * sp * sy));
  p.pack(std::string("x_val"));
  p.pack_float(static_cast<float>(sr * cp * cy - cr * sp * sy));
  p.pack(std::string("y_val"));
  p.pack_float(static_cast<float>(cr * sp * cy + sr * cp * sy));
  p.pack(std::string("z_val"));
  p.pack_float(static_cast<float>(cr * cp * sy - sr * sp * cy));
  p.pack(std::string("linear_velocity"));
  pack_vector(p, s.vx_m_s, s.vy_m_s, -s.vz_m_s);
  p.pack(std::string("angular_velocity"));
  pack_vector(p, 0, 0, 0);
  p.pack(std::string("linear_acceleration"));
  pack_vector(p, 0, 0, 0);
  p.pack(std::string("angular_acceleration"));
  pack_vector(p, 0, 0, 0);
  p.pack(std::string("gps_location"));
  p.pack_map(3);  // a fixed home; ~1.1e-5 deg per metre north
  p.pack(std::string("latitude"));
  p.pack_double(47.641468 + s.x_m / 111320.0);
  p.pack(std::string("longitude"));
  p.pack_double(-122.140165 + s.y_m / 75000.0);
  p.pack(std::string("altitude"));
  p.pack_float(static_cast<float>(122.0 + s.z_m));
  p.pack(std::string("timestamp"));
  p.pack_uint64(static_cast<std::uint64_t>(s.time_s * 1e9));
  p.pack(std::string("landed_state"));
  p.pack_int(s.mode == TwinMode::kLanded || s.mode == TwinMode::kCrashed ? 0 : 1);
  p.pack(std::string("rc_data"));
  p.pack_map(2);
  p.pack(std::string("is_initialized"));
  p.pack(false);
  p.pack(std::string("is_valid"));
  p.pack(false);
  p.pack(std::string("ready"));
  p.pack(s.mode != TwinMode::kCrashed);
  p.pack(std::string("ready_message"));
  p.pack(std::string(s.mode == TwinMode::kCrashed ? "crashed" : ""));
  p.pack(std::string("can_arm"));
  p.pack(s.mode != TwinMode::kCrashed);
}

int stick(double value, double maximum) {
  if (maximum <= 0) return 0;
  return static_cast<int>(std::clamp(std::round(100.0 * value / maximum), -100.0, 100.0));
}

}  // namespace

struct AirSimEmulator::Impl : std::enable_shared_from_this<AirSimEmulator::Impl> {
  struct Session {
    explicit Session(asio::io_context& io) : socket(io) {}
    tcp::socket socket;
    msgpack::unpacker unpacker{[](msgpack::type::object_type, std::size_t, void*) { return false; },
                               nullptr, MSGPACK_UNPACKER_INIT_BUFFER_SIZE,
                               msgpack::unpack_limit(10000, 10000, 1 << 16, 1 << 20, 1 << 16, 32)};
    std::array<char, 16384> buffer{};
    std::deque<std::string> queue;
    bool writing = false;
    bool closed = false;
  };
  enum class Kind { kTakeoff, kLand, kMove };
  struct Task {
    std::weak_ptr<Session> session;
    std::uint32_t msgid = 0;
    Kind kind = Kind::kMove;
    double deadline_s = 0;  // takeoff/land: false after it; move: true at it
  };

  Impl(TwinHost& h, AirSimEmulatorOptions o) : host(h), options(std::move(o)), acceptor(io) {
    boost::system::error_code ec;
    const auto address = asio::ip::make_address(options.bind_address, ec);
    if (ec) {
      throw std::invalid_argument("airsim emulator: bind_address '" + options.bind_address +
                                  "' is not an IP address");
    }
    const tcp::endpoint at(address, static_cast<unsigned short>(options.port));
    acceptor.open(at.protocol(), ec);
    if (!ec) acceptor.set_option(tcp::acceptor::reuse_address(true), ec);
    if (!ec) acceptor.bind(at, ec);
    if (!ec) acceptor.listen(asio::socket_base::max_listen_connections, ec);
    if (ec) {
      throw std::runtime_error("airsim emulator: cannot listen on TCP " + options.bind_address +
                               ":" + std::to_string(options.port) + ": " + ec.message() +
                               " (AirSim or another emulator running? use --airsim-port, 0 "
                               "for any)");
    }
  }

  void start() {
    listener = host.add_listener([this](TwinSim& sim, double t) { on_step(sim, t); });
    accept();
    thread = std::thread([this] { io.run(); });
  }

  void shutdown() {
    host.remove_listener(listener);
    io.stop();
    if (thread.joinable()) thread.join();
  }

  void accept() {
    auto session = std::make_shared<Session>(io);
    acceptor.async_accept(session->socket, [this, session](boost::system::error_code ec) {
      if (ec == asio::error::operation_aborted) return;
      if (!ec) {
        boost::system::error_code e2;
        session->socket.set_option(tcp::no_delay(true), e2);
        {
          std::lock_guard lock(mutex);
          ++stats.connections;
          sessions.insert(session);
        }
        read(session);
      }
      accept();
    });
  }

  void close(const std::shared_ptr<Session>& s) {
    if (s->closed) return;
    s->closed = true;
    if (!s->writing) discarded += s->queue.size();
    boost::system::error_code ignored;
    s->socket.close(ignored);
    std::lock_guard lock(mutex);
    sessions.erase(s);
  }

  void read(const std::shared_ptr<Session>& s) {
    s->socket.async_read_some(asio::buffer(s->buffer), [this, s](boost::system::error_code ec,
                                                                 std::size_t n) {
      if (ec) {
        close(s);
        return;
      }
      if (s->unpacker.nonparsed_size() + n > kMaxFrame) {
        malformed(s, "a frame larger than 1 MiB");
        return;
      }
      s->unpacker.reserve_buffer(n);
      std::copy_n(s->buffer.data(), n, s->unpacker.buffer());
      s->unpacker.buffer_consumed(n);
      try {
        msgpack::object_handle message;
        while (!s->closed && s->unpacker.next(message)) on_frame(s, message.get());
      } catch (const std::exception& e) {
        malformed(s, std::string("undecodable msgpack (") + e.what() + ")");
        return;
      }
      if (!s->closed) read(s);
    });
  }

  void malformed(const std::shared_ptr<Session>& s, const std::string& why) {
    {
      std::lock_guard lock(mutex);
      ++stats.malformed;
      stats.last_malformed = why;
    }
    close(s);
  }

  // I/O thread only.
  void write(const std::shared_ptr<Session>& s, std::string bytes) {
    if (s->closed) return;
    s->queue.push_back(std::move(bytes));
    if (s->writing) return;
    write_next(s);
  }

  void write_next(const std::shared_ptr<Session>& s) {
    if (s->queue.empty() || s->closed) {
      s->writing = false;
      return;
    }
    s->writing = true;
    asio::async_write(s->socket, asio::buffer(s->queue.front()),
                      [this, s](boost::system::error_code ec, std::size_t) {
                        s->queue.pop_front();
                        if (ec) {
                          discarded += s->queue.size() + 1;
                          close(s);
                          return;
                        }
                        write_next(s);
                      });
  }

  // Any thread: the bytes go out on the I/O thread.
  template <class PackResult>
  void respond(const std::weak_ptr<Session>& weak, std::uint32_t msgid, const std::string* error,
               PackResult&& pack_result) {
    msgpack::sbuffer buffer;
    Packer p(buffer);
    p.pack_array(4);
    p.pack_uint8(1);
    p.pack_uint32(msgid);
    if (error) {
      p.pack(*error);
      p.pack_nil();
    } else {
      p.pack_nil();
      pack_result(p);
    }
    ++responses;  // atomic: callers may hold `mutex`
    asio::post(io, [this, weak, bytes = std::string(buffer.data(), buffer.size())]() mutable {
      auto s = weak.lock();
      if (!s || s->closed) {
        ++discarded;  // its client is gone
        return;
      }
      write(s, std::move(bytes));
    });
  }

  void respond_bool(const std::weak_ptr<Session>& s, std::uint32_t id, bool value) {
    respond(s, id, nullptr, [value](Packer& p) { p.pack(value); });
  }

  void on_frame(const std::shared_ptr<Session>& s, const msgpack::object& o) {
    if (o.type != msgpack::type::ARRAY || o.via.array.size < 3) {
      malformed(s, "a frame that is not an msgpack-RPC array");
      return;
    }
    const auto* a = o.via.array.ptr;
    if (a[0].type == msgpack::type::POSITIVE_INTEGER && a[0].via.u64 == 2) return;  // notify
    const bool has_id = a[1].type == msgpack::type::POSITIVE_INTEGER && a[1].via.u64 <= 0xffffffffu;
    const auto id = has_id ? static_cast<std::uint32_t>(a[1].via.u64) : 0u;
    std::string why;
    if (o.via.array.size != 4) {
      why = "a request has 4 elements [0, msgid, method, params]";
    } else if (a[0].type != msgpack::type::POSITIVE_INTEGER || a[0].via.u64 != 0) {
      why = "type must be 0 (request)";
    } else if (!has_id) {
      why = "msgid must be an unsigned 32-bit integer";
    } else if (a[2].type != msgpack::type::STR) {
      why = "method must be a string";
    } else if (a[3].type != msgpack::type::ARRAY) {
      why = "params must be an array";
    }
    if (!why.empty()) {
      if (!has_id) {
        malformed(s, "malformed request: " + why);
        return;
      }
      {
        std::lock_guard lock(mutex);
        ++stats.malformed;
        stats.last_malformed = why;
      }
      const std::string error = "malformed request: " + why;
      respond(s, id, &error, [](Packer&) {});
      return;
    }
    const std::string method(a[2].via.str.ptr, a[2].via.str.size);
    host.with_sim([&](TwinSim& sim) {
      std::lock_guard lock(mutex);
      ++stats.requests;
      if (link_lost || sim.link_lost(sim.time_s())) {
        ++stats.dropped;
        return;
      }
      try {
        call_locked(sim, s, id, method, Args(method, a[3]));
      } catch (const CallError& e) {
        const std::string error = e.what();
        respond(s, id, &error, [](Packer&) {});
      }
    });
  }

  void check_vehicle(const Args& args, std::uint32_t i) const {
    const auto name = args.string(i);
    if (!name.empty() && name != options.vehicle) {
      throw CallError("Vehicle API for '" + name + "' is not available (the twin's AirSim "
                      "emulator has '" + options.vehicle + "')");
    }
  }

  void require_control() const {
    if (!api_control) {
      throw CallError("Vehicle cannot be controlled because EnableApiControl(true) was not "
                      "called");
    }
  }

  void cancel_task_locked() {
    if (task) respond_bool(task->session, task->msgid, false);
    task.reset();
  }

  void call_locked(TwinSim& sim, const std::shared_ptr<Session>& s, std::uint32_t id,
                   const std::string& m, const Args& args) {
    const double t = sim.time_s();
    if (m == "ping") {
      args.expect(0);
      return respond_bool(s, id, true);
    }
    if (m == "getServerVersion" || m == "getMinRequiredClientVersion") {
      args.expect(0);
      return respond(s, id, nullptr, [](Packer& p) { p.pack_int(1); });
    }
    if (m == "getMultirotorState") {
      args.expect(1);
      check_vehicle(args, 0);
      const auto status = sim.status();
      return respond(s, id, nullptr, [&](Packer& p) { pack_state(p, status); });
    }
    sim.keep_alive();
    if (m == "enableApiControl") {
      args.expect(2);
      check_vehicle(args, 1);
      api_control = args.boolean(0);
      return respond(s, id, nullptr, [](Packer& p) { p.pack_nil(); });
    }
    if (m == "isApiControlEnabled") {
      args.expect(1);
      check_vehicle(args, 0);
      return respond_bool(s, id, api_control);
    }
    if (m == "armDisarm") {
      args.expect(2);
      check_vehicle(args, 1);
      require_control();
      const bool arm = args.boolean(0);
      if (!arm && sim.mode() != TwinMode::kLanded && sim.mode() != TwinMode::kCrashed) {
        cancel_task_locked();
        sim.emergency();  // disarm in the air: motors off
      }
      armed = arm && sim.mode() != TwinMode::kCrashed;
      return respond_bool(s, id, arm == armed);
    }
    if (m == "takeoff") {
      args.expect(2);
      check_vehicle(args, 1);
      require_control();
      const double timeout = args.number(0);
      if (!armed) throw CallError("takeoff: the vehicle is not armed (call armDisarm(true))");
      const auto r = sim.takeoff();
      if (!r.ok) throw CallError("takeoff: " + r.error);
      cancel_task_locked();
      task = Task{s, id, Kind::kTakeoff, t + timeout};
      return;
    }
    if (m == "land") {
      args.expect(2);
      check_vehicle(args, 1);
      require_control();
      const double timeout = args.number(0);
      const auto r = sim.land();
      if (!r.ok) throw CallError("land: " + r.error);
      cancel_task_locked();
      task = Task{s, id, Kind::kLand, t + timeout};
      return;
    }
    if (m == "hover" || m == "cancelLastTask") {
      args.expect(1);
      check_vehicle(args, 0);
      require_control();
      cancel_task_locked();
      const auto mode = sim.mode();
      if (mode == TwinMode::kFlying || mode == TwinMode::kTakingOff) sim.hover();
      if (m == "hover") return respond_bool(s, id, true);
      return respond(s, id, nullptr, [](Packer& p) { p.pack_nil(); });
    }
    if (m == "moveByVelocityBodyFrame") {
      args.expect(7);
      check_vehicle(args, 6);
      require_control();
      const double vx = args.number(0), vy = args.number(1), vz = args.number(2);
      const double duration = args.number(3);
      const double drivetrain = args.number(4);
      const auto& yaw_mode = args.at(5);
      const auto* is_rate = field(yaw_mode, "is_rate");
      const auto* rate = field(yaw_mode, "yaw_or_rate");
      if (!is_rate || is_rate->type != msgpack::type::BOOLEAN || !rate ||
          (rate->type != msgpack::type::FLOAT32 && rate->type != msgpack::type::FLOAT64 &&
           rate->type != msgpack::type::POSITIVE_INTEGER &&
           rate->type != msgpack::type::NEGATIVE_INTEGER)) {
        throw CallError("moveByVelocityBodyFrame: yaw_mode must be a map {is_rate, yaw_or_rate}");
      }
      if (!is_rate->via.boolean) {
        throw CallError("moveByVelocityBodyFrame: yaw_mode.is_rate false (an absolute yaw) is "
                        "not supported by the twin's AirSim emulator");
      }
      if (drivetrain != 0 && drivetrain != 1) {
        throw CallError("moveByVelocityBodyFrame: drivetrain must be 0 or 1");
      }
      if (!(duration >= 0)) throw CallError("moveByVelocityBodyFrame: duration must be >= 0");
      const double yaw_rate = rate->type == msgpack::type::POSITIVE_INTEGER
                                  ? static_cast<double>(rate->via.u64)
                                  : rate->type == msgpack::type::NEGATIVE_INTEGER
                                        ? static_cast<double>(rate->via.i64)
                                        : rate->via.f64;
      const auto& c = sim.options().controller;
      const auto r = sim.rc(stick(vy, c.max_horizontal_m_s), stick(vx, c.max_horizontal_m_s),
                            stick(-vz, c.max_vertical_m_s), stick(yaw_rate, c.max_yaw_rate_deg_s));
      if (!r.ok) throw CallError("moveByVelocityBodyFrame: " + r.error);
      cancel_task_locked();
      task = Task{s, id, Kind::kMove, t + duration};
      return;
    }
    throw CallError("rpclib: server could not find function '" + m + "' with argument count " +
                    std::to_string(args.size()) + ".");
  }

  void on_step(TwinSim& sim, double t) {
    std::lock_guard lock(mutex);
    if (!task) return;
    const auto mode = sim.mode();
    const bool lost = link_lost || sim.link_lost(t);
    std::optional<bool> outcome;
    switch (task->kind) {
      case Kind::kTakeoff:
        if (mode == TwinMode::kFlying) outcome = true;
        else if (mode != TwinMode::kTakingOff || t > task->deadline_s) outcome = false;
        break;
      case Kind::kLand:
        if (mode == TwinMode::kLanded) outcome = true;
        else if (mode != TwinMode::kLanding || t > task->deadline_s) outcome = false;
        break;
      case Kind::kMove:
        if (t + 1e-9 >= task->deadline_s) {
          if (mode == TwinMode::kFlying || mode == TwinMode::kTakingOff) sim.hover();
          outcome = true;
        } else if (mode != TwinMode::kFlying && mode != TwinMode::kTakingOff) {
          outcome = false;
        }
        break;
    }
    if (!outcome) return;
    if (!lost) respond_bool(task->session, task->msgid, *outcome);
    task.reset();
  }

  TwinHost& host;
  AirSimEmulatorOptions options;
  asio::io_context io;
  tcp::acceptor acceptor;
  std::thread thread;
  int listener = 0;

  mutable std::mutex mutex;
  std::set<std::shared_ptr<Session>> sessions;
  bool link_lost = false;
  bool api_control = false;
  bool armed = false;
  std::optional<Task> task;
  AirSimEmulatorStats stats;
  std::atomic<std::uint64_t> responses{0};
  std::atomic<std::uint64_t> discarded{0};  // responses whose client was gone
};

AirSimEmulator::AirSimEmulator(TwinHost& host, AirSimEmulatorOptions options)
    : impl_(std::make_shared<Impl>(host, std::move(options))) {
  impl_->start();
}

AirSimEmulator::~AirSimEmulator() { impl_->shutdown(); }

std::uint16_t AirSimEmulator::port() const { return impl_->acceptor.local_endpoint().port(); }

void AirSimEmulator::set_link_lost(bool lost) {
  std::lock_guard lock(impl_->mutex);
  impl_->link_lost = lost;
}

void AirSimEmulator::drop_connections() {
  auto impl = impl_;
  asio::post(impl->io, [impl] {
    std::set<std::shared_ptr<Impl::Session>> all;
    {
      std::lock_guard lock(impl->mutex);
      all = impl->sessions;
    }
    for (const auto& s : all) impl->close(s);
  });
}

AirSimEmulatorStats AirSimEmulator::stats() const {
  std::lock_guard lock(impl_->mutex);
  auto s = impl_->stats;
  s.responses = impl_->responses - impl_->discarded;
  return s;
}

}  // namespace gbdcs::sim
