#include <gtest/gtest.h>

#include <atomic>
#include <future>

#include "gbdcs/telemetry/telemetry_manager.hpp"

namespace gbdcs::telemetry {
namespace {

contracts::TelemetryFrame frame(double altitude) {
  contracts::TelemetryFrame f;
  f.altitude_m = altitude;
  return f;
}

TEST(TelemetryManager, FansOutToEveryObserverInOrder) {
  TelemetryManager manager;
  std::vector<double> inline_seen;
  std::vector<double> queued_seen;
  std::mutex m;
  manager.subscribe(make_observer("a", [&](const auto& f) { inline_seen.push_back(f.altitude_m); }),
                    Delivery::kInline);
  manager.subscribe(make_observer("b",
                                  [&](const auto& f) {
                                    std::lock_guard lock(m);
                                    queued_seen.push_back(f.altitude_m);
                                  }),
                    Delivery::kQueued, 100);
  for (int i = 0; i < 50; ++i) manager.publish(frame(i));
  ASSERT_TRUE(manager.drain(std::chrono::seconds(5)));
  EXPECT_EQ(inline_seen.size(), 50u);
  std::lock_guard lock(m);
  ASSERT_EQ(queued_seen.size(), 50u);
  for (int i = 0; i < 50; ++i) EXPECT_EQ(queued_seen[static_cast<std::size_t>(i)], i);
  EXPECT_EQ(manager.latest()->altitude_m, 49);
  EXPECT_EQ(manager.published(), 50u);
}

TEST(TelemetryManager, ABlockedObserverBlocksNobody) {
  TelemetryManager manager;
  std::promise<void> release;
  auto released = release.get_future().share();
  std::atomic<int> fast{0};
  manager.subscribe(make_observer("stuck", [released](const auto&) { released.wait(); }),
                    Delivery::kQueued, 4);
  manager.subscribe(make_observer("fast", [&](const auto&) { ++fast; }), Delivery::kQueued, 1000);
  // publish() returns although "stuck" never finishes its first frame.
  for (int i = 0; i < 100; ++i) manager.publish(frame(i));
  EXPECT_FALSE(manager.drain(std::chrono::milliseconds(200)));  // "stuck" cannot drain
  EXPECT_EQ(fast.load(), 100);
  auto stats = manager.stats();
  ASSERT_EQ(stats.size(), 2u);
  EXPECT_EQ(stats[0].name, "stuck");
  EXPECT_GE(stats[0].dropped, 90u);  // bounded queue of 4: the oldest were dropped
  EXPECT_LE(stats[0].queue_depth, 4u);
  release.set_value();
  EXPECT_TRUE(manager.drain(std::chrono::seconds(5)));
}

TEST(TelemetryManager, AThrowingObserverIsCountedAndOthersStillServed) {
  TelemetryManager manager;
  int after = 0;
  manager.subscribe(make_observer("bad", [](const auto&) { throw std::runtime_error("boom"); }),
                    Delivery::kInline);
  manager.subscribe(make_observer("good", [&](const auto&) { ++after; }), Delivery::kInline);
  manager.publish(frame(1));
  manager.publish(frame(2));
  EXPECT_EQ(after, 2);
  EXPECT_EQ(manager.stats()[0].errors, 2u);
}

TEST(TelemetryManager, UnsubscribeStopsDelivery) {
  TelemetryManager manager;
  int seen = 0;
  auto id = manager.subscribe(make_observer("x", [&](const auto&) { ++seen; }), Delivery::kInline);
  manager.publish(frame(1));
  manager.unsubscribe(id);
  manager.publish(frame(2));
  EXPECT_EQ(seen, 1);
  EXPECT_TRUE(manager.stats().empty());
}

}  // namespace
}  // namespace gbdcs::telemetry
