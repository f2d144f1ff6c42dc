#include "gbdcs/runtime/control_loop.hpp"

namespace gbdcs::runtime {

using contracts::CommandSource;
using contracts::CommandType;

ControlLoop::ControlLoop(const contracts::Clock& clock, control::DroneAdapter& adapter,
                         gesture::GestureEngine& engine, control::CommandTranslator& translator,
                         ControlLoopOptions options)
    : clock_(clock),
      adapter_(adapter),
      engine_(engine),
      translator_(translator),
      options_(options),
      arbiter_(clock, options.arbiter),
      failsafe_(clock,
                telemetry::FailsafeSinks{
                    [this](const contracts::DroneCommand& c) {
                      auto d = arbiter_.submit(c);
                      if (!d.accepted) emit_command(d.command, "REFUSED: " + d.reason);
                    },
                    [this](const contracts::Alert& a) { emit_alert(a); },
                    [this](const std::string& reason, bool active) {
                      if (active) {
                        arbiter_.set_takeoff_inhibit(reason);
                      } else {
                        arbiter_.clear_takeoff_inhibit(reason);
                      }
                    }},
                options.failsafe) {
  arbiter_.set_refusal_handler([this](const contracts::DroneCommand& c, const std::string& why) {
    emit_command(c, (why.rfind("dropped", 0) == 0 ? "DROPPED: " : "REFUSED: ") + why);
  });
  // The failsafe sees every frame first and inline: it only records values.
  telemetry_.subscribe(telemetry::make_observer("failsafe",
                                                [this](const contracts::TelemetryFrame& f) {
                                                  arbiter_.set_adapter_state(f.flight_state);
                                                  failsafe_.on_telemetry(f);
                                                }),
                       telemetry::Delivery::kInline);
  adapter_.set_telemetry_sink(
      [this](const contracts::TelemetryFrame& f) { telemetry_.publish(f); });
}

ControlLoop::~ControlLoop() { adapter_.set_telemetry_sink(nullptr); }

void ControlLoop::add_listener(std::shared_ptr<EventListener> listener) {
  {
    std::lock_guard lock(mutex_);
    listeners_.push_back(listener);
  }
  telemetry_.subscribe(
      telemetry::make_observer("listener",
                               [listener](const contracts::TelemetryFrame& f) {
                                 listener->on_telemetry(f);
                               }),
      telemetry::Delivery::kQueued, 256);
}

std::vector<std::shared_ptr<EventListener>> ControlLoop::listeners() const {
  std::lock_guard lock(mutex_);
  return listeners_;
}

control::Result ControlLoop::start() {
  const auto result = adapter_.connect();
  arbiter_.set_adapter_state(adapter_.state());
  if (result == control::Result::kOk) failsafe_.start();
  return result;
}

void ControlLoop::stop() {
  failsafe_.stop();
  std::lock_guard lock(dispatch_mutex_);
  adapter_.disconnect();
}

void ControlLoop::update_vision_locked(bool healthy, const std::string& reason) {
  // Caller holds mutex_; the failsafe is told outside it by the callers below.
  vision_ready_ = healthy;
  pipeline_reason_ = reason;
}

void ControlLoop::on_frame(const std::optional<contracts::Landmarks>& hand,
                           std::int64_t frame_id) {
  bool became_ready = false;
  {
    std::lock_guard lock(mutex_);
    last_frame_ = clock_.now();
    if (!vision_ready_ && pipeline_healthy_) {
      update_vision_locked(true, {});
      became_ready = true;
    }
  }
  if (became_ready) {
    arbiter_.set_vision_healthy(true);
    failsafe_.on_vision_health(true, {});
  }
  auto event = engine_.process(hand, frame_id);
  if (!event) return;
  failsafe_.note_operator_input();
  for (const auto& l : listeners()) l->on_gesture(*event);
  if (auto command = translator_.translate(*event)) {
    auto decision = arbiter_.submit(*command);
    if (!decision.accepted) emit_command(decision.command, "REFUSED: " + decision.reason);
  }
}

void ControlLoop::on_vision_health(bool healthy, const std::string& reason) {
  bool ready = false;
  {
    std::lock_guard lock(mutex_);
    pipeline_healthy_ = healthy;
    ready = healthy && last_frame_.has_value();
    update_vision_locked(ready, reason);
  }
  arbiter_.set_vision_healthy(ready);
  failsafe_.on_vision_health(healthy, reason);
  if (!healthy) engine_.reset();
  dispatch_pending();
}

control::Decision ControlLoop::submit(contracts::DroneCommand command) {
  if (command.source != CommandSource::kFailsafe) failsafe_.note_operator_input();
  arbiter_.set_adapter_state(adapter_.state());
  auto decision = arbiter_.submit(std::move(command));
  if (!decision.accepted) emit_command(decision.command, "REFUSED: " + decision.reason);
  return decision;
}

control::Decision ControlLoop::emergency_stop(CommandSource source, const std::string& source_id) {
  contracts::DroneCommand command;
  command.type = CommandType::kEmergencyStop;
  command.source = source;
  command.source_id = source_id;
  auto decision = arbiter_.submit(command);
  dispatch_pending();  // at once, not at the next tick
  return decision;
}

void ControlLoop::reset_emergency() { arbiter_.reset_emergency(); }

void ControlLoop::tick() {
  adapter_.poll();
  arbiter_.set_adapter_state(adapter_.state());
  bool went_stale = false;
  std::string why;
  {
    std::lock_guard lock(mutex_);
    if (vision_ready_ && last_frame_ &&
        contracts::to_seconds(clock_.now() - *last_frame_) > options_.vision_stale_s) {
      why = "no camera frame for more than " +
            std::to_string(static_cast<int>(options_.vision_stale_s * 1000)) + " ms";
      update_vision_locked(false, why);
      went_stale = true;
    }
  }
  if (went_stale) {
    arbiter_.set_vision_healthy(false);
    failsafe_.on_vision_health(false, why);
    engine_.reset();
  }
  failsafe_.tick();
  dispatch_pending();
}

void ControlLoop::dispatch_pending() {
  std::lock_guard lock(dispatch_mutex_);
  while (auto command = arbiter_.next()) {
    const auto result = control::execute(adapter_, *command);
    std::string outcome(control::to_string(result));
    if (result != control::Result::kOk) {
      const auto detail = adapter_.last_error();
      if (!detail.empty()) outcome += ": " + detail;
    }
    emit_command(*command, outcome);
    arbiter_.set_adapter_state(adapter_.state());
  }
}

void ControlLoop::emit_command(const contracts::DroneCommand& command, const std::string& outcome) {
  for (const auto& l : listeners()) l->on_command(command, outcome);
}

void ControlLoop::emit_alert(const contracts::Alert& alert) {
  auto a = alert;
  if (a.id == 0) a.id = alert_ids_++;
  for (const auto& l : listeners()) l->on_alert(a);
}

std::optional<contracts::TelemetryFrame> ControlLoop::latest_telemetry() const {
  return telemetry_.latest();
}

bool ControlLoop::vision_ready() const {
  std::lock_guard lock(mutex_);
  return vision_ready_;
}

}  // namespace gbdcs::runtime
