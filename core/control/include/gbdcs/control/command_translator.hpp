// CommandTranslator: gesture events -> drone commands, by a JSON profile.
//
// Input : GestureEvent (onset or repeat) from the GestureEngine.
// Output: at most one DroneCommand (source = gesture, source_id = the gesture name).
// Profile: JSON valid against core/contracts/schemas/gesture_profile.schema.json, e.g.
//   {"name": "default", "mappings": {"THUMB_UP": {"command": "TAKEOFF"},
//     "POINT_LEFT": {"command": "MOVE", "payload": {"vy_m_s": -0.4, "duration_s": 1.0},
//                    "repeat_while_held": true}}}
//   An unknown gesture or command, a MOVE without payload, NONE mapped: ProfileError naming
//   the entry. Gestures the profile leaves out produce no command.
// Repeats: an onset always translates; a repeat (gesture still held) only for mappings with
//   repeat_while_held, so a held MOVE keeps moving and a held TAKEOFF is sent once.
#pragma once

#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "gbdcs/contracts/messages.hpp"

namespace gbdcs::control {

class ProfileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct Mapping {
  contracts::CommandType command = contracts::CommandType::kHover;
  std::optional<contracts::MotionPayload> payload;
  bool repeat_while_held = false;
};

struct GestureProfile {
  std::string name;
  std::string description;
  std::map<contracts::GestureType, Mapping> mappings;

  static GestureProfile from_json(const nlohmann::json& doc);  // throws ProfileError
  static GestureProfile from_text(std::string_view json_text);
  static GestureProfile load_file(const std::string& path);
  static GestureProfile builtin_default();  // core/control/profiles/default.json, embedded
  nlohmann::json to_json() const;
};

class CommandTranslator {
 public:
  explicit CommandTranslator(GestureProfile profile);

  std::optional<contracts::DroneCommand> translate(const contracts::GestureEvent& event) const;
  const GestureProfile& profile() const { return profile_; }
  void set_profile(GestureProfile profile) { profile_ = std::move(profile); }

 private:
  GestureProfile profile_;
};

}  // namespace gbdcs::control
