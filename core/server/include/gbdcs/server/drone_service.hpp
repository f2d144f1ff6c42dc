// DroneService: the operator's drone behind the server. Owns the adapter and the core wiring
// (runtime::ControlLoop, exactly as `gbdcs fly` uses it), one control session per connected
// drone, and records every gesture, command (with outcome), telemetry frame and alert in
// SQLite while broadcasting it on /ws/live and logging commands and alerts.
//
// Inputs : connect(name, options)  (re)connect: the old drone is landed if flying and
//                                   disconnected first, its session ended
//          on_vision_frame(msg)     a vision_frame message from the worker
//          on_vision_health(ok, why), raise_alert(alert)
//          emergency_stop / reset_emergency / key(key, pressed) / submit(command)
// Outputs: hub messages gesture, command, alert, telemetry, state (every 1 s and on change),
//          drone_view (the adapter's picture, e.g. the twin's chase camera, at options.view.fps
//          while a client is connected);
//          the log callback gets one JSON object per command and safety event.
//          Storage: when SQLite writes start failing (disk full, ...) the tick thread raises
//          STORAGE_WRITE_FAILING (WARNING, cause and fix from storage::WriteHealth) and logs
//          it, repeats the log every 10 s while it lasts, and raises STORAGE_RECOVERED (INFO)
//          when writes succeed again. Flying is not affected.
// Time   : the injected Clock; a tick thread calls ControlLoop::tick every tick_s.
#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <shared_mutex>
#include <string>
#include <thread>

#include "gbdcs/contracts/clock.hpp"
#include "gbdcs/control/command_translator.hpp"
#include "gbdcs/control/drone_adapter.hpp"
#include "gbdcs/control/drone_view.hpp"
#include "gbdcs/runtime/control_loop.hpp"
#include "gbdcs/server/live_hub.hpp"
#include "gbdcs/storage/storage_manager.hpp"

namespace gbdcs::server {

using DroneFactory = std::function<std::unique_ptr<control::DroneAdapter>(
    const std::string& name, const nlohmann::json& options)>;
using EventLog = std::function<void(const std::string& level, const nlohmann::json& event)>;

struct DroneServiceOptions {
  double tick_s = 0.02;
  double state_every_s = 1.0;
  runtime::ControlLoopOptions loop;
  // The drone's own picture (control::DroneViewSource) as drone_view messages; fps 0: off.
  control::ViewOptions view;
};

struct VisionStatus {
  bool worker_running = false;
  std::int64_t worker_restarts = 0;
  double fps = 0;
  std::string source;
};

class DroneService {
 public:
  DroneService(const contracts::Clock& clock, storage::StorageManager& storage, LiveHub& hub,
               DroneFactory factory, control::GestureProfile profile, EventLog log,
               DroneServiceOptions options = {});
  ~DroneService();

  // "" when connected; otherwise the error (the service then runs without a drone).
  std::string connect(const std::string& name, const nlohmann::json& options);
  // Whether `options` make a `name` drone, asked before connect() lets the current one go: ""
  // when they do (or when only the swap can tell: the adapter could not be made for another
  // reason, such as sockets the connected drone holds), else why not (an unknown adapter, an
  // unknown or bad option). Makes an adapter and drops it; connects nothing.
  std::string check_adapter(const std::string& name, const nlohmann::json& options) const;
  void disconnect();

  void on_vision_frame(const nlohmann::json& frame_message);
  void on_vision_health(bool healthy, const std::string& reason);
  void raise_alert(contracts::Alert alert);
  control::Decision emergency_stop(contracts::CommandSource source, const std::string& source_id);
  void reset_emergency();
  bool emergency_latched() const;
  // Keyboard flying; returns what happened ("" when the key means nothing).
  std::string key(const std::string& key, bool pressed);
  std::optional<control::Decision> submit(contracts::DroneCommand command);

  nlohmann::json state() const;
  void set_vision_status(const VisionStatus& status);
  control::GestureProfile profile() const;
  void set_profile(control::GestureProfile profile);
  std::string adapter_name() const;
  nlohmann::json adapter_options() const;
  std::optional<std::int64_t> session_id() const;
  bool connected() const;
  // Extra observers (tests, metrics); they see what the hub sees.
  void add_listener(std::shared_ptr<runtime::EventListener> listener);
  void publish_state();

 private:
  struct Active;
  void tick_loop();
  void watch_storage();  // on the tick thread, outside every lock
  void stop_active_locked();
  void end_session_quietly(std::int64_t session);  // never throws

  const contracts::Clock& clock_;
  storage::StorageManager& storage_;
  LiveHub& hub_;
  DroneFactory factory_;
  EventLog log_;
  DroneServiceOptions options_;

  mutable std::shared_mutex active_mutex_;  // exclusive: connect/disconnect/profile
  std::unique_ptr<Active> active_;
  control::GestureProfile profile_;
  std::string adapter_name_;
  nlohmann::json adapter_options_ = nlohmann::json::object();

  mutable std::mutex status_mutex_;
  VisionStatus vision_status_;
  bool vision_healthy_ = true;
  std::string vision_reason_;
  std::vector<std::shared_ptr<runtime::EventListener>> extra_listeners_;
  std::string last_state_;

  std::int64_t storage_episodes_seen_ = 0;  // tick thread only
  bool storage_failing_ = false;
  contracts::Duration storage_next_log_{};
  std::atomic<bool> running_{true};
  std::thread ticker_;
};

}  // namespace gbdcs::server
