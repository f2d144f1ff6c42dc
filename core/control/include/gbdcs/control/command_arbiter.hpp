// CommandArbiter: decides which command reaches the drone, and when.
//
// Input : DroneCommands from gestures, keyboard, API, failsafes, scenarios (submit()).
// Output: the next command to dispatch (next()), highest priority first, FIFO within one.
// Priority: EMERGENCY_STOP (any source) > failsafe > operator input (gesture, keyboard, api,
//   scenario). A higher-priority command drops every pending lower-priority one.
// Safety rules:
//   - TAKEOFF is refused until vision reports healthy AND the adapter is READY AND no
//     take-off inhibit is set (e.g. battery critical); checked at submit and again at next().
//   - EMERGENCY_STOP latches: every later command is refused until reset_emergency().
//   - MOVE without a payload is refused.
// Options: max_pending (default 32): when full, the oldest operator command is dropped.
// Thread-safe.
#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <optional>
#include <set>
#include <string>

#include "gbdcs/contracts/clock.hpp"
#include "gbdcs/contracts/messages.hpp"

namespace gbdcs::control {

enum class Priority { kOperator = 0, kFailsafe = 1, kEmergency = 2 };
Priority priority_of(const contracts::DroneCommand& command);

struct Decision {
  bool accepted = false;
  std::string reason;          // why it was refused (empty when accepted)
  std::size_t dropped = 0;     // lower-priority pending commands this one displaced
  contracts::DroneCommand command;  // with id and issued_at filled in
};

struct ArbiterOptions {
  std::size_t max_pending = 32;
};

class CommandArbiter {
 public:
  using RefusalHandler = std::function<void(const contracts::DroneCommand&, const std::string&)>;

  explicit CommandArbiter(const contracts::Clock& clock, ArbiterOptions options = {});

  Decision submit(contracts::DroneCommand command);
  std::optional<contracts::DroneCommand> next();
  std::size_t pending() const;

  void set_vision_healthy(bool healthy);
  void set_adapter_state(contracts::FlightState state);
  void set_takeoff_inhibit(const std::string& reason);
  void clear_takeoff_inhibit(const std::string& reason);
  bool emergency_latched() const;
  void reset_emergency();
  // Called for commands dropped or refused after they were accepted (pre-empted, or a
  // TAKEOFF whose conditions no longer hold at dispatch time).
  void set_refusal_handler(RefusalHandler handler);

 private:
  std::optional<std::string> takeoff_blocker_locked() const;

  const contracts::Clock& clock_;
  ArbiterOptions options_;
  mutable std::mutex mutex_;
  std::deque<contracts::DroneCommand> pending_;
  std::int64_t next_id_ = 1;
  bool vision_healthy_ = false;
  contracts::FlightState adapter_state_ = contracts::FlightState::kInit;
  std::set<std::string> takeoff_inhibits_;
  bool emergency_latched_ = false;
  RefusalHandler on_refused_;
};

}  // namespace gbdcs::control
