#include "gbdcs/control/command_translator.hpp"

#include <fstream>
#include <sstream>

#include "gbdcs/contracts/codec.hpp"

namespace gbdcs::control {
namespace embedded {
std::vector<std::pair<std::string_view, std::string_view>> embedded_files();
}

using contracts::CommandType;
using contracts::GestureType;

GestureProfile GestureProfile::from_json(const nlohmann::json& doc) {
  // Clear messages for the two mistakes people make most, before the generic schema check.
  if (doc.is_object() && doc.contains("mappings") && doc["mappings"].is_object()) {
    for (const auto& [gesture, entry] : doc["mappings"].items()) {
      const auto g = contracts::gesture_from_string(gesture);
      if (!g) {
        throw ProfileError("profile: unknown gesture '" + gesture +
                           "' in mappings (known: OPEN_PALM, FIST, THUMB_UP, THUMB_DOWN, "
                           "POINT_LEFT, POINT_RIGHT, POINT_UP, VICTORY, I_LOVE_YOU)");
      }
      if (*g == GestureType::kNone) {
        throw ProfileError("profile: NONE cannot be mapped: it means 'no deliberate gesture' "
                           "and must never move the drone (remove the entry)");
      }
      if (entry.is_object() && entry.contains("command") && entry["command"] == "MOVE" &&
          !entry.contains("payload")) {
        throw ProfileError("profile: MOVE for " + gesture +
                           " needs a payload (vx_m_s, vy_m_s, vz_m_s, yaw_rate_deg_s, duration_s)");
      }
      if (entry.is_object() && entry.contains("command") && entry["command"].is_string() &&
          !contracts::command_type_from_string(entry["command"].get<std::string>())) {
        throw ProfileError("profile: unknown command '" + entry["command"].get<std::string>() +
                           "' for " + gesture +
                           " (known: TAKEOFF, LAND, HOVER, MOVE, EMERGENCY_STOP)");
      }
    }
  }
  try {
    contracts::validate("gesture_profile", doc);
  } catch (const contracts::ContractError& e) {
    throw ProfileError(std::string("profile: ") + e.what());
  }
  GestureProfile profile;
  profile.name = doc.at("name").get<std::string>();
  profile.description = doc.value("description", std::string{});
  for (const auto& [gesture, entry] : doc.at("mappings").items()) {
    Mapping m;
    m.command = *contracts::command_type_from_string(entry.at("command").get<std::string>());
    if (entry.contains("payload")) m.payload = contracts::motion_payload_from_json(entry["payload"]);
    m.repeat_while_held = entry.value("repeat_while_held", false);
    if (m.repeat_while_held && m.command != CommandType::kMove) {
      throw ProfileError("profile: repeat_while_held is only for MOVE (" + gesture + " maps to " +
                         std::string(contracts::to_string(m.command)) + ")");
    }
    if (m.payload && m.command != CommandType::kMove) {
      throw ProfileError("profile: only MOVE takes a payload (" + gesture + " maps to " +
                         std::string(contracts::to_string(m.command)) + ")");
    }
    profile.mappings[*contracts::gesture_from_string(gesture)] = m;
  }
  return profile;
}

GestureProfile GestureProfile::from_text(std::string_view json_text) {
  try {
    return from_json(contracts::parse_json(json_text));
  } catch (const contracts::ContractError& e) {
    throw ProfileError(std::string("profile: ") + e.what());
  }
}

GestureProfile GestureProfile::load_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) {
    throw ProfileError("profile: cannot read '" + path +
                       "' (check the path; the built-in default is used when none is given)");
  }
  std::stringstream text;
  text << in.rdbuf();
  try {
    return from_text(text.str());
  } catch (const ProfileError& e) {
    throw ProfileError(path + ": " + e.what());
  }
}

GestureProfile GestureProfile::builtin_default() {
  for (const auto& [name, text] : embedded::embedded_files()) {
    if (name == "default.json") return from_text(text);
  }
  throw ProfileError("profile: built-in default profile missing from the build");
}

nlohmann::json GestureProfile::to_json() const {
  nlohmann::json entries = nlohmann::json::object();
  for (const auto& [gesture, m] : this->mappings) {
    nlohmann::json entry = {{"command", contracts::to_string(m.command)}};
    if (m.payload) entry["payload"] = contracts::to_json(*m.payload);
    if (m.repeat_while_held) entry["repeat_while_held"] = true;
    entries[std::string(contracts::to_string(gesture))] = entry;
  }
  nlohmann::json doc = {{"name", name}, {"mappings", entries}};
  if (!description.empty()) doc["description"] = description;
  return doc;
}

CommandTranslator::CommandTranslator(GestureProfile profile) : profile_(std::move(profile)) {}

std::optional<contracts::DroneCommand> CommandTranslator::translate(
    const contracts::GestureEvent& event) const {
  if (event.gesture == GestureType::kNone) return std::nullopt;
  auto it = profile_.mappings.find(event.gesture);
  if (it == profile_.mappings.end()) return std::nullopt;
  const auto& mapping = it->second;
  if (event.repeat && !mapping.repeat_while_held) return std::nullopt;
  contracts::DroneCommand command;
  command.type = mapping.command;
  command.source = contracts::CommandSource::kGesture;
  command.source_id = std::string(contracts::to_string(event.gesture));
  command.payload = mapping.payload;
  command.issued_at = event.timestamp;
  return command;
}

}  // namespace gbdcs::control
