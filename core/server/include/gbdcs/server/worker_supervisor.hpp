// WorkerSupervisor: runs the vision worker process (`gbdcs vision --publish ...`) and watches
// it. The worker is lost when its process exits (crash, kill -9), its WebSocket closes, or
// nothing (frame or heartbeat) arrives for silence_s. Then, once per episode: on_lost(why)
// (the server commands HOVER and raises a critical alert), and the worker is restarted after
// a back-off (initial, doubling, capped; reset once a worker has run healthy for 30 s).
// on_ready() is called at the first message of each new worker.
// Time: the injected Clock; a watch thread polls every poll_s.
#pragma once

#include <sys/types.h>

#include <atomic>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "gbdcs/contracts/clock.hpp"
#include "gbdcs/server/drone_service.hpp"

namespace gbdcs::server {

struct WorkerOptions {
  std::vector<std::string> argv;  // argv[0] is the executable path
  double silence_s = 2.0;
  double startup_grace_s = 30.0;  // before its first message (model loading)
  double backoff_initial_s = 0.5;
  double backoff_max_s = 10.0;
  double poll_s = 0.01;
};

class WorkerSupervisor {
 public:
  WorkerSupervisor(const contracts::Clock& clock, WorkerOptions options,
                   std::function<void(const std::string&)> on_lost, std::function<void()> on_ready,
                   EventLog log);
  ~WorkerSupervisor();
  void start();
  void stop();  // SIGTERM, then SIGKILL after 2 s

  void on_connected();
  void on_message();
  void on_disconnected();

  std::optional<pid_t> pid() const;
  std::int64_t restarts() const { return restarts_.load(); }
  bool running() const;

 private:
  void watch();
  void spawn_locked();
  void lost_locked(const std::string& why, std::vector<std::function<void()>>& after);

  const contracts::Clock& clock_;
  WorkerOptions options_;
  std::function<void(const std::string&)> on_lost_;
  std::function<void()> on_ready_;
  EventLog log_;
  mutable std::mutex mutex_;
  pid_t pid_ = -1;
  bool lost_ = false;          // this episode reported
  bool got_message_ = false;   // since the last spawn
  contracts::Duration spawned_at_{};
  contracts::Duration last_message_{};
  contracts::Duration restart_at_{};
  double backoff_s_;
  std::atomic<std::int64_t> restarts_{0};
  std::atomic<bool> running_{false};
  std::thread thread_;
};

}  // namespace gbdcs::server
