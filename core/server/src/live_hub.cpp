#include "gbdcs/server/live_hub.hpp"

#include <algorithm>

#include "gbdcs/contracts/codec.hpp"

namespace gbdcs::server {

MessageClass class_of(std::string_view type) {
  if (type == "frame" || type == "picture" || type == "drone_view") return MessageClass::kFrame;
  if (type == "telemetry") return MessageClass::kTelemetry;
  if (type == "alert" || type == "ack_result" || type == "error") return MessageClass::kNeverDrop;
  return MessageClass::kOther;
}

bool ClientQueue::push(OutMessagePtr message) {
  items_.push_back(std::move(message));
  while (items_.size() > soft_) {
    bool removed = false;
    for (auto cls : {MessageClass::kFrame, MessageClass::kTelemetry, MessageClass::kOther}) {
      auto it = std::find_if(items_.begin(), items_.end(),
                             [cls](const OutMessagePtr& m) { return m->cls == cls; });
      if (it != items_.end()) {
        items_.erase(it);
        ++dropped_;
        removed = true;
        break;
      }
    }
    if (!removed) break;  // only undroppable messages left
  }
  return items_.size() <= hard_;
}

std::optional<OutMessagePtr> ClientQueue::pop() {
  if (items_.empty()) return std::nullopt;
  auto m = std::move(items_.front());
  items_.pop_front();
  return m;
}

void LiveHub::add(const std::shared_ptr<LiveClient>& client) {
  std::lock_guard lock(mutex_);
  clients_.push_back(client);
}

void LiveHub::remove(const LiveClient* client) {
  std::lock_guard lock(mutex_);
  std::erase_if(clients_, [&](const std::weak_ptr<LiveClient>& w) {
    auto c = w.lock();
    if (c && c.get() == client) {
      dropped_of_gone_ += c->dropped();
      return true;
    }
    return !c;
  });
}

std::vector<std::shared_ptr<LiveClient>> LiveHub::snapshot() const {
  std::lock_guard lock(mutex_);
  std::vector<std::shared_ptr<LiveClient>> out;
  for (const auto& w : clients_) {
    if (auto c = w.lock()) out.push_back(std::move(c));
  }
  return out;
}

OutMessagePtr LiveHub::make(const std::string& type, const nlohmann::json& data,
                            bool replay) const {
  nlohmann::json doc = {{"type", type}, {"ts", contracts::format_utc(clock_.utc_now())}};
  if (replay) doc["replay"] = true;
  doc["data"] = data;
  auto m = std::make_shared<OutMessage>();
  m->cls = class_of(type);
  m->text = doc.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  m->enqueued = clock_.now();
  return m;
}

void LiveHub::broadcast(const std::string& type, const nlohmann::json& data, bool replay) {
  auto clients = snapshot();
  {
    std::lock_guard lock(mutex_);
    ++broadcasts_;
  }
  if (clients.empty()) return;
  auto message = make(type, data, replay);
  for (const auto& c : clients) c->deliver(message);
}

void LiveHub::close_token(const std::string& jti, const std::string& reason) {
  for (const auto& c : snapshot()) {
    if (c->token_id() == jti) c->close_with(4001, reason);
  }
}

void LiveHub::close_expired() {
  const auto now = clock_.utc_now();
  for (const auto& c : snapshot()) {
    if (now >= c->token_expires()) c->close_with(4001, "token expired: log in again");
  }
}

std::size_t LiveHub::client_count() const { return snapshot().size(); }

std::uint64_t LiveHub::dropped_total() const {
  std::uint64_t total = 0;
  for (const auto& c : snapshot()) total += c->dropped();
  std::lock_guard lock(mutex_);
  return total + dropped_of_gone_;
}

std::size_t LiveHub::queued_total() const {
  std::size_t total = 0;
  for (const auto& c : snapshot()) total += c->queued();
  return total;
}

std::uint64_t LiveHub::broadcast_total() const {
  std::lock_guard lock(mutex_);
  return broadcasts_;
}

}  // namespace gbdcs::server
