// ReplayManager: streams a stored session over /ws/live at `speed` x real time, every message
// marked replay: true, in the order it was recorded; ends with a state message whose
// data.replay.finished is true. One replay per session at a time.
#pragma once

#include <atomic>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "gbdcs/server/auth.hpp"
#include "gbdcs/server/drone_service.hpp"
#include "gbdcs/server/live_hub.hpp"
#include "gbdcs/storage/storage_manager.hpp"

namespace gbdcs::server {

struct ReplayInfo {
  std::string replay_id;
  std::int64_t session_id = 0;
  double speed = 1;
  std::size_t messages = 0;
  double duration_s = 0;
};

class ReplayManager {
 public:
  ReplayManager(const contracts::Clock& clock, storage::StorageManager& storage, LiveHub& hub,
                DroneService& drone);
  ~ReplayManager();
  // nullopt: that session is already replaying. Throws storage::StorageError.
  std::optional<ReplayInfo> start(std::int64_t session_id, double speed);
  void stop_all();

 private:
  struct Item {
    std::int64_t ts_ms;
    std::string type;
    nlohmann::json data;
  };
  storage::StorageManager& storage_;
  LiveHub& hub_;
  DroneService& drone_;
  UlidGenerator ids_;
  std::mutex mutex_;
  std::map<std::int64_t, std::shared_ptr<std::atomic<bool>>> running_;  // session -> active
  std::vector<std::thread> threads_;
  std::atomic<bool> stopping_{false};
};

}  // namespace gbdcs::server
