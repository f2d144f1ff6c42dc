#include <gtest/gtest.h>

#include "gbdcs/contracts/clock.hpp"
#include "gbdcs/contracts/codec.hpp"

namespace gbdcs::contracts {
namespace {

TEST(ManualClock, MovesOnlyWhenTold) {
  ManualClock clock(parse_utc("2026-01-01T00:00:00Z"));
  EXPECT_EQ(clock.now(), Duration{0});
  clock.advance(from_seconds(1.5));
  EXPECT_DOUBLE_EQ(to_seconds(clock.now()), 1.5);
  EXPECT_EQ(format_utc(clock.utc_now()), "2026-01-01T00:00:01.500Z");
  EXPECT_THROW(clock.set(from_seconds(1.0)), std::invalid_argument);
  EXPECT_THROW(clock.advance(from_seconds(-1)), std::invalid_argument);
}

TEST(SteadyClock, IsMonotonic) {
  SteadyClock clock;
  auto a = clock.now();
  auto b = clock.now();
  EXPECT_LE(a, b);
}

}  // namespace
}  // namespace gbdcs::contracts
