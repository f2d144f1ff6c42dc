// TelemetryManager: the subject every TelemetryFrame passes through, fanned out to observers
// (FailsafeMonitor, the WebSocket gateway, StorageManager) so that no observer can block
// another, nor the drone adapter that publishes.
//
// Delivery::kInline  the observer runs on the publisher's thread, in subscription order. For
//                    observers that only note a value (the FailsafeMonitor); it must not block.
// Delivery::kQueued  the observer has its own thread and a bounded queue (capacity frames);
//                    when full the oldest frame is dropped and counted. For anything slow
//                    (storage, sockets).
// An exception thrown by an observer is caught and counted; the others still get the frame.
// latest() is the last frame published; stats() the per-observer counters.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "gbdcs/contracts/messages.hpp"

namespace gbdcs::telemetry {

class TelemetryObserver {
 public:
  virtual ~TelemetryObserver() = default;
  virtual std::string observer_name() const = 0;
  virtual void on_telemetry(const contracts::TelemetryFrame& frame) = 0;
};

// Wraps a lambda as an observer.
std::shared_ptr<TelemetryObserver> make_observer(
    std::string name, std::function<void(const contracts::TelemetryFrame&)> fn);

enum class Delivery { kInline, kQueued };

struct ObserverStats {
  std::string name;
  Delivery delivery = Delivery::kInline;
  std::uint64_t delivered = 0;
  std::uint64_t dropped = 0;
  std::uint64_t errors = 0;
  std::size_t queue_depth = 0;
};

class TelemetryManager {
 public:
  using SubscriptionId = std::uint64_t;

  TelemetryManager();
  ~TelemetryManager();
  TelemetryManager(const TelemetryManager&) = delete;
  TelemetryManager& operator=(const TelemetryManager&) = delete;

  SubscriptionId subscribe(std::shared_ptr<TelemetryObserver> observer, Delivery delivery,
                           std::size_t capacity = 64);
  void unsubscribe(SubscriptionId id);
  void publish(const contracts::TelemetryFrame& frame);
  std::optional<contracts::TelemetryFrame> latest() const;
  std::vector<ObserverStats> stats() const;
  std::uint64_t published() const;
  // Blocks until every queued observer has taken what was published before the call, or the
  // timeout passes (a stuck observer); returns false then. For shutdown and tests.
  bool drain(std::chrono::milliseconds timeout);

 private:
  struct Subscription;
  void run_queued(const std::shared_ptr<Subscription>& sub);

  mutable std::mutex mutex_;
  std::vector<std::shared_ptr<Subscription>> subscriptions_;
  std::optional<contracts::TelemetryFrame> latest_;
  std::uint64_t published_ = 0;
  SubscriptionId next_id_ = 1;
};

}  // namespace gbdcs::telemetry
