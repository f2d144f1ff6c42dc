// LiveHub: fan-out of /ws/live messages to every connected client, each with its own bounded
// queue, so a slow client never slows the others or the control loop.
//
//   ClientQueue  the per-client policy (plain logic, unit-tested): capacity `soft_limit`
//                (256); when full, drop the oldest frame (picture, frame or drone_view), else the oldest telemetry, else the
//                oldest other droppable message (gesture, command, state). Alerts, ack_result
//                and error are never dropped; past `hard_limit` (1024) of those the client is
//                too slow to be safe and is disconnected.
//   LiveHub      broadcast(type, data, replay): encodes {type, ts, replay?, data} once and
//                offers it to every client; close_token(jti) / close_expired(now) end
//                sockets on logout and expiry.
#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "gbdcs/contracts/clock.hpp"

namespace gbdcs::server {

enum class MessageClass { kFrame = 0, kTelemetry = 1, kOther = 2, kNeverDrop = 3 };
MessageClass class_of(std::string_view type);

struct OutMessage {
  MessageClass cls = MessageClass::kOther;
  std::string text;
  contracts::Duration enqueued{};  // clock time when broadcast (for delivery latency)
};
using OutMessagePtr = std::shared_ptr<const OutMessage>;

class ClientQueue {
 public:
  explicit ClientQueue(std::size_t soft_limit = 256, std::size_t hard_limit = 1024)
      : soft_(soft_limit), hard_(hard_limit) {}
  // false: the client must be disconnected (too many undroppable messages pending).
  bool push(OutMessagePtr message);
  std::optional<OutMessagePtr> pop();
  std::size_t size() const { return items_.size(); }
  std::uint64_t dropped() const { return dropped_; }

 private:
  std::size_t soft_;
  std::size_t hard_;
  std::deque<OutMessagePtr> items_;
  std::uint64_t dropped_ = 0;
};

class LiveClient {
 public:
  virtual ~LiveClient() = default;
  virtual void deliver(const OutMessagePtr& message) = 0;
  // Close with a WebSocket close code (4001 logout/expired).
  virtual void close_with(int code, const std::string& reason) = 0;
  virtual const std::string& token_id() const = 0;
  virtual contracts::UtcTime token_expires() const = 0;
  virtual std::uint64_t dropped() const = 0;
  virtual std::size_t queued() const = 0;
};

class LiveHub {
 public:
  explicit LiveHub(const contracts::Clock& clock) : clock_(clock) {}
  void add(const std::shared_ptr<LiveClient>& client);
  void remove(const LiveClient* client);
  // {type, ts, replay?, data} to every client.
  void broadcast(const std::string& type, const nlohmann::json& data, bool replay = false);
  // The same envelope for one client (state on connect, ack_result, error).
  OutMessagePtr make(const std::string& type, const nlohmann::json& data,
                     bool replay = false) const;
  void close_token(const std::string& jti, const std::string& reason);
  void close_expired();
  std::size_t client_count() const;
  std::uint64_t dropped_total() const;
  std::size_t queued_total() const;
  std::uint64_t broadcast_total() const;

 private:
  std::vector<std::shared_ptr<LiveClient>> snapshot() const;
  const contracts::Clock& clock_;
  mutable std::mutex mutex_;
  std::vector<std::weak_ptr<LiveClient>> clients_;
  std::uint64_t broadcasts_ = 0;
  std::uint64_t dropped_of_gone_ = 0;
};

}  // namespace gbdcs::server
