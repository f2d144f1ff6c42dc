#include "gbdcs/control/keyboard_input.hpp"

#include <cctype>
#include <string>

namespace gbdcs::control {

using contracts::CommandType;

std::optional<contracts::DroneCommand> KeyboardInput::command_for(std::string_view key) const {
  std::string k(key);
  if (k.size() == 1) k[0] = static_cast<char>(std::tolower(static_cast<unsigned char>(k[0])));
  contracts::DroneCommand command;
  command.source = contracts::CommandSource::kKeyboard;
  command.source_id = k == " " ? "Space" : k;
  contracts::MotionPayload motion;
  motion.duration_s = options_.hold_s;
  if (k == "w" || k == "ArrowUp") {
    motion.vx_m_s = options_.horizontal_m_s;
  } else if (k == "s" || k == "ArrowDown") {
    motion.vx_m_s = -options_.horizontal_m_s;
  } else if (k == "a" || k == "ArrowLeft") {
    motion.vy_m_s = -options_.horizontal_m_s;
  } else if (k == "d" || k == "ArrowRight") {
    motion.vy_m_s = options_.horizontal_m_s;
  } else if (k == "q") {
    motion.yaw_rate_deg_s = -options_.yaw_rate_deg_s;
  } else if (k == "e") {
    motion.yaw_rate_deg_s = options_.yaw_rate_deg_s;
  } else if (k == "r") {
    motion.vz_m_s = options_.vertical_m_s;
  } else if (k == "f") {
    motion.vz_m_s = -options_.vertical_m_s;
  } else if (k == "t") {
    command.type = CommandType::kTakeoff;
    return command;
  } else if (k == "l") {
    command.type = CommandType::kLand;
    return command;
  } else if (k == "h") {
    command.type = CommandType::kHover;
    return command;
  } else if (k == " " || k == "Space" || k == "space") {
    command.type = CommandType::kEmergencyStop;
    command.source_id = "Space";
    return command;
  } else {
    return std::nullopt;
  }
  command.type = CommandType::kMove;
  command.payload = motion;
  return command;
}

}  // namespace gbdcs::control
