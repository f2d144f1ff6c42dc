// String names of the contract enums, exactly as they appear in the JSON Schemas.
#include <utility>

#include "gbdcs/contracts/messages.hpp"

namespace gbdcs::contracts {
namespace {

template <class E, std::size_t N>
std::string_view name_of(const std::array<std::pair<E, std::string_view>, N>& table, E value) {
  for (const auto& [e, name] : table) {
    if (e == value) return name;
  }
  return "?";
}

template <class E, std::size_t N>
std::optional<E> value_of(const std::array<std::pair<E, std::string_view>, N>& table,
                          std::string_view name) {
  for (const auto& [e, n] : table) {
    if (n == name) return e;
  }
  return std::nullopt;
}

constexpr std::array<std::pair<GestureType, std::string_view>, 10> kGestureNames{{
    {GestureType::kNone, "NONE"},
    {GestureType::kOpenPalm, "OPEN_PALM"},
    {GestureType::kFist, "FIST"},
    {GestureType::kThumbUp, "THUMB_UP"},
    {GestureType::kThumbDown, "THUMB_DOWN"},
    {GestureType::kPointLeft, "POINT_LEFT"},
    {GestureType::kPointRight, "POINT_RIGHT"},
    {GestureType::kPointUp, "POINT_UP"},
    {GestureType::kVictory, "VICTORY"},
    {GestureType::kILoveYou, "I_LOVE_YOU"},
}};
constexpr std::array<std::pair<Handedness, std::string_view>, 2> kHandNames{{
    {Handedness::kLeft, "Left"}, {Handedness::kRight, "Right"}}};
constexpr std::array<std::pair<CommandType, std::string_view>, 5> kCommandNames{{
    {CommandType::kTakeoff, "TAKEOFF"},
    {CommandType::kLand, "LAND"},
    {CommandType::kHover, "HOVER"},
    {CommandType::kMove, "MOVE"},
    {CommandType::kEmergencyStop, "EMERGENCY_STOP"},
}};
constexpr std::array<std::pair<CommandSource, std::string_view>, 5> kSourceNames{{
    {CommandSource::kGesture, "gesture"},
    {CommandSource::kKeyboard, "keyboard"},
    {CommandSource::kApi, "api"},
    {CommandSource::kFailsafe, "failsafe"},
    {CommandSource::kScenario, "scenario"},
}};
constexpr std::array<std::pair<FlightState, std::string_view>, 5> kFlightNames{{
    {FlightState::kInit, "INIT"},
    {FlightState::kReady, "READY"},
    {FlightState::kFlying, "FLYING"},
    {FlightState::kLanding, "LANDING"},
    {FlightState::kFault, "FAULT"},
}};
constexpr std::array<std::pair<LinkState, std::string_view>, 3> kLinkNames{{
    {LinkState::kOk, "OK"}, {LinkState::kDegraded, "DEGRADED"}, {LinkState::kLost, "LOST"}}};
constexpr std::array<std::pair<Severity, std::string_view>, 3> kSeverityNames{{
    {Severity::kInfo, "INFO"}, {Severity::kWarning, "WARNING"}, {Severity::kCritical, "CRITICAL"}}};

}  // namespace

std::string_view to_string(GestureType g) { return name_of(kGestureNames, g); }
std::optional<GestureType> gesture_from_string(std::string_view s) {
  return value_of(kGestureNames, s);
}
std::string_view to_string(Handedness h) { return name_of(kHandNames, h); }
std::optional<Handedness> handedness_from_string(std::string_view s) {
  return value_of(kHandNames, s);
}
std::string_view to_string(CommandType t) { return name_of(kCommandNames, t); }
std::optional<CommandType> command_type_from_string(std::string_view s) {
  return value_of(kCommandNames, s);
}
std::string_view to_string(CommandSource s) { return name_of(kSourceNames, s); }
std::optional<CommandSource> command_source_from_string(std::string_view s) {
  return value_of(kSourceNames, s);
}
std::string_view to_string(FlightState s) { return name_of(kFlightNames, s); }
std::optional<FlightState> flight_state_from_string(std::string_view s) {
  return value_of(kFlightNames, s);
}
std::string_view to_string(LinkState s) { return name_of(kLinkNames, s); }
std::optional<LinkState> link_state_from_string(std::string_view s) {
  return value_of(kLinkNames, s);
}
std::string_view to_string(Severity s) { return name_of(kSeverityNames, s); }
std::optional<Severity> severity_from_string(std::string_view s) {
  return value_of(kSeverityNames, s);
}

}  // namespace gbdcs::contracts
