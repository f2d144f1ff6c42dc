// ControlLoop: the production core wired once, exactly as `gbdcs serve`, `gbdcs fly` and the
// scenario runner use it. Pure wiring; the logic lives in the classes it holds.
//
//   vision frame -> GestureEngine -> CommandTranslator -> CommandArbiter -> DroneAdapter
//   DroneAdapter telemetry -> TelemetryManager -> FailsafeMonitor (inline), listeners (queued)
//   FailsafeMonitor -> commands into the arbiter, alerts and inhibits
//
// Inputs : on_frame(hand?, frame_id)  each processed camera frame (nullopt = no hand)
//          on_vision_health(ok, why)  the vision pipeline's own verdict
//          submit(command)            operator input (keyboard, API, scenario)
//          emergency_stop(source_id)  dispatched at once, ahead of everything
//          tick()                     poll the adapter, run the failsafe timers, dispatch
// Outputs: every gesture event, command (with its outcome), alert and telemetry frame goes
//          to the EventListeners (storage, WebSocket, console), so all are logged.
// Options: vision_stale_s (0.5): no frame for this long makes vision unhealthy.
// Time   : the injected Clock only.
#pragma once

#include <atomic>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "gbdcs/contracts/clock.hpp"
#include "gbdcs/contracts/messages.hpp"
#include "gbdcs/control/command_arbiter.hpp"
#include "gbdcs/control/command_translator.hpp"
#include "gbdcs/control/drone_adapter.hpp"
#include "gbdcs/gesture/gesture_engine.hpp"
#include "gbdcs/telemetry/failsafe_monitor.hpp"
#include "gbdcs/telemetry/telemetry_manager.hpp"

namespace gbdcs::runtime {

// What happened to a command: "OK", an adapter result ("REJECTED: ..."), "REFUSED: why"
// (never accepted by the arbiter) or "DROPPED: why" (accepted, then pre-empted).
class EventListener {
 public:
  virtual ~EventListener() = default;
  virtual void on_gesture(const contracts::GestureEvent&) {}
  virtual void on_command(const contracts::DroneCommand&, const std::string& /*outcome*/) {}
  virtual void on_alert(const contracts::Alert&) {}
  virtual void on_telemetry(const contracts::TelemetryFrame&) {}
};

struct ControlLoopOptions {
  double vision_stale_s = 0.5;
  telemetry::FailsafeOptions failsafe;
  control::ArbiterOptions arbiter;
};

class ControlLoop {
 public:
  ControlLoop(const contracts::Clock& clock, control::DroneAdapter& adapter,
              gesture::GestureEngine& engine, control::CommandTranslator& translator,
              ControlLoopOptions options = {});
  ~ControlLoop();

  // Listeners get telemetry on their own queue (never blocking the adapter) and the rest
  // synchronously; add them before start().
  void add_listener(std::shared_ptr<EventListener> listener);

  control::Result start();  // connects the adapter and arms the failsafes
  void stop();              // disconnects (the caller lands first if it wants to)

  void on_frame(const std::optional<contracts::Landmarks>& hand, std::int64_t frame_id);
  void on_vision_health(bool healthy, const std::string& reason);
  control::Decision submit(contracts::DroneCommand command);
  control::Decision emergency_stop(contracts::CommandSource source, const std::string& source_id);
  void reset_emergency();
  void tick();

  std::optional<contracts::TelemetryFrame> latest_telemetry() const;
  bool vision_ready() const;
  telemetry::TelemetryManager& telemetry() { return telemetry_; }
  telemetry::FailsafeMonitor& failsafe() { return failsafe_; }
  control::CommandArbiter& arbiter() { return arbiter_; }

 private:
  void dispatch_pending();
  void emit_command(const contracts::DroneCommand& command, const std::string& outcome);
  void emit_alert(const contracts::Alert& alert);
  void update_vision_locked(bool healthy, const std::string& reason);
  std::vector<std::shared_ptr<EventListener>> listeners() const;

  const contracts::Clock& clock_;
  control::DroneAdapter& adapter_;
  gesture::GestureEngine& engine_;
  control::CommandTranslator& translator_;
  ControlLoopOptions options_;
  telemetry::TelemetryManager telemetry_;
  control::CommandArbiter arbiter_;
  telemetry::FailsafeMonitor failsafe_;

  mutable std::mutex mutex_;  // listeners_, vision state
  std::vector<std::shared_ptr<EventListener>> listeners_;
  std::optional<contracts::Duration> last_frame_;
  bool pipeline_healthy_ = true;
  std::string pipeline_reason_;
  bool vision_ready_ = false;

  std::mutex dispatch_mutex_;  // one command at a time reaches the adapter
  std::atomic<std::int64_t> alert_ids_{1};
};

}  // namespace gbdcs::runtime
