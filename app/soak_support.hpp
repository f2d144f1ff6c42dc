// Pieces of `gbdcs bench soak` (app/bench_soak_command.cpp): a `gbdcs serve` child process,
// blocking HTTP calls, and a dashboard-like /ws/live client that renews its token before it
// expires without missing an alert.
//
// ServeChild   forks and execs this binary's `serve` with the given arguments and
//              environment, reads its log (one JSON object per line, --log-json) on a thread
//              and hands every line to a callback; SIGTERM and waits on destruction.
// SoakClient   one thread: logs in, opens /ws/live, reads every message, records per type
//              the delivery latencies (receive - envelope ts, in ms) and every alert; at 75 % of
//              the token's life (0.6-0.9, per client) it logs in again, opens a second socket, keeps reading the old
//              one until it delivers a message stamped after the new one was accepted (so every
//              alert is on one or the other), then closes the old one.
#pragma once

#include <sys/types.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <vector>

namespace gbdcs::app::soak {

struct HttpReply {
  int status = 0;
  std::string body;
  double elapsed_ms = 0;
};

// One request on a fresh connection; status 0 when the server could not be reached.
HttpReply http_call(unsigned short port, const std::string& method, const std::string& target,
                    const std::string& body = {}, const std::string& token = {});

// Milliseconds since the Unix epoch of a contracts::format_utc string; -1 if malformed.
std::int64_t utc_ms(const std::string& text);
std::int64_t now_utc_ms();

// VmRSS (or VmHWM with peak=true) of a process, MB; 0 when it is gone.
double rss_mb(pid_t pid, bool peak = false);
// Children of `pid` that are not zombies.
std::vector<pid_t> children_of(pid_t pid);
double percentile(std::vector<double> values, double q);

class ServeChild {
 public:
  ServeChild(const std::vector<std::string>& args, const std::map<std::string, std::string>& env,
             std::function<void(const std::string& line)> on_line);
  ~ServeChild();
  ServeChild(const ServeChild&) = delete;
  ServeChild& operator=(const ServeChild&) = delete;
  pid_t pid() const { return pid_; }
  unsigned short port() const { return port_; }  // 0: it never said it was listening
  bool alive();  // false once it has exited (its status is kept for stop())
  // The last log lines (for an error report).
  std::vector<std::string> tail() const;
  int stop();  // SIGTERM, wait; returns the exit status (or -signal)

 private:
  pid_t pid_ = -1;
  int fd_ = -1;
  unsigned short port_ = 0;
  std::thread reader_;
  mutable std::mutex tail_mutex_;
  std::vector<std::string> tail_;
  std::function<void(const std::string&)> on_line_;
  int status_ = 0;
  bool stopped_ = false;
  bool exited_ = false;
};

struct ClientReport {
  std::map<std::string, std::int64_t> messages;  // by type
  std::vector<double> delivery_ms;               // telemetry: receive - envelope ts
  std::vector<double> frame_age_ms;              // frame: receive - capture_time
  std::vector<double> command_age_ms;            // command: receive - command.issued_at
  std::vector<double> alert_age_ms;              // alert: receive - alert.timestamp
  std::set<std::string> alerts;                  // each alert's data, dumped (its identity)
  std::int64_t renewals = 0;
  std::int64_t unexpected_closes = 0;
  std::string last_error;
};

class SoakClient {
 public:
  // renew_fraction: the share of the token's life after which it renews (spread the clients
  // over 0.6-0.9 so their logins, Argon2id each, do not all land at once).
  SoakClient(unsigned short port, std::string email, std::string password, double renew_fraction,
             const std::atomic<bool>& stop);
  ~SoakClient();
  bool wait_connected(std::chrono::seconds timeout);
  // How many of `alerts` (dumped alert data) this client has not received yet.
  std::size_t missing(const std::set<std::string>& alerts) const;
  ClientReport report();  // after stop: joins the thread

 private:
  void run();
  unsigned short port_;
  std::string email_, password_;
  double renew_fraction_;
  const std::atomic<bool>& stop_;
  std::atomic<bool> connected_{false};
  mutable std::mutex alerts_mutex_;  // guards report_.alerts while running
  ClientReport report_;
  std::thread thread_;
};

}  // namespace gbdcs::app::soak
