#include "gbdcs/sim/faults.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>

namespace gbdcs::sim {
namespace {

const char* kAllFaults = R"({"faults": [
  {"type": "link_loss", "start_s": 5, "duration_s": 2},
  {"type": "telemetry_delay", "start_s": 0, "duration_s": 10, "delay_ms": 200, "jitter_ms": 50},
  {"type": "battery_jump", "start_s": 3, "battery_pct": 15},
  {"type": "wind_gust", "start_s": 4, "duration_s": 1, "force_n": [0.2, -0.1, 0]},
  {"type": "wind_gust", "start_s": 4.5, "duration_s": 1, "force_n": [0.1, 0, 0]},
  {"type": "motor_degraded", "start_s": 4, "motor": 2, "thrust_factor": 0.7},
  {"type": "sensor_noise", "start_s": 1, "duration_s": 60, "position_sigma_m": 0.05,
   "heading_sigma_deg": 2}
]})";

std::string error_of(const std::string& text) {
  try {
    FaultSchedule::from_json_text(text);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(FaultSchedule, ParsesEveryType) {
  const auto s = FaultSchedule::from_json_text(kAllFaults);
  ASSERT_EQ(s.faults().size(), 7u);
  EXPECT_EQ(s.faults()[2].type, FaultType::kBatteryJump);
  EXPECT_DOUBLE_EQ(s.faults()[2].battery_pct, 15);
  EXPECT_TRUE(std::isinf(s.faults()[5].duration_s));  // no duration: to the end
  // Round trip.
  const auto again = FaultSchedule::from_json(s.to_json());
  EXPECT_EQ(again.to_json(), s.to_json());
  // The bare array is accepted too.
  EXPECT_EQ(FaultSchedule::from_json(s.to_json()["faults"]).faults().size(), 7u);
}

TEST(FaultSchedule, QueriesFollowTheSimulatedClock) {
  const auto s = FaultSchedule::from_json_text(kAllFaults);
  EXPECT_FALSE(s.link_lost(4.999));
  EXPECT_TRUE(s.link_lost(5.0));
  EXPECT_TRUE(s.link_lost(6.999));
  EXPECT_FALSE(s.link_lost(7.0));

  EXPECT_EQ(s.wind_force_n(3.9), (std::array<double, 3>{0, 0, 0}));
  EXPECT_EQ(s.wind_force_n(4.2), (std::array<double, 3>{0.2, -0.1, 0}));
  EXPECT_EQ(s.wind_force_n(4.7), (std::array<double, 3>{0.30000000000000004, -0.1, 0}));
  EXPECT_EQ(s.wind_force_n(5.2), (std::array<double, 3>{0.1, 0, 0}));

  EXPECT_EQ(s.motor_factor(2, 3.0), 1.0);
  EXPECT_EQ(s.motor_factor(2, 400.0), 0.7);
  EXPECT_EQ(s.motor_factor(1, 400.0), 1.0);

  EXPECT_FALSE(s.sensor_noise(0.5).any());
  EXPECT_DOUBLE_EQ(s.sensor_noise(2).position_sigma_m, 0.05);
  EXPECT_DOUBLE_EQ(s.sensor_noise(2).velocity_sigma_m_s, 0);
}

TEST(FaultSchedule, TelemetryDelayJitterIsSeededAndBounded) {
  const auto s = FaultSchedule::from_json_text(kAllFaults);
  double low = 1, high = 0;
  for (int ms = 0; ms < 10'000; ms += 7) {
    const double d = s.telemetry_delay_s(ms / 1000.0, 42);
    low = std::min(low, d);
    high = std::max(high, d);
    EXPECT_EQ(d, s.telemetry_delay_s(ms / 1000.0, 42));  // the same question, the same answer
  }
  EXPECT_GE(low, 0.150);
  EXPECT_LE(high, 0.250);
  EXPECT_LT(low, 0.160);  // the jitter is used
  EXPECT_GT(high, 0.240);
  EXPECT_NE(s.telemetry_delay_s(1.0, 42), s.telemetry_delay_s(1.0, 43));
  EXPECT_EQ(s.telemetry_delay_s(10.0, 42), 0.0);  // over
}

TEST(FaultSchedule, StrictJsonErrorsNameTheFaultAndKey) {
  using ::testing::HasSubstr;
  EXPECT_THAT(error_of(R"([{"type": "tornado"}])"),
              HasSubstr("fault 0: unknown type 'tornado' (known: link_loss, telemetry_delay, "
                        "battery_jump, wind_gust, motor_degraded, sensor_noise)"));
  EXPECT_THAT(error_of(R"([{"start_s": 1}])"), HasSubstr("fault 0: 'type' is required"));
  EXPECT_THAT(error_of(R"([{"type": "link_loss"}, {"type": "link_loss", "delay_ms": 5}])"),
              HasSubstr("fault 1 (link_loss): 'delay_ms' is not a known option"));
  EXPECT_THAT(error_of(R"([{"type": "battery_jump", "battery_pct": 5, "duration_s": 1}])"),
              HasSubstr("'duration_s' is not a known option"));
  EXPECT_THAT(error_of(R"([{"type": "wind_gust", "start_s": 1}])"),
              HasSubstr("fault 0 (wind_gust): 'force_n' is required"));
  EXPECT_THAT(error_of(R"([{"type": "wind_gust", "force_n": [1, 2]}])"),
              HasSubstr("'force_n' must be an array of 3 numbers"));
  EXPECT_THAT(error_of(R"([{"type": "motor_degraded", "motor": 4, "thrust_factor": 0.5}])"),
              HasSubstr("'motor' must be 0...3"));
  EXPECT_THAT(error_of(R"([{"type": "motor_degraded", "motor": 1, "thrust_factor": "half"}])"),
              HasSubstr("'thrust_factor' must be a number"));
  EXPECT_THAT(error_of(R"([{"type": "link_loss", "start_s": 1, "duration_s": 0}])"),
              HasSubstr("'duration_s' must be > 0"));
  EXPECT_THAT(error_of(R"({"fault": []})"), HasSubstr("'fault' is not a known key"));
  EXPECT_THAT(error_of(R"([{"type": "link_loss",)"), HasSubstr("malformed JSON at byte"));
}

TEST(FaultSchedule, LoadNamesTheFile) {
  const std::string path = ::testing::TempDir() + "gbdcs_bad_faults.json";
  std::ofstream(path) << R"([{"type": "hail"}])";
  try {
    FaultSchedule::load(path);
    FAIL() << "bad file accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr(path));
    EXPECT_THAT(e.what(), ::testing::HasSubstr("unknown type 'hail'"));
  }
  std::remove(path.c_str());
  EXPECT_THROW(FaultSchedule::load(path), std::invalid_argument);
}

}  // namespace
}  // namespace gbdcs::sim
