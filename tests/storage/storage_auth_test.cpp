// Migration 2: users by id, revoked tokens (logout) and who acknowledged an alert.
#include <gtest/gtest.h>

#include "gbdcs/storage/storage_manager.hpp"
#include "storage_test_support.hpp"

namespace gbdcs::storage {
namespace {

using namespace std::chrono_literals;

TEST(StorageAuth, RevokedTokensUntilTheyExpire) {
  testing::TempDir dir;
  contracts::ManualClock clock;
  StorageManager db({.path = dir.file("gbdcs.db")}, clock);
  EXPECT_GE(db.schema_version(), 2);
  auto user = db.create_user("op@example.com", "$argon2id$x");
  ASSERT_TRUE(user);
  ASSERT_TRUE(db.find_user_by_id(*user));
  EXPECT_EQ(db.find_user_by_id(*user)->username, "op@example.com");
  EXPECT_FALSE(db.find_user_by_id(*user + 100));

  EXPECT_FALSE(db.is_token_revoked("jti-1"));
  db.revoke_token("jti-1", user, clock.utc_now() + 30min);
  db.revoke_token("jti-1", user, clock.utc_now() + 30min);  // twice is fine
  EXPECT_TRUE(db.is_token_revoked("jti-1"));
  EXPECT_TRUE(db.is_token_revoked("jti-1"));
  EXPECT_FALSE(db.is_token_revoked("jti-1' OR '1'='1"));
  EXPECT_EQ(db.purge_revoked_tokens(), 0);
  clock.advance(31min);
  EXPECT_EQ(db.purge_revoked_tokens(), 1);
  EXPECT_FALSE(db.is_token_revoked("jti-1"));
}

TEST(StorageAuth, AlertAcknowledgedBy) {
  testing::TempDir dir;
  contracts::ManualClock clock;
  StorageManager db({.path = dir.file("gbdcs.db")}, clock);
  auto user = db.create_user("op@example.com", "$argon2id$x");
  auto session = db.begin_session(user, "dummy", "default");
  contracts::Alert alert;
  alert.code = "LINK_LOSS";
  alert.cause = "c";
  alert.suggestion = "s";
  alert.timestamp = clock.utc_now();
  auto written = db.log_alert(session, alert);
  ASSERT_TRUE(written);
  EXPECT_FALSE(db.find_alert(written.row_id)->acknowledged_at);
  clock.advance(2s);
  EXPECT_TRUE(db.acknowledge_alert_by(written.row_id, user));
  EXPECT_TRUE(db.find_alert(written.row_id)->acknowledged_at);
  EXPECT_FALSE(db.acknowledge_alert_by(written.row_id + 9, user));
  EXPECT_FALSE(db.find_alert(written.row_id + 9));
  testing::RawDb raw(dir.file("gbdcs.db"));
  EXPECT_EQ(raw.integer("SELECT acknowledged_by FROM alerts"), *user);
}

}  // namespace
}  // namespace gbdcs::storage
