// KeyboardInput: keys -> DroneCommands (source = keyboard), the operator's alternative to
// gestures. Same commands, same arbiter, same failsafes.
//
// Keys (names as browsers report KeyboardEvent.key, case-insensitive for letters):
//   w / ArrowUp forward, s / ArrowDown back, a / ArrowLeft left, d / ArrowRight right,
//   q yaw left, e yaw right, r up, f down, t take off, l land, h hover, " " (Space) emergency stop.
// Options: horizontal_m_s 0.5, vertical_m_s 0.3, yaw_rate_deg_s 45, hold_s 0.5 (a MOVE lasts
//   this long; key auto-repeat keeps it going, releasing stops within hold_s).
#pragma once

#include <optional>
#include <string_view>

#include "gbdcs/contracts/messages.hpp"

namespace gbdcs::control {

struct KeyboardOptions {
  double horizontal_m_s = 0.5;
  double vertical_m_s = 0.3;
  double yaw_rate_deg_s = 45;
  double hold_s = 0.5;
};

class KeyboardInput {
 public:
  explicit KeyboardInput(KeyboardOptions options = {}) : options_(options) {}
  // nullopt for a key that means nothing.
  std::optional<contracts::DroneCommand> command_for(std::string_view key) const;

 private:
  KeyboardOptions options_;
};

}  // namespace gbdcs::control
