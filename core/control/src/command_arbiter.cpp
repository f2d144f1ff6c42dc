#include "gbdcs/control/command_arbiter.hpp"

#include <algorithm>

namespace gbdcs::control {

using contracts::CommandSource;
using contracts::CommandType;
using contracts::DroneCommand;

Priority priority_of(const DroneCommand& command) {
  if (command.type == CommandType::kEmergencyStop) return Priority::kEmergency;
  if (command.source == CommandSource::kFailsafe) return Priority::kFailsafe;
  return Priority::kOperator;
}

CommandArbiter::CommandArbiter(const contracts::Clock& clock, ArbiterOptions options)
    : clock_(clock), options_(options) {
  if (options_.max_pending == 0) options_.max_pending = 1;
}

std::optional<std::string> CommandArbiter::takeoff_blocker_locked() const {
  if (!vision_healthy_) {
    return "take-off refused: vision is not ready (wait until the camera shows a tracked "
           "hand and the vision health indicator is green)";
  }
  if (adapter_state_ != contracts::FlightState::kReady) {
    return "take-off refused: the drone is " + std::string(contracts::to_string(adapter_state_)) +
           ", not READY (connect the drone and wait for READY)";
  }
  if (!takeoff_inhibits_.empty()) {
    return "take-off refused: " + *takeoff_inhibits_.begin();
  }
  return std::nullopt;
}

Decision CommandArbiter::submit(DroneCommand command) {
  std::vector<std::pair<DroneCommand, std::string>> displaced;
  Decision decision;
  RefusalHandler handler;
  {
    std::lock_guard lock(mutex_);
    handler = on_refused_;
    if (command.id == 0) command.id = next_id_++;
    if (command.issued_at == contracts::UtcTime{}) command.issued_at = clock_.utc_now();
    decision.command = command;
    const auto priority = priority_of(command);

    if (priority == Priority::kEmergency) {
      emergency_latched_ = true;
    } else if (emergency_latched_) {
      decision.reason =
          "refused: emergency stop is latched (reset it from the dashboard or POST "
          "/api/v1/control/reset once the drone is safe)";
      return decision;
    }
    if (command.type == CommandType::kMove && !command.payload) {
      decision.reason = "refused: MOVE needs a payload (vx_m_s, vy_m_s, vz_m_s, yaw_rate_deg_s)";
      return decision;
    }
    if (command.type == CommandType::kTakeoff) {
      if (auto blocker = takeoff_blocker_locked()) {
        decision.reason = *blocker;
        return decision;
      }
    }
    // A higher-priority command drops every pending lower-priority one.
    auto lower = [&](const DroneCommand& c) { return priority_of(c) < priority; };
    for (const auto& c : pending_) {
      if (lower(c)) displaced.emplace_back(c, "dropped: pre-empted by " +
                                                  std::string(contracts::to_string(command.type)) +
                                                  " from " +
                                                  std::string(contracts::to_string(command.source)));
    }
    std::erase_if(pending_, lower);
    decision.dropped = displaced.size();

    if (pending_.size() >= options_.max_pending) {
      auto oldest = std::find_if(pending_.begin(), pending_.end(), [](const DroneCommand& c) {
        return priority_of(c) == Priority::kOperator;
      });
      if (oldest == pending_.end()) {
        decision.reason = "refused: command queue is full of safety commands";
        return decision;
      }
      displaced.emplace_back(*oldest, "dropped: command queue full, oldest operator command");
      pending_.erase(oldest);
    }
    // Keep the queue ordered by priority, FIFO within a priority.
    auto pos = std::find_if(pending_.begin(), pending_.end(), [&](const DroneCommand& c) {
      return priority_of(c) < priority;
    });
    pending_.insert(pos, command);
    decision.accepted = true;
  }
  if (handler) {
    for (const auto& [c, why] : displaced) handler(c, why);
  }
  return decision;
}

std::optional<DroneCommand> CommandArbiter::next() {
  std::vector<std::pair<DroneCommand, std::string>> refused;
  std::optional<DroneCommand> out;
  RefusalHandler handler;
  {
    std::lock_guard lock(mutex_);
    handler = on_refused_;
    while (!pending_.empty()) {
      auto command = pending_.front();
      pending_.pop_front();
      if (emergency_latched_ && priority_of(command) != Priority::kEmergency) {
        refused.emplace_back(command, "dropped: emergency stop is latched");
        continue;
      }
      if (command.type == CommandType::kTakeoff) {
        if (auto blocker = takeoff_blocker_locked()) {
          refused.emplace_back(command, *blocker);
          continue;
        }
      }
      out = command;
      break;
    }
  }
  if (handler) {
    for (const auto& [c, why] : refused) handler(c, why);
  }
  return out;
}

std::size_t CommandArbiter::pending() const {
  std::lock_guard lock(mutex_);
  return pending_.size();
}

void CommandArbiter::set_vision_healthy(bool healthy) {
  std::lock_guard lock(mutex_);
  vision_healthy_ = healthy;
}

void CommandArbiter::set_adapter_state(contracts::FlightState state) {
  std::lock_guard lock(mutex_);
  adapter_state_ = state;
}

void CommandArbiter::set_takeoff_inhibit(const std::string& reason) {
  std::lock_guard lock(mutex_);
  takeoff_inhibits_.insert(reason);
}

void CommandArbiter::clear_takeoff_inhibit(const std::string& reason) {
  std::lock_guard lock(mutex_);
  takeoff_inhibits_.erase(reason);
}

bool CommandArbiter::emergency_latched() const {
  std::lock_guard lock(mutex_);
  return emergency_latched_;
}

void CommandArbiter::reset_emergency() {
  std::lock_guard lock(mutex_);
  emergency_latched_ = false;
}

void CommandArbiter::set_refusal_handler(RefusalHandler handler) {
  std::lock_guard lock(mutex_);
  on_refused_ = std::move(handler);
}

}  // namespace gbdcs::control
