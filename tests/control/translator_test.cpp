#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "gbdcs/contracts/codec.hpp"
#include "gbdcs/control/command_translator.hpp"

namespace gbdcs::control {
namespace {

using contracts::CommandType;
using contracts::GestureType;

contracts::GestureEvent event(GestureType g, bool repeat = false) {
  contracts::GestureEvent e;
  e.gesture = g;
  e.confidence = 0.9;
  e.repeat = repeat;
  e.timestamp = contracts::parse_utc("2026-11-23T10:00:00Z");
  return e;
}

std::string error_of(std::string_view text) {
  try {
    GestureProfile::from_text(text);
  } catch (const ProfileError& e) {
    return e.what();
  }
  return "no error";
}

TEST(Profile, DefaultMapsTheWholeVocabulary) {
  auto p = GestureProfile::builtin_default();
  EXPECT_EQ(p.name, "default");
  for (auto g : contracts::kAllGestures) {
    if (g == GestureType::kNone) {
      EXPECT_FALSE(p.mappings.contains(g));
    } else {
      EXPECT_TRUE(p.mappings.contains(g)) << contracts::to_string(g);
    }
  }
  EXPECT_EQ(p.mappings.at(GestureType::kThumbUp).command, CommandType::kTakeoff);
  EXPECT_EQ(p.mappings.at(GestureType::kFist).command, CommandType::kLand);
}

TEST(Profile, TheRepoFileIsTheEmbeddedOne) {
  auto file = GestureProfile::load_file(std::string(GBDCS_SOURCE_DIR) +
                                        "/core/control/profiles/default.json");
  EXPECT_EQ(file.to_json(), GestureProfile::builtin_default().to_json());
}

TEST(Profile, RoundTripsThroughJson) {
  auto p = GestureProfile::builtin_default();
  auto again = GestureProfile::from_json(p.to_json());
  EXPECT_EQ(again.to_json(), p.to_json());
}

TEST(Profile, UnknownGestureIsRejectedByName) {
  auto msg = error_of(R"({"name":"x","mappings":{"WAVE":{"command":"HOVER"}}})");
  EXPECT_NE(msg.find("unknown gesture 'WAVE'"), std::string::npos) << msg;
}

TEST(Profile, UnknownCommandIsRejectedByName) {
  auto msg = error_of(R"({"name":"x","mappings":{"FIST":{"command":"FLIP"}}})");
  EXPECT_NE(msg.find("unknown command 'FLIP'"), std::string::npos) << msg;
}

TEST(Profile, NoneCannotBeMapped) {
  auto msg = error_of(R"({"name":"x","mappings":{"NONE":{"command":"HOVER"}}})");
  EXPECT_NE(msg.find("NONE cannot be mapped"), std::string::npos) << msg;
}

TEST(Profile, MoveNeedsPayloadAndOnlyMoveTakesOne) {
  EXPECT_NE(error_of(R"({"name":"x","mappings":{"FIST":{"command":"MOVE"}}})").find("payload"),
            std::string::npos);
  EXPECT_NE(error_of(R"({"name":"x","mappings":{"FIST":{"command":"LAND","payload":{}}}})")
                .find("only MOVE takes a payload"),
            std::string::npos);
  EXPECT_NE(error_of(R"({"name":"x","mappings":{"FIST":{"command":"MOVE","payload":{"vx_m_s":50}}}})")
                .find("vx_m_s"),
            std::string::npos);
}

TEST(Profile, MalformedJsonAndMissingFile) {
  EXPECT_NE(error_of("{\"name\": ").find("malformed JSON"), std::string::npos);
  EXPECT_THROW(GestureProfile::load_file("/nonexistent/profile.json"), ProfileError);
}

TEST(Translator, OnsetTranslatesRepeatOnlyWhenHeldMove) {
  CommandTranslator t(GestureProfile::builtin_default());
  auto takeoff = t.translate(event(GestureType::kThumbUp));
  ASSERT_TRUE(takeoff);
  EXPECT_EQ(takeoff->type, CommandType::kTakeoff);
  EXPECT_EQ(takeoff->source, contracts::CommandSource::kGesture);
  EXPECT_EQ(takeoff->source_id, "THUMB_UP");
  EXPECT_FALSE(t.translate(event(GestureType::kThumbUp, true)));  // a held take-off is sent once

  auto left = t.translate(event(GestureType::kPointLeft, true));
  ASSERT_TRUE(left);
  EXPECT_EQ(left->type, CommandType::kMove);
  ASSERT_TRUE(left->payload);
  EXPECT_LT(left->payload->vy_m_s, 0);
}

TEST(Translator, NoneAndUnmappedProduceNothing) {
  CommandTranslator t(GestureProfile::from_text(
      R"({"name":"tiny","mappings":{"FIST":{"command":"LAND"}}})"));
  EXPECT_FALSE(t.translate(event(GestureType::kNone)));
  EXPECT_FALSE(t.translate(event(GestureType::kOpenPalm)));
  EXPECT_TRUE(t.translate(event(GestureType::kFist)));
}

}  // namespace
}  // namespace gbdcs::control
