#include <gtest/gtest.h>

#include "gbdcs/contracts/codec.hpp"

namespace gbdcs::contracts {
namespace {

UtcTime t0() { return parse_utc("2026-11-23T08:30:00.123Z"); }

TEST(Utc, FormatsAndParsesMilliseconds) {
  EXPECT_EQ(format_utc(t0()), "2026-11-23T08:30:00.123Z");
  EXPECT_EQ(parse_utc("2026-11-23T08:30:00Z"), t0() - std::chrono::milliseconds(123));
  EXPECT_EQ(parse_utc("2026-11-23T08:30:00.1Z"), t0() - std::chrono::milliseconds(23));
  EXPECT_THROW(parse_utc("2026-11-23 08:30:00"), ContractError);
  EXPECT_THROW(parse_utc("2026-13-23T08:30:00Z"), ContractError);
  EXPECT_THROW(parse_utc("2026-11-23T08:30:00.123+01:00"), ContractError);
}

TEST(Codec, EveryMessageRoundTripsAndValidates) {
  TelemetryFrame f;
  f.timestamp = t0();
  f.altitude_m = 1.25;
  f.speed_m_s = 0.5;
  f.vx_m_s = 0.5;
  f.x_m = -2;
  f.y_m = 3;
  f.heading_deg = 90;
  f.battery_pct = 42.5;
  f.flight_state = FlightState::kFlying;
  f.link = LinkState::kDegraded;
  auto f2 = decode<TelemetryFrame>(encode(f));
  EXPECT_EQ(encode(f2), encode(f));
  EXPECT_EQ(f2.flight_state, FlightState::kFlying);
  EXPECT_EQ(f2.link, LinkState::kDegraded);
  EXPECT_DOUBLE_EQ(f2.battery_pct, 42.5);

  DroneCommand c;
  c.type = CommandType::kMove;
  c.source = CommandSource::kKeyboard;
  c.source_id = "w";
  c.payload = MotionPayload{0.5, -0.25, 0.1, 30, 1.5};
  c.id = 7;
  c.issued_at = t0();
  auto c2 = decode<DroneCommand>(encode(c));
  ASSERT_TRUE(c2.payload.has_value());
  EXPECT_DOUBLE_EQ(c2.payload->vy_m_s, -0.25);
  EXPECT_DOUBLE_EQ(c2.payload->duration_s, 1.5);
  EXPECT_EQ(c2.source, CommandSource::kKeyboard);
  EXPECT_EQ(encode(c2), encode(c));

  GestureEvent g{GestureType::kILoveYou, 0.875, Handedness::kLeft, 12, t0(), true};
  auto g2 = decode<GestureEvent>(encode(g));
  EXPECT_EQ(g2.gesture, GestureType::kILoveYou);
  EXPECT_EQ(g2.handedness, Handedness::kLeft);
  EXPECT_TRUE(g2.repeat);

  Alert a{Severity::kCritical, "LINK_LOSS", "no telemetry", "check the drone", t0(), 3};
  auto a2 = decode<Alert>(encode(a));
  EXPECT_EQ(a2.code, "LINK_LOSS");
  EXPECT_EQ(a2.severity, Severity::kCritical);

  Landmarks m;
  for (std::size_t i = 0; i < kLandmarkCount; ++i) m.points[i] = {0.01 * double(i), 0.5, -0.1};
  m.score = 0.9;
  auto m2 = decode<Landmarks>(encode(m));
  EXPECT_DOUBLE_EQ(m2.points[20].x, 0.2);
  EXPECT_DOUBLE_EQ(m2.score, 0.9);
}

TEST(Codec, EveryNameRoundTrips) {
  for (auto g : kAllGestures) EXPECT_EQ(gesture_from_string(to_string(g)), g);
  EXPECT_FALSE(gesture_from_string("WAVE").has_value());
  EXPECT_FALSE(command_type_from_string("FLIP").has_value());
}

std::string field_of(const std::function<void()>& fn) {
  try {
    fn();
  } catch (const ContractError& e) {
    return e.field() + " | " + e.what();
  }
  return "no error";
}

TEST(Codec, MalformedJsonNamesTheOffset) {
  auto msg = field_of([] { decode<TelemetryFrame>("{\"altitude_m\": 1,"); });
  EXPECT_NE(msg.find("malformed JSON at byte"), std::string::npos) << msg;
}

TEST(Codec, WrongTypeNamesTheField) {
  TelemetryFrame f;
  f.timestamp = t0();
  auto doc = to_json(f);
  doc["altitude_m"] = "high";
  auto msg = field_of([&] { from_json<TelemetryFrame>(doc); });
  EXPECT_EQ(msg.rfind("altitude_m |", 0), 0u) << msg;
}

TEST(Codec, MissingFieldIsReported) {
  TelemetryFrame f;
  f.timestamp = t0();
  auto doc = to_json(f);
  doc.erase("battery_pct");
  auto msg = field_of([&] { from_json<TelemetryFrame>(doc); });
  EXPECT_NE(msg.find("battery_pct"), std::string::npos) << msg;
}

TEST(Codec, NestedPayloadFieldIsNamed) {
  DroneCommand c;
  c.type = CommandType::kMove;
  c.payload = MotionPayload{};
  auto doc = to_json(c);
  doc["payload"]["vx_m_s"] = 99;  // beyond the 5 m/s limit
  auto msg = field_of([&] { from_json<DroneCommand>(doc); });
  EXPECT_EQ(msg.rfind("payload.vx_m_s |", 0), 0u) << msg;
}

TEST(Codec, MoveWithoutPayloadIsRejected) {
  nlohmann::json doc = {{"type", "MOVE"}, {"source", "api"}};
  EXPECT_THROW(from_json<DroneCommand>(doc), ContractError);
  doc["type"] = "HOVER";
  EXPECT_NO_THROW(from_json<DroneCommand>(doc));
}

TEST(Codec, UnknownEnumAndExtraFieldsAreRejected) {
  nlohmann::json doc = {{"type", "BARREL_ROLL"}, {"source", "api"}};
  EXPECT_NE(field_of([&] { from_json<DroneCommand>(doc); }).find("type"), std::string::npos);
  doc = {{"type", "HOVER"}, {"source", "api"}, {"speed", 3}};
  EXPECT_NE(field_of([&] { from_json<DroneCommand>(doc); }).find("speed"), std::string::npos);
}

TEST(Codec, LandmarksNeedExactly21Points) {
  Landmarks m;
  auto doc = to_json(m);
  doc["points"].erase(20);
  EXPECT_NE(field_of([&] { from_json<Landmarks>(doc); }).find("points"), std::string::npos);
}

TEST(Schemas, AllAreEmbeddedAndParse) {
  auto names = schema_names();
  for (const char* n : {"alert", "drone_command", "gesture_event", "gesture_profile", "landmarks",
                        "motion_payload", "telemetry_frame"}) {
    EXPECT_NE(std::find(names.begin(), names.end(), n), names.end()) << n;
    EXPECT_NO_THROW(nlohmann::json::parse(schema_text(n))) << n;
  }
  EXPECT_THROW(schema_text("nope"), std::invalid_argument);
}

TEST(Schemas, ViolationsListsEveryProblem) {
  nlohmann::json doc = {{"severity", "LOUD"}, {"code", "x"}};
  auto v = violations("alert", doc);
  EXPECT_GE(v.size(), 2u);
}

}  // namespace
}  // namespace gbdcs::contracts
