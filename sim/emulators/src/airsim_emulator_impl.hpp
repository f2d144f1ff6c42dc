// The AirSim emulator's insides, shared by its two halves: the msgpack-RPC server
// (airsim_emulator.cpp: listen, sessions, framing, responses) and the method table
// (airsim_methods.cpp: what each AirSim method does to the twin, the MultirotorState).
#pragma once

#include <utility>  // before Boost 1.74 Asio (std::exchange in awaitable.hpp)
#include <array>
#include <atomic>
#include <boost/asio.hpp>
#include <cmath>
#include <deque>
#include <msgpack.hpp>
#include <mutex>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>

#include "gbdcs/sim/airsim_emulator.hpp"

namespace gbdcs::sim {

namespace airsim_emulator_detail {

namespace asio = boost::asio;
using asio::ip::tcp;
using Packer = msgpack::packer<msgpack::sbuffer>;

// A call's failure: sent back as the response's error string.
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


}  // namespace airsim_emulator_detail

struct AirSimEmulator::Impl : std::enable_shared_from_this<AirSimEmulator::Impl> {
  using Args = airsim_emulator_detail::Args;
  using CallError = airsim_emulator_detail::CallError;
  using Packer = airsim_emulator_detail::Packer;
  using tcp = airsim_emulator_detail::tcp;
  using io_context = boost::asio::io_context;

  struct Session {
    explicit Session(io_context& io) : socket(io) {}
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


  // ---- the server (airsim_emulator.cpp) ---------------------------------------------------
  Impl(TwinHost& h, AirSimEmulatorOptions o);
  void start();
  void shutdown();
  void accept();
  void close(const std::shared_ptr<Session>& s);
  void read(const std::shared_ptr<Session>& s);
  void malformed(const std::shared_ptr<Session>& s, const std::string& why);
  // I/O thread only.
  void write(const std::shared_ptr<Session>& s, std::string bytes);
  void write_next(const std::shared_ptr<Session>& s);
  void respond_bool(const std::weak_ptr<Session>& s, std::uint32_t id, bool value);
  void on_frame(const std::shared_ptr<Session>& s, const msgpack::object& o);
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
    boost::asio::post(io, [this, weak, bytes = std::string(buffer.data(), buffer.size())]() mutable {
      auto s = weak.lock();
      if (!s || s->closed) {
        ++discarded;  // its client is gone
        return;
      }
      write(s, std::move(bytes));
    });
  }

  // ---- the method table (airsim_methods.cpp) ----------------------------------------------
  void check_vehicle(const Args& args, std::uint32_t i) const;
  void require_control() const;
  void cancel_task_locked();
  void call_locked(TwinSim& sim, const std::shared_ptr<Session>& s, std::uint32_t id,
                   const std::string& m, const Args& args);
  void on_step(TwinSim& sim, double t);

  TwinHost& host;
  AirSimEmulatorOptions options;
  boost::asio::io_context io;
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

}  // namespace gbdcs::sim
