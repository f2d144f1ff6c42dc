#include "gbdcs/sim/tello_emulator.hpp"

#include <algorithm>
#include <boost/asio.hpp>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <vector>

#include "gbdcs/contracts/json_options.hpp"

namespace gbdcs::sim {

namespace asio = boost::asio;
using asio::ip::udp;

namespace {

std::string trim(std::string_view s) {
  while (!s.empty() && (s.back() == '\r' || s.back() == '\n' || s.back() == ' ' ||
                        s.back() == '\0')) {
    s.remove_suffix(1);
  }
  while (!s.empty() && s.front() == ' ') s.remove_prefix(1);
  return std::string(s);
}

std::vector<std::string> split(const std::string& s) {
  std::istringstream in(s);
  std::vector<std::string> out;
  for (std::string w; in >> w;) out.push_back(w);
  return out;
}

std::optional<int> to_int(const std::string& s) {
  try {
    std::size_t used = 0;
    const int v = std::stoi(s, &used);
    if (used != s.size()) return std::nullopt;
    return v;
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

int iround(double v) { return static_cast<int>(std::lround(v)); }

std::string read_word(const nlohmann::json& doc, const char* key, const std::string& fallback) {
  const auto it = doc.find(key);
  if (it == doc.end()) return fallback;
  if (!it->is_string() || it->get<std::string>().empty()) {
    throw std::invalid_argument(std::string("tello emulator options: commands: '") + key +
                                "' must be a non-empty string");
  }
  return it->get<std::string>();
}

}  // namespace

TelloEmulatorOptions TelloEmulatorOptions::from_json(const nlohmann::json& doc) {
  TelloEmulatorOptions o;
  const std::string owner = "tello emulator options";
  if (doc.is_null()) return o;
  if (!doc.is_object()) throw std::invalid_argument(owner + ": must be a JSON object");
  nlohmann::json rest = doc;
  for (const char* key : {"bind_address", "sdk"}) {
    if (auto it = rest.find(key); it != rest.end()) {
      if (!it->is_string()) throw std::invalid_argument(owner + ": '" + key + "' must be a string");
      (std::string(key) == "sdk" ? o.sdk : o.bind_address) = it->get<std::string>();
      rest.erase(key);
    }
  }
  if (auto it = rest.find("commands"); it != rest.end()) {
    if (!it->is_object()) throw std::invalid_argument(owner + ": 'commands' must be an object");
    for (const auto& [k, v] : it->items()) {
      static const char* kKnown[] = {"handshake", "takeoff", "land", "emergency",
                                     "stop",      "rc",      "battery", "keepalive"};
      if (std::find_if(std::begin(kKnown), std::end(kKnown),
                       [&](const char* n) { return k == n; }) == std::end(kKnown)) {
        throw std::invalid_argument(owner + ": commands: '" + k + "' is not a command word");
      }
      (void)v;
    }
    o.words.handshake = read_word(*it, "handshake", o.words.handshake);
    o.words.takeoff = read_word(*it, "takeoff", o.words.takeoff);
    o.words.land = read_word(*it, "land", o.words.land);
    o.words.emergency = read_word(*it, "emergency", o.words.emergency);
    o.words.stop = read_word(*it, "stop", o.words.stop);
    o.words.rc = read_word(*it, "rc", o.words.rc);
    o.words.battery = read_word(*it, "battery", o.words.battery);
    rest.erase("commands");
  }
  contracts::JsonOptionReader r(rest, owner);
  r.read("command_port", o.command_port);
  r.read("state_port", o.state_port);
  r.read("state_hz", o.state_hz);
  r.finish();
  contracts::require(o.command_port >= 0 && o.command_port <= 65535, owner, "command_port",
                     "must be within [0, 65535]");
  contracts::require(o.state_port >= 1 && o.state_port <= 65535, owner, "state_port",
                     "must be within [1, 65535]");
  contracts::require(o.state_hz >= 1 && o.state_hz <= 100, owner, "state_hz",
                     "must be within [1, 100]");
  contracts::require(o.sdk == "2.0" || o.sdk == "1.3", owner, "sdk", "must be \"2.0\" or \"1.3\"");
  return o;
}

struct TelloEmulator::Impl {
  enum class Waiting { kNone, kTakeoff, kLand };

  Impl(TwinHost& h, TelloEmulatorOptions o) : host(h), options(std::move(o)), socket(io) {
    boost::system::error_code ec;
    const auto address = asio::ip::make_address(options.bind_address, ec);
    if (ec) {
      throw std::invalid_argument("tello emulator: bind_address '" + options.bind_address +
                                  "' is not an IP address");
    }
    const udp::endpoint at(address, static_cast<unsigned short>(options.command_port));
    socket.open(at.protocol(), ec);
    if (!ec) socket.bind(at, ec);
    if (ec) {
      throw std::runtime_error("tello emulator: cannot bind UDP " + options.bind_address + ":" +
                               std::to_string(options.command_port) + ": " + ec.message() +
                               " (another emulator running? use --tello-port, 0 for any)");
    }
    listener = host.add_listener([this](TwinSim& sim, double t) { on_step(sim, t); });
    receive();
    thread = std::thread([this] { io.run(); });
  }

  ~Impl() {
    host.remove_listener(listener);
    io.stop();
    if (thread.joinable()) thread.join();
  }

  void receive() {
    socket.async_receive_from(asio::buffer(buffer), from,
                              [this](boost::system::error_code ec, std::size_t n) {
                                if (ec == asio::error::operation_aborted) return;
                                if (!ec) on_datagram(std::string_view(buffer.data(), n), from);
                                receive();
                              });
  }

  bool lost_locked(const TwinSim& sim) const { return link_lost || sim.link_lost(sim.time_s()); }

  void send_locked(const std::string& text, const udp::endpoint& to) {
    boost::system::error_code ec;
    socket.send_to(asio::buffer(text), to, 0, ec);  // a lost datagram is what UDP does
  }

  void reply_locked(const std::string& text) {
    ++stats.replies;
    send_locked(text, client);
  }

  void on_datagram(std::string_view raw, const udp::endpoint& sender) {
    host.with_sim([&](TwinSim& sim) {
      std::lock_guard lock(mutex);
      if (lost_locked(sim)) {
        ++stats.dropped;
        return;
      }
      ++stats.datagrams;
      const std::string text = trim(raw);
      if (text.empty() || text.size() > 512 ||
          std::any_of(text.begin(), text.end(), [](char c) { return c < 0x20 || c > 0x7e; })) {
        return;  // not a command; a Tello ignores it
      }
      client = sender;
      have_client = true;
      handle_locked(sim, text);
    });
  }

  // A reply-expecting command releases a pending take-off/land reply first (command order).
  void release_waiting_locked() {
    if (waiting != Waiting::kNone) reply_locked("ok");
    waiting = Waiting::kNone;
  }

  void handle_locked(TwinSim& sim, const std::string& text) {
    const auto words = split(text);
    const std::string& verb = words.front();
    const auto& w = options.words;
    if (verb == w.handshake && words.size() == 1) {
      sim.keep_alive();
      release_waiting_locked();
      if (!sdk_mode) next_state_s = sim.time_s();
      sdk_mode = true;
      reply_locked("ok");
      return;
    }
    if (!sdk_mode) return;  // a Tello ignores everything before "command"
    if (verb == w.rc) {
      ++stats.rc_commands;
      std::array<int, 4> v{};
      bool ok = words.size() == 5;
      for (std::size_t i = 0; ok && i < 4; ++i) {
        const auto n = to_int(words[i + 1]);
        ok = n && *n >= -100 && *n <= 100;
        if (ok) v[i] = *n;
      }
      if (!ok) {
        reply_locked("error");
        return;
      }
      sim.rc(v[0], v[1], v[2], v[3]);  // refused on the ground: a Tello ignores it silently
      return;
    }
    sim.keep_alive();
    release_waiting_locked();
    if (verb == w.takeoff && words.size() == 1) {
      const auto r = sim.takeoff();
      if (!r.ok) {
        reply_locked("error " + r.error);
      } else {
        waiting = Waiting::kTakeoff;
      }
      return;
    }
    if (verb == w.land && words.size() == 1) {
      const auto r = sim.land();
      if (!r.ok) {
        reply_locked("error " + r.error);
      } else if (sim.mode() == TwinMode::kLanded) {
        reply_locked("ok");
      } else {
        waiting = Waiting::kLand;
      }
      return;
    }
    if (verb == w.emergency && words.size() == 1) {
      sim.emergency();
      reply_locked("ok");
      return;
    }
    if (verb == w.stop && words.size() == 1 && options.sdk != "1.3") {
      const auto mode = sim.mode();
      if (mode == TwinMode::kFlying || mode == TwinMode::kTakingOff) sim.hover();
      reply_locked("ok");
      return;
    }
    if (verb == w.battery && words.size() == 1) {
      reply_locked(std::to_string(iround(sim.status().battery_pct)));
      return;
    }
    answer_other_locked(sim, text, words);
  }

  void answer_other_locked(TwinSim& sim, const std::string& text,
                           const std::vector<std::string>& words) {
    const auto s = sim.status();
    const std::string& verb = words.front();
    if (words.size() == 1) {
      if (verb == "speed?") return reply_locked(std::to_string(speed_cm_s) + ".0");
      if (verb == "time?") return reply_locked(std::to_string(iround(motor_time_s)) + "s");
      if (verb == "height?") return reply_locked(std::to_string(iround(s.z_m * 10)) + "dm");
      if (verb == "temp?") return reply_locked("60~63C");
      if (verb == "attitude?") {
        return reply_locked("pitch:" + std::to_string(iround(s.pitch_deg)) +
                            ";roll:" + std::to_string(iround(s.roll_deg)) +
                            ";yaw:" + std::to_string(yaw_of(s)) + ";");
      }
      if (verb == "baro?") return reply_locked(format("%.2f", 100.0 + s.z_m));
      if (verb == "tof?") return reply_locked(std::to_string(tof_cm(s) * 10) + "mm");
      if (verb == "wifi?") return reply_locked("90");
      if (verb == "sdk?" && options.sdk == "2.0") return reply_locked("20");
      if (verb == "sn?") return reply_locked("0TQZGBDCSTWIN1");
      if (verb == "streamon" || verb == "streamoff") {
        if (stream_handler) stream_handler(verb == "streamon", client.address().to_string());
        return reply_locked("ok");
      }
    }
    if (verb == "speed" && words.size() == 2) {
      const auto v = to_int(words[1]);
      if (!v || *v < 10 || *v > 100) return reply_locked("error");
      speed_cm_s = *v;
      return reply_locked("ok");
    }
    static const char* kMoves[] = {"up",  "down", "left", "right", "forward", "back",
                                   "cw",  "ccw",  "flip", "go",    "curve",   "jump"};
    for (const char* m : kMoves) {
      if (verb == m) return reply_locked("error Not supported by the twin's Tello emulator");
    }
    ++stats.unknown_commands;
    reply_locked("unknown command: " + text.substr(0, 64));
  }

  static int yaw_of(const TwinStatus& s) {
    double yaw = s.heading_deg;  // [0, 360) clockwise -> (-180, 180]
    if (yaw > 180) yaw -= 360;
    return iround(yaw);
  }

  static int tof_cm(const TwinStatus& s) { return std::max(10, iround(s.z_m * 100 + 10)); }

  static std::string format(const char* fmt, double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, fmt, v);
    return buf;
  }

  std::string state_text(const TwinStatus& s) const {
    const int vgx = iround(s.vx_m_s * 10), vgy = iround(s.vy_m_s * 10);
    const int vgz = iround(-s.vz_m_s * 10);
    const int h = std::max(0, iround(s.z_m * 100));
    // Gravity on the accelerometer, in 0.001 g (body z up: -1000 at rest).
    std::string out;
    if (options.sdk == "2.0") out += "mid:-1;x:0;y:0;z:0;mpry:0,0,0;";
    out += "pitch:" + std::to_string(iround(s.pitch_deg)) + ";roll:" +
           std::to_string(iround(s.roll_deg)) + ";yaw:" + std::to_string(yaw_of(s)) +
           ";vgx:" + std::to_string(vgx) + ";vgy:" + std::to_string(vgy) +
           ";vgz:" + std::to_string(vgz) + ";templ:60;temph:63;tof:" + std::to_string(tof_cm(s)) +
           ";h:" + std::to_string(h) + ";bat:" + std::to_string(iround(s.battery_pct)) +
           ";baro:" + format("%.2f", 100.0 + s.z_m) + ";time:" + std::to_string(iround(motor_time_s)) +
           ";agx:0.00;agy:0.00;agz:-1000.00;\r\n";
    return out;
  }

  void on_step(TwinSim& sim, double t) {
    std::lock_guard lock(mutex);
    const auto mode = sim.mode();
    if (mode != TwinMode::kLanded && mode != TwinMode::kCrashed && last_step_s >= 0) {
      motor_time_s += t - last_step_s;
    }
    last_step_s = t;
    if (!sdk_mode || !have_client) return;
    const bool lost = lost_locked(sim);
    if (waiting == Waiting::kTakeoff) {
      if (mode == TwinMode::kFlying) {
        finish_locked(lost, "ok");
      } else if (mode != TwinMode::kTakingOff) {
        finish_locked(lost, "error");
      }
    } else if (waiting == Waiting::kLand) {
      if (mode == TwinMode::kLanded) {
        finish_locked(lost, "ok");
      } else if (mode == TwinMode::kCrashed) {
        finish_locked(lost, "error");
      }
    }
    if (t + 1e-9 < next_state_s) return;
    next_state_s += 1.0 / options.state_hz;
    if (next_state_s < t) next_state_s = t + 1.0 / options.state_hz;  // fell far behind
    if (lost) return;
    ++stats.state_packets;
    send_locked(state_text(sim.status()),
                udp::endpoint(client.address(), static_cast<unsigned short>(options.state_port)));
  }

  void finish_locked(bool lost, const char* reply) {
    waiting = Waiting::kNone;
    if (!lost) reply_locked(reply);
  }

  TwinHost& host;
  TelloEmulatorOptions options;
  asio::io_context io;
  udp::socket socket;
  udp::endpoint from;
  std::array<char, 2048> buffer{};
  std::thread thread;
  int listener = 0;

  mutable std::mutex mutex;
  bool link_lost = false;
  bool sdk_mode = false;
  bool have_client = false;
  udp::endpoint client;
  Waiting waiting = Waiting::kNone;
  double next_state_s = 0;
  double motor_time_s = 0;
  double last_step_s = -1;
  int speed_cm_s = 100;
  StreamHandler stream_handler;
  TelloEmulatorStats stats;
};

TelloEmulator::TelloEmulator(TwinHost& host, TelloEmulatorOptions options)
    : impl_(std::make_unique<Impl>(host, std::move(options))) {}

TelloEmulator::~TelloEmulator() = default;

std::uint16_t TelloEmulator::port() const { return impl_->socket.local_endpoint().port(); }

void TelloEmulator::set_state_port(int port) {
  std::lock_guard lock(impl_->mutex);
  impl_->options.state_port = port;
}

void TelloEmulator::set_link_lost(bool lost) {
  std::lock_guard lock(impl_->mutex);
  impl_->link_lost = lost;
}

bool TelloEmulator::link_lost() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->link_lost;
}

void TelloEmulator::set_stream_handler(StreamHandler handler) {
  std::lock_guard lock(impl_->mutex);
  impl_->stream_handler = std::move(handler);
}

TelloEmulatorStats TelloEmulator::stats() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->stats;
}

}  // namespace gbdcs::sim
