// JSON (de)serialisation of the messages, validated against core/contracts/schemas/.
//
//   encode(msg)        -> JSON text; the output is valid against the message's schema
//   decode<T>(text)    -> T, or throws ContractError naming the field and what is wrong
//   to_json / from_json the same on nlohmann::json values
//
// Schemas: gesture_event, drone_command, telemetry_frame, alert, landmarks,
// gesture_profile (see schema_names()).
#pragma once

#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "gbdcs/contracts/messages.hpp"

namespace gbdcs::contracts {

// A message that does not match its contract. what() names the field, the problem and how
// to fix it; field() is the JSON path ("payload.vx_m_s", "" for the whole document).
class ContractError : public std::runtime_error {
 public:
  ContractError(std::string field, const std::string& message);
  const std::string& field() const { return field_; }

 private:
  std::string field_;
};

// Validates `doc` against the named schema; throws ContractError on the first violation.
void validate(std::string_view schema_name, const nlohmann::json& doc);
// Every violation, each "field: problem"; empty when valid.
std::vector<std::string> violations(std::string_view schema_name, const nlohmann::json& doc);
std::vector<std::string> schema_names();
std::string_view schema_text(std::string_view schema_name);  // throws if unknown

// Parses JSON text; throws ContractError with the byte offset for malformed JSON.
nlohmann::json parse_json(std::string_view text);

std::string format_utc(UtcTime t);          // 2026-11-23T08:30:00.123Z
UtcTime parse_utc(std::string_view text);   // throws ContractError

nlohmann::json to_json(const Landmarks& m);
nlohmann::json to_json(const GestureEvent& m);
nlohmann::json to_json(const DroneCommand& m);
nlohmann::json to_json(const TelemetryFrame& m);
nlohmann::json to_json(const Alert& m);
nlohmann::json to_json(const MotionPayload& m);
MotionPayload motion_payload_from_json(const nlohmann::json& doc);  // validated by the caller

template <class T>
T from_json(const nlohmann::json& doc);
template <> Landmarks from_json<Landmarks>(const nlohmann::json& doc);
template <> GestureEvent from_json<GestureEvent>(const nlohmann::json& doc);
template <> DroneCommand from_json<DroneCommand>(const nlohmann::json& doc);
template <> TelemetryFrame from_json<TelemetryFrame>(const nlohmann::json& doc);
template <> Alert from_json<Alert>(const nlohmann::json& doc);

template <class T>
std::string encode(const T& msg) {
  return to_json(msg).dump();
}
template <class T>
T decode(std::string_view text) {
  return from_json<T>(parse_json(text));
}

}  // namespace gbdcs::contracts
