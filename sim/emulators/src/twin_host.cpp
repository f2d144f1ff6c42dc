#include "gbdcs/sim/twin_host.hpp"

#include <algorithm>
#include <stdexcept>

namespace gbdcs::sim {

TwinHost::TwinHost(const contracts::Clock& clock, std::shared_ptr<const TwinModel> model,
                   TwinHostOptions options)
    : clock_(clock), options_(std::move(options)) {
  if (!model) throw std::invalid_argument("TwinHost: no model");
  if (!(options_.step_s > 0) || !(options_.realtime_step_hz > 0)) {
    throw std::invalid_argument("TwinHost: step_s and realtime_step_hz must be positive");
  }
  origin_ = clock_.now();
  sim_ = std::make_unique<TwinSim>(std::move(model), options_.twin, options_.seed);
}

TwinHost::~TwinHost() { stop(); }

double TwinHost::clock_sim_s() const { return contracts::to_seconds(clock_.now() - origin_); }

double TwinHost::sim_time_s() const {
  auto& self = const_cast<TwinHost&>(*this);
  std::lock_guard lock(self.mutex_);
  return sim_->time_s();
}

int TwinHost::add_listener(Listener listener) {
  std::lock_guard lock(mutex_);
  listeners_[next_listener_] = std::move(listener);
  return next_listener_++;
}

void TwinHost::remove_listener(int id) {
  std::lock_guard lock(mutex_);
  listeners_.erase(id);
}

void TwinHost::advance_locked(double t_s) {
  // By targets, not by sim_->time_s(): the twin steps in whole 2 ms steps, so its time can
  // stay a fraction of a step short of a target that is not a multiple of one.
  while (advanced_to_s_ < t_s) {
    const double next = std::min(t_s, advanced_to_s_ + options_.step_s);
    sim_->step_to(next);
    advanced_to_s_ = next;
    for (auto& [id, listener] : listeners_) listener(*sim_, sim_->time_s());
  }
}

void TwinHost::poll() {
  std::lock_guard lock(mutex_);
  advance_locked(clock_sim_s());
}

void TwinHost::start() {
  if (thread_.joinable()) return;
  {
    std::lock_guard tl(thread_mutex_);
    thread_stop_ = false;
  }
  thread_ = std::thread([this] {
    const auto period = std::chrono::duration_cast<std::chrono::nanoseconds>(
        std::chrono::duration<double>(1.0 / options_.realtime_step_hz));
    std::unique_lock tl(thread_mutex_);
    while (!thread_stop_) {
      tl.unlock();
      poll();
      tl.lock();
      thread_cv_.wait_for(tl, period, [this] { return thread_stop_; });
    }
  });
}

void TwinHost::stop() {
  {
    std::lock_guard tl(thread_mutex_);
    thread_stop_ = true;
  }
  thread_cv_.notify_all();
  if (thread_.joinable()) thread_.join();
}

}  // namespace gbdcs::sim
