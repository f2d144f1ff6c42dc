// The JSON message parser and schema validation (core/contracts), as every JSON input uses
// them: WebSocket and worker messages, REST bodies, profiles.
//
// Input: byte 0 picks a schema (mod the number of schemas), the rest is the JSON text.
// Checks: parse_json throws only ContractError; violations() and validate() agree; a
// message that decodes re-encodes to JSON that passes its schema and decodes to the same
// text again (encode(decode(encode(m))) == encode(m)); timestamps round-trip.
#include <nlohmann/json.hpp>

#include "fuzz_harness.hpp"
#include "gbdcs/contracts/codec.hpp"
#include "gbdcs/control/command_translator.hpp"

namespace gbdcs::fuzz {
namespace {

constexpr std::string_view kName = "json_messages";
using nlohmann::json;

template <class T>
void round_trip(const json& doc, std::string_view schema) {
  T message;
  try {
    message = contracts::from_json<T>(doc);
  } catch (const contracts::ContractError&) {
    return;  // rejected the documented way
  }
  const auto text = contracts::encode(message);
  const auto again = contracts::parse_json(text);
  const auto problems = contracts::violations(schema, again);
  require(problems.empty(), kName,
          std::string(schema) + ": encode() wrote JSON its own schema rejects: " +
              (problems.empty() ? "" : problems.front()) + " in " + text.substr(0, 300));
  const auto twice = contracts::encode(contracts::decode<T>(text));
  require(twice == text, kName,
          std::string(schema) + ": decode(encode(m)) changed the message: " + text.substr(0, 300) +
              " became " + twice.substr(0, 300));
}

}  // namespace

void json_messages(Bytes input) {
  static const auto names = contracts::schema_names();
  if (input.empty() || names.empty()) return;
  const auto& schema = names[input[0] % names.size()];
  json doc;
  try {
    doc = contracts::parse_json(as_text(input.subspan(1)));
  } catch (const contracts::ContractError&) {
    return;
  }

  const auto problems = contracts::violations(schema, doc);
  bool threw = false;
  try {
    contracts::validate(schema, doc);
  } catch (const contracts::ContractError&) {
    threw = true;
  }
  require(threw == !problems.empty(), kName,
          schema + ": validate() and violations() disagree on " + doc.dump().substr(0, 300));

  // Every decoder sees every document: they must reject foreign ones cleanly.
  round_trip<contracts::Landmarks>(doc, "landmarks");
  round_trip<contracts::GestureEvent>(doc, "gesture_event");
  round_trip<contracts::DroneCommand>(doc, "drone_command");
  round_trip<contracts::TelemetryFrame>(doc, "telemetry_frame");
  round_trip<contracts::Alert>(doc, "alert");

  try {
    const auto profile = control::GestureProfile::from_json(doc);
    const auto text = profile.to_json().dump();
    const auto again = control::GestureProfile::from_text(text).to_json().dump();
    require(again == text, kName, "gesture profile changed on a round trip: " + text.substr(0, 300));
  } catch (const control::ProfileError&) {
  }

  if (doc.is_string()) {
    try {
      const auto t = contracts::parse_utc(doc.get<std::string>());
      const auto text = contracts::format_utc(t);
      require(contracts::parse_utc(text) == t, kName, "timestamp " + text + " does not round-trip");
    } catch (const contracts::ContractError&) {
    }
  }
}

}  // namespace gbdcs::fuzz

GBDCS_FUZZ_ENTRY(json_messages)
