// What goes in comes back: users, sessions, each log, config.
#include <gtest/gtest.h>

#include <thread>
#include <vector>

#include "gbdcs/storage/storage_manager.hpp"
#include "storage_test_support.hpp"

namespace gbdcs::storage {
namespace {

using namespace std::chrono_literals;
using contracts::ManualClock;
using testing::sample_frame;
using testing::TempDir;

class StorageRoundTrip : public ::testing::Test {
 protected:
  StorageOptions options() const { return {.path = dir_.file("var/db/gbdcs.db")}; }
  TempDir dir_;
  ManualClock clock_;
};

TEST_F(StorageRoundTrip, CreatesParentFoldersAndReportsItself) {
  StorageManager db(options(), clock_);
  EXPECT_TRUE(std::filesystem::exists(options().path));
  EXPECT_EQ(db.path(), options().path);
  EXPECT_GE(db.schema_version(), 1);
  EXPECT_GT(db.size_bytes(), 0);
  testing::RawDb raw(options().path);
  EXPECT_EQ(raw.text("PRAGMA journal_mode"), "wal");
  EXPECT_EQ(raw.integer("PRAGMA auto_vacuum"), 2);  // INCREMENTAL
}

TEST_F(StorageRoundTrip, Users) {
  StorageManager db(options(), clock_);
  auto alice = db.create_user("alice", "$argon2id$hash-a");
  ASSERT_TRUE(alice.has_value());
  EXPECT_FALSE(db.create_user("alice", "other").has_value());
  EXPECT_FALSE(db.create_user("ALICE", "other").has_value()) << "names are case-insensitive";
  auto bob = db.create_user("bob", "$argon2id$hash-b");
  ASSERT_TRUE(bob.has_value());
  EXPECT_NE(*alice, *bob);

  auto found = db.find_user("alice");
  ASSERT_TRUE(found.has_value());
  EXPECT_EQ(found->id, *alice);
  EXPECT_EQ(found->username, "alice");
  EXPECT_EQ(found->password_hash, "$argon2id$hash-a");
  EXPECT_EQ(found->theme, "light");
  EXPECT_EQ(found->created_at, clock_.utc_now());
  EXPECT_FALSE(db.find_user("carol").has_value());

  EXPECT_TRUE(db.set_user_theme(*alice, "dark"));
  EXPECT_FALSE(db.set_user_theme(*bob + 100, "dark"));
  EXPECT_EQ(db.find_user("alice")->theme, "dark");
  EXPECT_EQ(db.find_user("bob")->theme, "light");
}

TEST_F(StorageRoundTrip, SessionsListNewestFirstWithCountsAndDuration) {
  StorageManager db(options(), clock_);
  const auto user = db.create_user("pilot", "h");
  const auto first = db.begin_session(user, "twin", "default");
  clock_.advance(90s);
  EXPECT_TRUE(db.end_session(first));
  EXPECT_FALSE(db.end_session(first)) << "ending twice keeps the first end";
  EXPECT_FALSE(db.end_session(first + 1000));
  clock_.advance(10s);
  const auto second = db.begin_session(std::nullopt, "tello", "left-handed");
  contracts::DroneCommand cmd;
  ASSERT_TRUE(db.log_command(second, cmd, "OK"));
  ASSERT_TRUE(db.log_command(second, cmd, "REJECTED"));
  ASSERT_TRUE(db.log_alert(second, contracts::Alert{}));
  clock_.advance(2500ms);

  auto list = db.list_sessions(10);
  ASSERT_EQ(list.size(), 2u);
  EXPECT_EQ(list[0].id, second);
  EXPECT_EQ(list[1].id, first);
  EXPECT_FALSE(list[0].user_id.has_value());
  EXPECT_EQ(list[0].drone, "tello");
  EXPECT_EQ(list[0].profile, "left-handed");
  EXPECT_FALSE(list[0].ended_at.has_value());
  EXPECT_DOUBLE_EQ(list[0].duration_s, 2.5);  // open: measured to the clock's now
  EXPECT_EQ(list[0].command_count, 2);
  EXPECT_EQ(list[0].alert_count, 1);
  EXPECT_EQ(list[1].user_id, user);
  ASSERT_TRUE(list[1].ended_at.has_value());
  EXPECT_EQ(*list[1].ended_at - list[1].started_at, 90s);
  EXPECT_DOUBLE_EQ(list[1].duration_s, 90.0);
  EXPECT_EQ(list[1].command_count, 0);

  auto page = db.list_sessions(1, 1);
  ASSERT_EQ(page.size(), 1u);
  EXPECT_EQ(page[0].id, first);
  EXPECT_EQ(db.session_count(), 2);
  ASSERT_TRUE(db.get_session(second).has_value());
  EXPECT_EQ(db.get_session(second)->command_count, 2);
  EXPECT_FALSE(db.get_session(second + 1000).has_value());
}

TEST_F(StorageRoundTrip, GesturesRoundTrip) {
  StorageManager db(options(), clock_);
  const auto s = db.begin_session(std::nullopt, "dummy", "default");
  contracts::GestureEvent a{contracts::GestureType::kThumbUp, 0.875,
                            contracts::Handedness::kLeft,     42,
                            clock_.utc_now() + 5ms,           false};
  contracts::GestureEvent b{contracts::GestureType::kILoveYou, 0.5,
                            contracts::Handedness::kRight,     43,
                            clock_.utc_now() + 40ms,           true};
  auto ra = db.log_gesture(s, a);
  ASSERT_TRUE(ra) << ra.error;
  EXPECT_GT(ra.row_id, 0);
  ASSERT_TRUE(db.log_gesture(s, b));
  auto back = db.gestures(s);
  ASSERT_EQ(back.size(), 2u);
  for (const auto& [got, want] : {std::pair{back[0], a}, std::pair{back[1], b}}) {
    EXPECT_EQ(got.gesture, want.gesture);
    EXPECT_EQ(got.confidence, want.confidence);
    EXPECT_EQ(got.handedness, want.handedness);
    EXPECT_EQ(got.frame_id, want.frame_id);
    EXPECT_EQ(got.timestamp, want.timestamp);
    EXPECT_EQ(got.repeat, want.repeat);
  }
  EXPECT_TRUE(db.gestures(s + 1).empty());
}

TEST_F(StorageRoundTrip, CommandsRoundTripWithAndWithoutPayload) {
  StorageManager db(options(), clock_);
  const auto s = db.begin_session(std::nullopt, "dummy", "default");
  contracts::DroneCommand move;
  move.type = contracts::CommandType::kMove;
  move.source = contracts::CommandSource::kKeyboard;
  move.source_id = "ArrowUp";
  move.payload = contracts::MotionPayload{0.5, -0.25, 0.125, 30.0, 1.5};
  move.id = 7;
  move.issued_at = clock_.utc_now() - 3ms;
  contracts::DroneCommand stop;
  stop.type = contracts::CommandType::kEmergencyStop;
  stop.source = contracts::CommandSource::kFailsafe;
  stop.source_id = "LINK_LOSS";
  stop.id = 8;
  stop.issued_at = clock_.utc_now() + 1ms;
  ASSERT_TRUE(db.log_command(s, move, "OK"));
  clock_.advance(20ms);
  ASSERT_TRUE(db.log_command(s, stop, "ADAPTER_TIMEOUT"));

  auto back = db.commands(s);
  ASSERT_EQ(back.size(), 2u);
  EXPECT_EQ(back[0].command.type, contracts::CommandType::kMove);
  EXPECT_EQ(back[0].command.source, contracts::CommandSource::kKeyboard);
  EXPECT_EQ(back[0].command.source_id, "ArrowUp");
  EXPECT_EQ(back[0].command.id, 7);
  EXPECT_EQ(back[0].command.issued_at, move.issued_at);
  EXPECT_EQ(back[0].result, "OK");
  EXPECT_EQ(back[0].recorded_at, clock_.utc_now() - 20ms);
  ASSERT_TRUE(back[0].command.payload.has_value());
  EXPECT_EQ(back[0].command.payload->vx_m_s, 0.5);
  EXPECT_EQ(back[0].command.payload->vy_m_s, -0.25);
  EXPECT_EQ(back[0].command.payload->vz_m_s, 0.125);
  EXPECT_EQ(back[0].command.payload->yaw_rate_deg_s, 30.0);
  EXPECT_EQ(back[0].command.payload->duration_s, 1.5);
  EXPECT_EQ(back[1].command.type, contracts::CommandType::kEmergencyStop);
  EXPECT_EQ(back[1].command.source, contracts::CommandSource::kFailsafe);
  EXPECT_FALSE(back[1].command.payload.has_value());
  EXPECT_EQ(back[1].result, "ADAPTER_TIMEOUT");
  EXPECT_EQ(back[1].recorded_at, clock_.utc_now());
}

TEST_F(StorageRoundTrip, TelemetryRoundTripInOrderWithLimit) {
  StorageManager db(options(), clock_);
  const auto s = db.begin_session(std::nullopt, "twin", "default");
  const auto other = db.begin_session(std::nullopt, "twin", "default");
  // Logged out of order: read-back is by timestamp.
  for (int i : {2, 0, 3, 1}) {
    ASSERT_TRUE(db.log_telemetry(s, sample_frame(clock_.utc_now() + i * 200ms, i)));
  }
  ASSERT_TRUE(db.log_telemetry(other, sample_frame(clock_.utc_now(), 9)));
  auto back = db.telemetry(s);
  ASSERT_EQ(back.size(), 4u);
  for (int i = 0; i < 4; ++i) {
    const auto want = sample_frame(clock_.utc_now() + i * 200ms, i);
    const auto& got = back[static_cast<std::size_t>(i)];
    EXPECT_EQ(got.timestamp, want.timestamp);
    EXPECT_EQ(got.altitude_m, want.altitude_m);
    EXPECT_EQ(got.speed_m_s, want.speed_m_s);
    EXPECT_EQ(got.vx_m_s, want.vx_m_s);
    EXPECT_EQ(got.vy_m_s, want.vy_m_s);
    EXPECT_EQ(got.vz_m_s, want.vz_m_s);
    EXPECT_EQ(got.x_m, want.x_m);
    EXPECT_EQ(got.y_m, want.y_m);
    EXPECT_EQ(got.heading_deg, want.heading_deg);
    EXPECT_EQ(got.battery_pct, want.battery_pct);
    EXPECT_EQ(got.flight_state, want.flight_state);
    EXPECT_EQ(got.link, want.link);
  }
  auto first_two = db.telemetry(s, 2);
  ASSERT_EQ(first_two.size(), 2u);
  EXPECT_EQ(first_two[1].timestamp, back[1].timestamp);
  EXPECT_EQ(db.telemetry(other).size(), 1u);
}

TEST_F(StorageRoundTrip, AlertsRoundTripAndAcknowledge) {
  StorageManager db(options(), clock_);
  const auto s = db.begin_session(std::nullopt, "twin", "default");
  contracts::Alert low{contracts::Severity::kWarning,
                       "BATTERY_LOW",
                       "battery at 19 %",
                       "land soon",
                       clock_.utc_now(),
                       1};
  contracts::Alert lost{contracts::Severity::kCritical, "LINK_LOSS",
                        "no telemetry for 1.2 s",       "the drone hovers; check the radio",
                        clock_.utc_now() + 1s,          1};
  auto r1 = db.log_alert(s, low);
  auto r2 = db.log_alert(s, lost);
  ASSERT_TRUE(r1);
  ASSERT_TRUE(r2);
  EXPECT_NE(r1.row_id, r2.row_id) << "row ids, not the ids the alerts carried";

  clock_.advance(5s);
  EXPECT_TRUE(db.acknowledge_alert(r2.row_id));
  const auto first_ack = clock_.utc_now();
  clock_.advance(5s);
  EXPECT_TRUE(db.acknowledge_alert(r2.row_id)) << "acknowledging again is not an error";
  EXPECT_FALSE(db.acknowledge_alert(r2.row_id + 100));

  auto back = db.alerts(s);
  ASSERT_EQ(back.size(), 2u);
  EXPECT_EQ(back[0].alert.id, r1.row_id);
  EXPECT_EQ(back[0].alert.severity, contracts::Severity::kWarning);
  EXPECT_EQ(back[0].alert.code, "BATTERY_LOW");
  EXPECT_EQ(back[0].alert.cause, "battery at 19 %");
  EXPECT_EQ(back[0].alert.suggestion, "land soon");
  EXPECT_EQ(back[0].alert.timestamp, low.timestamp);
  EXPECT_FALSE(back[0].acknowledged_at.has_value());
  EXPECT_EQ(back[1].alert.id, r2.row_id);
  EXPECT_EQ(back[1].alert.code, "LINK_LOSS");
  EXPECT_EQ(back[1].acknowledged_at, first_ack);
}

TEST_F(StorageRoundTrip, ConfigPutGetOverwrite) {
  StorageManager db(options(), clock_);
  EXPECT_FALSE(db.get_config("profile").has_value());
  const nlohmann::json value = {{"active", "default"}, {"hold_frames", 5}, {"ratio", 0.6}};
  db.put_config("profile", value);
  EXPECT_EQ(db.get_config("profile"), value);
  db.put_config("profile", "left-handed");
  EXPECT_EQ(db.get_config("profile"), nlohmann::json("left-handed"));
  db.put_config("null", nullptr);
  ASSERT_TRUE(db.get_config("null").has_value());
  EXPECT_TRUE(db.get_config("null")->is_null());
}

TEST_F(StorageRoundTrip, EndOpenSessionsUsesTheLastLoggedRow) {
  StorageManager db(options(), clock_);
  const auto crashed = db.begin_session(std::nullopt, "twin", "default");
  const auto started = clock_.utc_now();
  ASSERT_TRUE(db.log_telemetry(crashed, sample_frame(started + 7s, 0)));
  const auto empty = db.begin_session(std::nullopt, "twin", "default");
  const auto done = db.begin_session(std::nullopt, "twin", "default");
  ASSERT_TRUE(db.end_session(done));
  clock_.advance(60s);
  EXPECT_EQ(db.end_open_sessions(), 2);
  EXPECT_EQ(db.get_session(crashed)->ended_at, started + 7s);
  EXPECT_EQ(db.get_session(empty)->ended_at, db.get_session(empty)->started_at);
  EXPECT_EQ(db.end_open_sessions(), 0);
}

TEST_F(StorageRoundTrip, ConcurrentLoggersLoseNothing) {
  StorageManager db(options(), clock_);
  const auto s = db.begin_session(std::nullopt, "twin", "default");
  constexpr int kThreads = 4;
  constexpr int kRowsEach = 40;
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&, t] {
      for (int i = 0; i < kRowsEach; ++i) {
        const int n = t * kRowsEach + i;
        EXPECT_TRUE(db.log_telemetry(s, sample_frame(clock_.utc_now(), n)));
        EXPECT_TRUE(db.log_gesture(s, contracts::GestureEvent{.frame_id = n}));
        if (i % 10 == 0) {
          EXPECT_EQ(db.get_session(s)->id, s);
        }
      }
    });
  }
  for (auto& thread : threads) thread.join();
  EXPECT_EQ(db.telemetry(s).size(), static_cast<std::size_t>(kThreads * kRowsEach));
  EXPECT_EQ(db.gestures(s).size(), static_cast<std::size_t>(kThreads * kRowsEach));
  EXPECT_EQ(db.write_failures(), 0);
}

TEST_F(StorageRoundTrip, InMemoryDatabaseWorks) {
  StorageManager db({.path = ":memory:"}, clock_);
  const auto s = db.begin_session(std::nullopt, "dummy", "default");
  ASSERT_TRUE(db.log_telemetry(s, sample_frame(clock_.utc_now(), 1)));
  EXPECT_EQ(db.telemetry(s).size(), 1u);
}

}  // namespace
}  // namespace gbdcs::storage
