// AirSimLink: the msgpack-RPC transport under AirSimAdapter. One TCP connection on one I/O
// thread: requests [0, id, method, params] are written at once, responses [1, id, error,
// result] are matched by id (Call); a broken stream, an undecodable frame or a frame over
// 4 MiB drops the connection, fails every waiting call and re-dials with back-off
// (reconnect_min_s doubling up to reconnect_max_s) while the adapter is connected.
//
// The adapter derives from it (one mutex guards both). Hooks, called with the lock held on
// the I/O thread:
//   on_state_response_locked(call, frames)  a getMultirotorState answer (is_state calls);
//   on_redialled_locked()                   the connection came back while connected;
//   tick()                                  every 10 ms (and from poll()), without the lock.
// The derived constructor calls start() last; its destructor calls stop() first.
#pragma once

#include <utility>  // before Boost.Asio: 1.74's awaitable.hpp uses std::exchange

#include <array>
#include <boost/asio.hpp>
#include <chrono>
#include <condition_variable>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "gbdcs/adapters/airsim_adapter.hpp"
#include "gbdcs/adapters/airsim_rpc.hpp"
#include "gbdcs/contracts/clock.hpp"

namespace gbdcs::adapters::detail {

class AirSimLink {
 public:
  using WallClock = std::chrono::steady_clock;
  using Packer = msgpack::packer<msgpack::sbuffer>;
  using tcp = boost::asio::ip::tcp;

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

  // Throws std::invalid_argument when 'address' is not an IP address.
  AirSimLink(const contracts::Clock& clock, AirSimOptions options);
  virtual ~AirSimLink();
  AirSimLink(const AirSimLink&) = delete;
  AirSimLink& operator=(const AirSimLink&) = delete;

  // ---- with `mutex` held ------------------------------------------------------------------
  // Starts a connection attempt (completes on the I/O thread; `dialing` until then).
  void dial();
  void lost_socket_locked(const std::string& why);
  // Sends a request; the Call its response will fill, nullptr when nothing was sent.
  std::shared_ptr<Call> call_locked(const std::string& method,
                                    const std::function<void(Packer&)>& params, bool deferred,
                                    bool is_state = false);
  // Calls and waits up to `wait`; the Call (done or not), or nullptr when nothing was sent.
  // `deferred`: a call still unanswered is kept (its late outcome logged) instead of expiring.
  std::shared_ptr<Call> wait_locked(std::unique_lock<std::mutex>& lock, const std::string& method,
                                    const std::function<void(Packer&)>& params,
                                    std::chrono::milliseconds wait, bool deferred);
  // An error, `false` or no answer from a call that must succeed at once (last_error says).
  control::Result check(const std::shared_ptr<Call>& c, const std::string& what, bool want_true);
  void expire_calls_locked();
  void redial_if_due_locked(contracts::Duration now);

  std::string where() const;  // address:port
  std::string fix() const;    // what to start and which options to check

  void deliver(const std::vector<contracts::TelemetryFrame>& frames,
               const control::TelemetrySink& to);

  const contracts::Clock& clock;
  const AirSimOptions options;

  mutable std::mutex mutex;  // guards everything below and the derived adapter's state
  std::condition_variable cv;
  std::mutex sink_mutex;  // frames reach the sink in order
  control::TelemetrySink sink;
  std::map<std::uint32_t, std::shared_ptr<Call>> calls;
  bool connected = false;  // the adapter wants the link: re-dial when it breaks
  bool socket_up = false;
  bool dialing = false;
  std::uint64_t dial_generation = 0;
  std::string dial_error;
  double backoff_s = 0.5;
  contracts::Duration reconnect_at{0};
  std::string last_error;
  AirSimStats stats;

 protected:
  void start();  // the I/O thread; call last in the derived constructor
  void stop();   // call first in the derived destructor

  virtual void on_state_response_locked(const Call& call,
                                        std::vector<contracts::TelemetryFrame>& frames) = 0;
  virtual void on_redialled_locked() = 0;
  virtual void tick() = 0;

 private:
  static std::unique_ptr<msgpack::unpacker> make_unpacker();
  void schedule_tick();
  void read();
  void lost_socket(const std::string& why);
  bool on_bytes(std::size_t n);
  void on_message(msgpack::object_handle&& message,
                  std::vector<contracts::TelemetryFrame>& frames);

  boost::asio::io_context io_;
  tcp::socket socket_;
  boost::asio::steady_timer tick_timer_;
  tcp::endpoint server_;
  std::array<char, 65536> read_buffer_{};
  std::thread io_thread_;
  std::unique_ptr<msgpack::unpacker> unpacker_;
  std::uint32_t next_id_ = 1;
};

}  // namespace gbdcs::adapters::detail
