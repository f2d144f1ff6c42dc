// The API and /ws/live schemas: every one parses, and documents shaped as docs/API.md shows
// are accepted while the hostile ones are refused.
#include <gtest/gtest.h>

#include "gbdcs/contracts/codec.hpp"

namespace gbdcs::contracts {
namespace {

using nlohmann::json;

TEST(ApiSchemas, EveryApiAndWsSchemaParses) {
  int count = 0;
  for (const auto& name : schema_names()) {
    if (name.rfind("api_", 0) != 0 && name.rfind("ws_", 0) != 0) continue;
    ++count;
    EXPECT_NO_THROW(violations(name, json::object())) << name;
  }
  EXPECT_GE(count, 30);
}

TEST(ApiSchemas, ErrorEnvelopeNeedsAUlid) {
  json e = {{"error", "invalid_body"},
            {"cause", "x"},
            {"suggestion", "y"},
            {"request_id", "01JD3Z8Q4K7J9ZK3M2V6X1N0AB"}};
  EXPECT_TRUE(violations("api_error", e).empty());
  e["request_id"] = "not-a-ulid";
  EXPECT_FALSE(violations("api_error", e).empty());
}

TEST(ApiSchemas, RegisterRefusesWrongTypesAndExtraFields) {
  EXPECT_TRUE(violations("api_register_request",
                         {{"email", "a@b.example"}, {"password", "long enough pw"}})
                  .empty());
  EXPECT_FALSE(
      violations("api_register_request", {{"email", 5}, {"password", "long enough pw"}}).empty());
  EXPECT_FALSE(violations("api_register_request", {{"email", "a@b.example"},
                                                   {"password", "long enough pw"},
                                                   {"admin", true}})
                   .empty());
}

TEST(ApiSchemas, ServerMessagesAreEnvelopes) {
  json telemetry = {{"timestamp", "2026-11-23T08:30:00.123Z"},
                    {"altitude_m", 1.0},
                    {"speed_m_s", 0.0},
                    {"vx_m_s", 0.0},
                    {"vy_m_s", 0.0},
                    {"vz_m_s", 0.0},
                    {"x_m", 0.0},
                    {"y_m", 0.0},
                    {"heading_deg", 0.0},
                    {"battery_pct", 90.0},
                    {"flight_state", "FLYING"},
                    {"link", "OK"}};
  json msg = {{"type", "telemetry"}, {"ts", "2026-11-23T08:30:00.123Z"}, {"data", telemetry}};
  EXPECT_TRUE(violations("ws_server_message", msg).empty());
  msg["replay"] = true;
  EXPECT_TRUE(violations("ws_server_message", msg).empty());
  msg["type"] = "gesture";  // telemetry data under the wrong type
  EXPECT_FALSE(violations("ws_server_message", msg).empty());
}

TEST(ApiSchemas, ClientMessages) {
  EXPECT_TRUE(violations("ws_client_message", {{"type", "ack"}, {"alert_id", 3}}).empty());
  EXPECT_TRUE(
      violations("ws_client_message", {{"type", "input"}, {"key", "w"}, {"pressed", true}})
          .empty());
  EXPECT_TRUE(violations("ws_client_message", {{"type", "emergency_stop"}}).empty());
  EXPECT_FALSE(violations("ws_client_message", {{"type", "ack"}, {"alert_id", "3"}}).empty());
  EXPECT_FALSE(violations("ws_client_message", {{"type", "launch_missiles"}}).empty());
}

}  // namespace
}  // namespace gbdcs::contracts
