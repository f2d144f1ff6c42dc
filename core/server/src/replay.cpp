#include "replay.hpp"

#include <algorithm>

#include "gbdcs/contracts/codec.hpp"

namespace gbdcs::server {

using nlohmann::json;

namespace {
std::int64_t ms(contracts::UtcTime t) { return t.time_since_epoch().count(); }
}  // namespace

ReplayManager::ReplayManager(const contracts::Clock& clock, storage::StorageManager& storage,
                             LiveHub& hub, DroneService& drone)
    : storage_(storage), hub_(hub), drone_(drone), ids_(clock) {}

ReplayManager::~ReplayManager() { stop_all(); }

void ReplayManager::stop_all() {
  stopping_ = true;
  std::vector<std::thread> threads;
  {
    std::lock_guard lock(mutex_);
    threads.swap(threads_);
  }
  for (auto& t : threads) {
    if (t.joinable()) t.join();
  }
}

std::optional<ReplayInfo> ReplayManager::start(std::int64_t session_id, double speed) {
  std::vector<Item> items;
  for (const auto& g : storage_.gestures(session_id))
    items.push_back({ms(g.timestamp), "gesture", contracts::to_json(g)});
  for (const auto& c : storage_.commands(session_id))
    items.push_back({ms(c.recorded_at), "command",
                     {{"command", contracts::to_json(c.command)}, {"outcome", c.result}}});
  for (const auto& t : storage_.telemetry(session_id))
    items.push_back({ms(t.timestamp), "telemetry", contracts::to_json(t)});
  for (const auto& a : storage_.alerts(session_id))
    items.push_back({ms(a.alert.timestamp), "alert", contracts::to_json(a.alert)});
  std::stable_sort(items.begin(), items.end(),
                   [](const Item& a, const Item& b) { return a.ts_ms < b.ts_ms; });

  ReplayInfo info;
  info.replay_id = ids_.next();
  info.session_id = session_id;
  info.speed = speed;
  info.messages = items.size();
  if (!items.empty())
    info.duration_s = static_cast<double>(items.back().ts_ms - items.front().ts_ms) / 1000.0 / speed;

  auto active = std::make_shared<std::atomic<bool>>(true);
  std::lock_guard lock(mutex_);
  if (auto it = running_.find(session_id); it != running_.end() && it->second->load())
    return std::nullopt;
  running_[session_id] = active;
  threads_.emplace_back([this, items = std::move(items), info, active] {
    auto finish_state = [&](bool finished) {
      auto s = drone_.state();
      s["replay"] = {{"replay_id", info.replay_id}, {"session_id", info.session_id},
                     {"finished", finished}};
      hub_.broadcast("state", s, true);
    };
    finish_state(false);
    for (std::size_t i = 0; i < items.size() && !stopping_; ++i) {
      if (i > 0) {
        // Paced by the recorded gaps; a long pause is capped so a replay never stalls.
        const double gap_s =
            std::min(5.0, static_cast<double>(items[i].ts_ms - items[i - 1].ts_ms) / 1000.0) /
            info.speed;
        if (gap_s > 0) std::this_thread::sleep_for(contracts::from_seconds(gap_s));
      }
      hub_.broadcast(items[i].type, items[i].data, true);
    }
    finish_state(true);
    *active = false;
  });
  return info;
}

}  // namespace gbdcs::server
