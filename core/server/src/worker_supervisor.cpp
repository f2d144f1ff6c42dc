#include "gbdcs/server/worker_supervisor.hpp"

#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace gbdcs::server {

WorkerSupervisor::WorkerSupervisor(const contracts::Clock& clock, WorkerOptions options,
                                   std::function<void(const std::string&)> on_lost,
                                   std::function<void()> on_ready, EventLog log)
    : clock_(clock), options_(std::move(options)), on_lost_(std::move(on_lost)),
      on_ready_(std::move(on_ready)), log_(std::move(log)), backoff_s_(options_.backoff_initial_s) {}

WorkerSupervisor::~WorkerSupervisor() { stop(); }

void WorkerSupervisor::start() {
  {
    std::lock_guard lock(mutex_);
    spawn_locked();
  }
  running_ = true;
  thread_ = std::thread([this] { watch(); });
}

void WorkerSupervisor::spawn_locked() {
  std::vector<char*> argv;
  for (auto& a : options_.argv) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  const pid_t parent = getpid();
  const pid_t child = fork();
  if (child == 0) {
    // Only async-signal-safe calls between fork and exec. Die with the server. Its own
    // process group: a Ctrl-C on the terminal (SIGINT to the foreground group) reaches only
    // the server, which stops the worker in order, instead of the worker dying first and
    // being reported lost (VISION_WORKER_LOST, HOVER) by a server on its way down.
    prctl(PR_SET_PDEATHSIG, SIGTERM);
    setpgid(0, 0);
    if (getppid() != parent) _exit(127);
    execv(argv[0], argv.data());
    _exit(127);
  }
  spawned_at_ = clock_.now();
  last_message_ = spawned_at_;
  got_message_ = false;
  if (child < 0) {
    pid_ = -1;
    if (log_) log_("error", {{"event", "worker_spawn_failed"}, {"cause", std::strerror(errno)}});
    return;
  }
  pid_ = child;
  if (log_) log_("info", {{"event", "worker_started"}, {"pid", child}, {"argv", options_.argv}});
}

void WorkerSupervisor::lost_locked(const std::string& why,
                                   std::vector<std::function<void()>>& after) {
  if (pid_ > 0) {
    kill(pid_, SIGKILL);  // a silent or disconnected worker is not trusted to recover
  }
  if (!lost_) {
    lost_ = true;
    if (log_) log_("error", {{"event", "worker_lost"}, {"cause", why}, {"pid", pid_}});
    after.push_back([this, why] {
      if (on_lost_) on_lost_(why);
    });
  }
  if (restart_at_ <= spawned_at_) {
    // Healthy for long enough: start the back-off again.
    if (got_message_ && contracts::to_seconds(clock_.now() - spawned_at_) > 30) {
      backoff_s_ = options_.backoff_initial_s;
    }
    restart_at_ = clock_.now() + contracts::from_seconds(backoff_s_);
    backoff_s_ = std::min(options_.backoff_max_s, backoff_s_ * 2);
  }
}

void WorkerSupervisor::watch() {
  while (running_) {
    std::vector<std::function<void()>> after;
    {
      std::lock_guard lock(mutex_);
      const auto now = clock_.now();
      if (pid_ > 0) {
        int status = 0;
        const pid_t r = waitpid(pid_, &status, WNOHANG);
        if (r == pid_) {
          std::string why = WIFSIGNALED(status)
                                ? "the vision worker was killed by signal " +
                                      std::to_string(WTERMSIG(status))
                                : "the vision worker exited with status " +
                                      std::to_string(WEXITSTATUS(status));
          pid_ = -1;
          lost_locked(why, after);
        } else if (!lost_ && contracts::to_seconds(now - last_message_) >
                                  (got_message_ ? options_.silence_s : options_.startup_grace_s)) {
          lost_locked("the vision worker went silent (no frame or heartbeat in time)", after);
        }
      } else if (!lost_) {
        lost_locked("the vision worker could not be started", after);
      }
      if (pid_ <= 0 && lost_ && now >= restart_at_ && running_) {
        restarts_++;
        lost_ = false;
        spawn_locked();
        if (pid_ <= 0) lost_locked("the vision worker could not be started", after);
      }
    }
    for (auto& f : after) f();
    std::this_thread::sleep_for(contracts::from_seconds(options_.poll_s));
  }
}

void WorkerSupervisor::on_connected() {
  std::lock_guard lock(mutex_);
  last_message_ = clock_.now();
}

void WorkerSupervisor::on_message() {
  bool first = false;
  {
    std::lock_guard lock(mutex_);
    last_message_ = clock_.now();
    if (!got_message_ && !lost_) {
      got_message_ = true;
      first = true;
    }
  }
  if (first && on_ready_) on_ready_();
}

void WorkerSupervisor::on_disconnected() {
  std::vector<std::function<void()>> after;
  {
    std::lock_guard lock(mutex_);
    if (!running_ || lost_) return;
    lost_locked("the vision worker's connection closed", after);
  }
  for (auto& f : after) f();
}

std::optional<pid_t> WorkerSupervisor::pid() const {
  std::lock_guard lock(mutex_);
  if (pid_ <= 0) return std::nullopt;
  return pid_;
}

bool WorkerSupervisor::running() const {
  std::lock_guard lock(mutex_);
  return pid_ > 0 && !lost_;
}

void WorkerSupervisor::stop() {
  const bool was = running_.exchange(false);
  if (thread_.joinable()) thread_.join();
  if (!was) return;
  pid_t pid;
  {
    std::lock_guard lock(mutex_);
    pid = pid_;
  }
  if (pid <= 0) return;
  // Waited for outside the lock: the worker's last messages and the close of its socket are
  // still taken (on_message, on_disconnected) while it exits. Holding the lock here blocked the
  // server's I/O thread, so the worker's close went unanswered until the SIGKILL, 2 s later,
  // and its last frame was handled only then.
  kill(pid, SIGTERM);
  bool reaped = false;
  for (int i = 0; i < 200 && !reaped; ++i) {
    reaped = waitpid(pid, nullptr, WNOHANG) == pid;
    if (!reaped) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  if (!reaped) {
    kill(pid, SIGKILL);
    waitpid(pid, nullptr, 0);
  }
  std::lock_guard lock(mutex_);
  pid_ = -1;
}

}  // namespace gbdcs::server
