// TelloLink: the transport under TelloAdapter. Two UDP sockets on one I/O thread: commands
// go to address:command_port and their replies come back to the same local socket, matched
// in order to the commands that wait for one (Pending); state datagrams arrive on the local
// state port. A 10 ms timer drives the adapter's clock timers (tick()).
//
// The adapter derives from it (one mutex guards both, so a reply, a state datagram and a
// command call never interleave). Hooks, called on the I/O thread:
//   on_state_datagram(bytes)          without the lock;
//   on_late_reply_locked(pending)     with the lock, for a reply the caller stopped waiting
//                                     for (take-off/land: logged, never returned);
//   tick()                            every 10 ms (and from poll()).
// The derived constructor calls start() last; its destructor calls stop() first, so no hook
// runs on a half-built or half-destroyed adapter.
#pragma once

#include <utility>  // before Boost.Asio: 1.74's awaitable.hpp uses std::exchange

#include <array>
#include <boost/asio.hpp>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <thread>

#include "gbdcs/adapters/tello_adapter.hpp"
#include "gbdcs/contracts/clock.hpp"

namespace gbdcs::adapters::detail {

// Strips the trailing CR/LF/space/NUL a drone may append to a reply.
std::string trim_reply(std::string s);
// "error ...", "unknown command", "out of range": the drone refused.
bool is_error_reply(const std::string& reply);

class TelloLink {
 public:
  using WallClock = std::chrono::steady_clock;
  using udp = boost::asio::ip::udp;

  struct Pending {
    std::string command;
    bool done = false;      // answered, expired or abandoned: nobody waits any more
    bool answered = false;  // `reply` holds the drone's answer
    bool deferred = false;  // the caller stopped waiting (take-off/land): outcome logged only
    std::string reply;
    contracts::Duration expires{0};  // on the injected clock
  };

  // Binds both local sockets; throws std::invalid_argument (addresses) or std::runtime_error
  // (a port in use) with the fix.
  TelloLink(const contracts::Clock& clock, TelloOptions options);
  virtual ~TelloLink();
  TelloLink(const TelloLink&) = delete;
  TelloLink& operator=(const TelloLink&) = delete;

  // ---- sending (with `mutex` held) --------------------------------------------------------
  // Sends `text`; with expect_reply, the Pending that its reply will fill (nullptr otherwise;
  // done at once when the send failed, last_error then says why).
  std::shared_ptr<Pending> send_locked(const std::string& text, bool expect_reply);
  // Sends and waits up to `wait` for the reply; nullopt on no reply (send_failed tells a
  // failed send). `deferred`: a reply that comes later is still consumed (and handed to
  // on_late_reply_locked) instead of being abandoned.
  std::optional<std::string> request_locked(std::unique_lock<std::mutex>& lock,
                                            const std::string& text,
                                            std::chrono::milliseconds wait, bool deferred);
  void abandon_locked(const std::shared_ptr<Pending>& p);
  // Every waiting command given up (their replies can no longer be told apart).
  void abandon_all_locked();
  // Drops the waits whose reply is overdue (lost on the way).
  void expire_pending_locked();
  bool long_command_pending_locked() const;

  std::string endpoint_text() const;  // address:command_port
  std::string fix_text() const;       // which Wi-Fi to join, which options to check
  std::uint16_t local_state_port() const;
  std::uint16_t local_command_port() const;

  const contracts::Clock& clock;
  const TelloOptions options;

  mutable std::mutex mutex;  // guards everything below and the derived adapter's state
  std::condition_variable reply_cv;
  std::deque<std::shared_ptr<Pending>> pending;
  bool send_failed = false;  // the last request_locked() could not send
  contracts::Duration last_sent_at{0};
  std::string last_error;
  TelloStats stats;

 protected:
  void start();  // the I/O thread; call last in the derived constructor
  void stop();   // call first in the derived destructor

  virtual void on_state_datagram(std::string_view datagram) = 0;
  virtual void on_late_reply_locked(const Pending& p) = 0;
  virtual void tick() = 0;

 private:
  void open_bound(udp::socket& socket, const udp::endpoint& at, const char* what,
                  const char* key);
  void receive_reply();
  void receive_state();
  void schedule_tick();
  void on_reply(std::string text);

  boost::asio::io_context io_;
  udp::socket command_socket_;
  udp::socket state_socket_;
  boost::asio::steady_timer tick_timer_;
  udp::endpoint drone_;
  udp::endpoint reply_from_, state_from_;
  std::array<char, 2048> reply_buffer_{};
  std::array<char, 4096> state_buffer_{};
  std::thread io_thread_;
};

}  // namespace gbdcs::adapters::detail
