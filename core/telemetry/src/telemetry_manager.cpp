#include "gbdcs/telemetry/telemetry_manager.hpp"

namespace gbdcs::telemetry {

namespace {
class LambdaObserver final : public TelemetryObserver {
 public:
  LambdaObserver(std::string name, std::function<void(const contracts::TelemetryFrame&)> fn)
      : name_(std::move(name)), fn_(std::move(fn)) {}
  std::string observer_name() const override { return name_; }
  void on_telemetry(const contracts::TelemetryFrame& frame) override { fn_(frame); }

 private:
  std::string name_;
  std::function<void(const contracts::TelemetryFrame&)> fn_;
};
}  // namespace

std::shared_ptr<TelemetryObserver> make_observer(
    std::string name, std::function<void(const contracts::TelemetryFrame&)> fn) {
  return std::make_shared<LambdaObserver>(std::move(name), std::move(fn));
}

struct TelemetryManager::Subscription {
  SubscriptionId id = 0;
  std::shared_ptr<TelemetryObserver> observer;
  Delivery delivery = Delivery::kInline;
  std::size_t capacity = 64;

  std::mutex mutex;  // guards everything below
  std::condition_variable wake;
  std::condition_variable idle;
  std::deque<contracts::TelemetryFrame> queue;
  bool busy = false;
  bool stopping = false;
  std::uint64_t delivered = 0;
  std::uint64_t dropped = 0;
  std::uint64_t errors = 0;
  std::thread worker;
};

TelemetryManager::TelemetryManager() = default;

TelemetryManager::~TelemetryManager() {
  std::vector<std::shared_ptr<Subscription>> subs;
  {
    std::lock_guard lock(mutex_);
    subs.swap(subscriptions_);
  }
  for (auto& sub : subs) {
    {
      std::lock_guard lock(sub->mutex);
      sub->stopping = true;
    }
    sub->wake.notify_all();
    if (sub->worker.joinable()) sub->worker.join();
  }
}

TelemetryManager::SubscriptionId TelemetryManager::subscribe(
    std::shared_ptr<TelemetryObserver> observer, Delivery delivery, std::size_t capacity) {
  auto sub = std::make_shared<Subscription>();
  sub->observer = std::move(observer);
  sub->delivery = delivery;
  sub->capacity = capacity == 0 ? 1 : capacity;
  std::lock_guard lock(mutex_);
  sub->id = next_id_++;
  if (delivery == Delivery::kQueued) {
    sub->worker = std::thread([this, sub] { run_queued(sub); });
  }
  subscriptions_.push_back(sub);
  return sub->id;
}

void TelemetryManager::unsubscribe(SubscriptionId id) {
  std::shared_ptr<Subscription> sub;
  {
    std::lock_guard lock(mutex_);
    for (auto it = subscriptions_.begin(); it != subscriptions_.end(); ++it) {
      if ((*it)->id == id) {
        sub = *it;
        subscriptions_.erase(it);
        break;
      }
    }
  }
  if (!sub) return;
  {
    std::lock_guard lock(sub->mutex);
    sub->stopping = true;
  }
  sub->wake.notify_all();
  // A stuck observer cannot be joined; let it go rather than block the caller forever.
  if (sub->worker.joinable()) sub->worker.detach();
}

void TelemetryManager::run_queued(const std::shared_ptr<Subscription>& sub) {
  std::unique_lock lock(sub->mutex);
  for (;;) {
    sub->wake.wait(lock, [&] { return sub->stopping || !sub->queue.empty(); });
    if (sub->stopping) return;
    auto frame = sub->queue.front();
    sub->queue.pop_front();
    sub->busy = true;
    lock.unlock();
    bool failed = false;
    try {
      sub->observer->on_telemetry(frame);
    } catch (...) {
      failed = true;
    }
    lock.lock();
    sub->busy = false;
    ++(failed ? sub->errors : sub->delivered);
    if (sub->queue.empty()) sub->idle.notify_all();
  }
}

void TelemetryManager::publish(const contracts::TelemetryFrame& frame) {
  std::vector<std::shared_ptr<Subscription>> subs;
  {
    std::lock_guard lock(mutex_);
    latest_ = frame;
    ++published_;
    subs = subscriptions_;
  }
  for (auto& sub : subs) {
    if (sub->delivery == Delivery::kInline) {
      bool failed = false;
      try {
        sub->observer->on_telemetry(frame);
      } catch (...) {
        failed = true;
      }
      std::lock_guard lock(sub->mutex);
      ++(failed ? sub->errors : sub->delivered);
      continue;
    }
    {
      std::lock_guard lock(sub->mutex);
      if (sub->queue.size() >= sub->capacity) {
        sub->queue.pop_front();
        ++sub->dropped;
      }
      sub->queue.push_back(frame);
    }
    sub->wake.notify_one();
  }
}

std::optional<contracts::TelemetryFrame> TelemetryManager::latest() const {
  std::lock_guard lock(mutex_);
  return latest_;
}

std::uint64_t TelemetryManager::published() const {
  std::lock_guard lock(mutex_);
  return published_;
}

std::vector<ObserverStats> TelemetryManager::stats() const {
  std::vector<std::shared_ptr<Subscription>> subs;
  {
    std::lock_guard lock(mutex_);
    subs = subscriptions_;
  }
  std::vector<ObserverStats> out;
  for (auto& sub : subs) {
    std::lock_guard lock(sub->mutex);
    out.push_back({sub->observer->observer_name(), sub->delivery, sub->delivered, sub->dropped,
                   sub->errors, sub->queue.size()});
  }
  return out;
}

bool TelemetryManager::drain(std::chrono::milliseconds timeout) {
  std::vector<std::shared_ptr<Subscription>> subs;
  {
    std::lock_guard lock(mutex_);
    subs = subscriptions_;
  }
  // Waiting on a condition variable for a deadline is not a timer of the core's logic: it
  // bounds how long shutdown may hang on a stuck observer.
  bool all = true;
  for (auto& sub : subs) {
    if (sub->delivery != Delivery::kQueued) continue;
    std::unique_lock lock(sub->mutex);
    all = sub->idle.wait_for(lock, timeout, [&] { return sub->queue.empty() && !sub->busy; }) &&
          all;
  }
  return all;
}

}  // namespace gbdcs::telemetry
