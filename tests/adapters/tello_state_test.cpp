// The Tello state parser: both SDK field sets, units, and fuzzed/truncated datagrams.
#include <gtest/gtest.h>

#include <random>
#include <string>

#include "gbdcs/adapters/tello_state.hpp"

namespace gbdcs::adapters {
namespace {

constexpr const char* kSdk20 =
    "mid:-1;x:-100;y:-100;z:-100;mpry:0,0,0;pitch:1;roll:-2;yaw:-35;vgx:3;vgy:-4;vgz:-5;"
    "templ:60;temph:63;tof:110;h:100;bat:87;baro:12.34;time:7;agx:1.00;agy:-2.00;agz:-998.00;\r\n";
constexpr const char* kSdk13 =
    "pitch:0;roll:0;yaw:12;vgx:0;vgy:0;vgz:0;templ:50;temph:52;tof:10;h:0;bat:55;baro:-3.20;"
    "time:0;agx:0.00;agy:0.00;agz:-1001.00;\r\n";

TEST(TelloState, DecodesTheSdk20Set) {
  std::string why;
  const auto s = decode_state(kSdk20, why);
  ASSERT_TRUE(s) << why;
  EXPECT_EQ(s->yaw_deg, -35);
  EXPECT_EQ(s->pitch_deg, 1);
  EXPECT_EQ(s->roll_deg, -2);
  EXPECT_EQ(s->vgx, 3);
  EXPECT_EQ(s->vgy, -4);
  EXPECT_EQ(s->vgz, -5);
  EXPECT_EQ(s->h_cm, 100);
  EXPECT_EQ(s->tof_cm, 110);
  EXPECT_EQ(s->bat_pct, 87);
  EXPECT_DOUBLE_EQ(s->baro_m, 12.34);
  EXPECT_EQ(s->time_s, 7);
  EXPECT_DOUBLE_EQ(s->agz, -998);
  EXPECT_EQ(s->fields.at("mpry"), "0,0,0");  // unknown to the decoder, kept as text
  EXPECT_EQ(s->fields.at("mid"), "-1");
}

TEST(TelloState, DecodesTheSdk13SetAndToleratesSpacingAndOrder) {
  std::string why;
  ASSERT_TRUE(decode_state(kSdk13, why)) << why;
  // No fixed pattern: other order, spaces after ';', no trailing CRLF, an extra key.
  const auto s = decode_state("bat:40; h:25;yaw:180;newkey:abc;vgx:+2", why);
  ASSERT_TRUE(s) << why;
  EXPECT_EQ(s->h_cm, 25);
  EXPECT_EQ(s->bat_pct, 40);
  EXPECT_EQ(s->vgx, 2);
}

TEST(TelloState, RejectsMalformedDatagramsWithAReason) {
  for (const char* bad : {"", "hello", "h:abc;bat:1;yaw:0;", "h:1;bat:2;", "h:1;bat:200;yaw:0;",
                          ":5;h:1;bat:2;yaw:0;", "h:1;bat:2;yaw:0;bad key:1;",
                          "h:1;bat:2;yaw:nan;", "h:1;bat:2;yaw:1e999;"}) {
    std::string why;
    EXPECT_FALSE(decode_state(bad, why)) << "accepted: " << bad;
    EXPECT_FALSE(why.empty()) << bad;
  }
  std::string why;
  EXPECT_FALSE(decode_state(std::string("h:1;bat:2;yaw:0;\x01:1;"), why));
  EXPECT_FALSE(decode_state(std::string(5000, 'a'), why));
}

TEST(TelloState, FuzzedAndTruncatedDatagramsNeverCrash) {
  std::mt19937 rng(1234);  // seeded: the same datagrams every run
  const std::string good = kSdk20;
  int accepted = 0;
  for (int i = 0; i < 20000; ++i) {
    std::string d;
    switch (i % 3) {
      case 0:  // truncated
        d = good.substr(0, rng() % (good.size() + 1));
        break;
      case 1: {  // bytes flipped
        d = good;
        for (int k = 0; k < 3; ++k) d[rng() % d.size()] = static_cast<char>(rng() % 256);
        break;
      }
      default: {  // random bytes
        d.resize(rng() % 300);
        for (auto& c : d) c = static_cast<char>(rng() % 256);
      }
    }
    std::string why;
    const auto s = decode_state(d, why);
    if (s) {
      ++accepted;
      EXPECT_GE(s->bat_pct, 0);
    } else {
      EXPECT_FALSE(why.empty());
    }
  }
  EXPECT_GT(accepted, 0);  // some truncations still carry h, bat and yaw
}

}  // namespace
}  // namespace gbdcs::adapters
