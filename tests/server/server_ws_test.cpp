// /ws/live over real sockets: refusal without/with bad token and foreign Origin, the state on
// connect, alerts and their ack, client message validation, logout and expiry closing the
// socket, replay marked as such; the per-client queue's drop policy.
#include <condition_variable>
#include <mutex>

#include "server_test_support.hpp"

namespace gbdcs::server::testing {
namespace {

using namespace std::chrono_literals;

TEST(ServerWs, RefusedWithoutGoodTokenOrFromAForeignOrigin) {
  TestServer s;
  EXPECT_EQ(upgrade_status(s.port, "/ws/live"), 401);
  EXPECT_EQ(upgrade_status(s.port, "/ws/live?token=nonsense"), 401);
  const auto token = s.register_and_login();
  EXPECT_EQ(upgrade_status(s.port, "/ws/live?token=" + token, "http://evil.example"), 403);
  EXPECT_EQ(upgrade_status(s.port, "/ws/live?token=" + token,
                                     "http://127.0.0.1:" + std::to_string(s.port)),
            101);
  EXPECT_EQ(upgrade_status(s.port, "/worker?secret=guess"), 403);
  s.clock.advance(31min);
  EXPECT_EQ(upgrade_status(s.port, "/ws/live?token=" + token), 401);
}

TEST(ServerWs, StateAlertAckAndClientMessageValidation) {
  TestServer s;
  const auto token = s.register_and_login();
  ASSERT_EQ(s.drone->connect("dummy", json::object()), "");
  WsClient ws;
  ws.connect(s.port, "/ws/live?token=" + token);
  auto state = ws.next_of("state");
  ASSERT_TRUE(state);
  EXPECT_TRUE(contracts::violations("ws_server_message", *state).empty()) << state->dump();

  contracts::Alert alert;
  alert.severity = contracts::Severity::kCritical;
  alert.code = "TEST_ALERT";
  alert.cause = "a test raised it";
  alert.suggestion = "acknowledge it";
  s.drone->raise_alert(alert);
  auto got = ws.next_of("alert");
  ASSERT_TRUE(got);
  EXPECT_TRUE(contracts::violations("ws_server_message", *got).empty()) << got->dump();
  const auto id = (*got)["data"]["id"].get<std::int64_t>();
  ASSERT_TRUE(s.storage.find_alert(id));

  ws.send(json{{"type", "ack"}, {"alert_id", id}}.dump());
  auto ack = ws.next_of("ack_result");
  ASSERT_TRUE(ack);
  EXPECT_EQ((*ack)["data"]["alert_id"], id);
  EXPECT_TRUE(s.storage.find_alert(id)->acknowledged_at.has_value());

  for (const char* bad : {"not json", "{\"type\": \"ack\", \"alert_id\": \"1\"}",
                          "{\"type\": \"fire\"}", "{\"type\": \"input\", \"key\": 5}",
                          "{\"type\": \"ack\", \"alert_id\": 99999}"}) {
    ws.send(bad);
    auto e = ws.next_of("error");
    ASSERT_TRUE(e) << bad;
    EXPECT_TRUE(contracts::violations("ws_server_message", *e).empty()) << e->dump();
  }
  // Keyboard and emergency stop go to the drone.
  ws.send(json{{"type", "input"}, {"key", "h"}, {"pressed", true}}.dump());
  ws.send(json{{"type", "emergency_stop"}}.dump());
  auto cmd = ws.next_of("command");
  ASSERT_TRUE(cmd);
  bool saw_estop = false;
  for (int i = 0; i < 50 && !saw_estop; ++i) {
    if ((*cmd)["data"]["command"]["type"] == "EMERGENCY_STOP") saw_estop = true;
    else if (!(cmd = ws.next_of("command"))) break;
  }
  EXPECT_TRUE(saw_estop);
  EXPECT_TRUE(s.drone->emergency_latched());
}

TEST(ServerWs, LogoutAndExpiryCloseTheSocket) {
  TestServer s;
  const auto token = s.register_and_login();
  WsClient ws;
  ws.connect(s.port, "/ws/live?token=" + token);
  ASSERT_TRUE(ws.next_of("state"));
  ASSERT_EQ(http_call(s.port, "POST", "/api/v1/auth/logout", "", token).status, 204);
  while (ws.next(10)) {
  }
  EXPECT_TRUE(ws.closed());
  EXPECT_EQ(ws.close_code(), 4001);

  const auto token2 = s.register_and_login("second@example.com", "another good password");
  WsClient ws2;
  ws2.connect(s.port, "/ws/live?token=" + token2);
  ASSERT_TRUE(ws2.next_of("state"));
  s.clock.advance(31min);  // the ticker notices within a tick
  while (ws2.next(10)) {
  }
  EXPECT_TRUE(ws2.closed());
  EXPECT_EQ(ws2.close_code(), 4001);
}

TEST(ServerWs, ReplayStreamsAStoredSessionMarkedAsReplay) {
  TestServer s;
  const auto token = s.register_and_login();
  const auto session = s.storage.begin_session(std::nullopt, "dummy", "default");
  for (int i = 0; i < 10; ++i) {
    contracts::TelemetryFrame f;
    f.timestamp = s.clock.utc_now() + std::chrono::milliseconds(100 * i);
    f.altitude_m = i * 0.1;
    s.storage.log_telemetry(session, f);
  }
  s.storage.end_session(session);
  WsClient ws;
  ws.connect(s.port, "/ws/live?token=" + token);
  ASSERT_TRUE(ws.next_of("state"));
  expect_error(http_call(s.port, "POST", "/api/v1/sessions/424242/replay", "", token), 404, "not_found");
  expect_error(http_call(s.port, "POST", "/api/v1/sessions/" + std::to_string(session) + "/replay",
                         json{{"speed", 0}}.dump(), token),
               400, "invalid_body");
  auto r = http_call(s.port, "POST", "/api/v1/sessions/" + std::to_string(session) + "/replay",
                     json{{"speed", 20}}.dump(), token);
  ASSERT_EQ(r.status, 202) << r.body;
  EXPECT_TRUE(contracts::violations("api_replay_response", r.doc()).empty()) << r.body;
  EXPECT_EQ(r.doc()["messages"], 10);
  int telemetry = 0;
  bool finished = false;
  while (auto m = ws.next(10)) {
    if (!m->value("replay", false)) continue;
    EXPECT_TRUE(contracts::violations("ws_server_message", *m).empty()) << m->dump();
    if ((*m)["type"] == "telemetry") ++telemetry;
    if ((*m)["type"] == "state" && (*m)["data"]["replay"]["finished"] == true) {
      finished = true;
      break;
    }
  }
  EXPECT_EQ(telemetry, 10);
  EXPECT_TRUE(finished);
}

OutMessagePtr msg(MessageClass cls, std::string text) {
  auto m = std::make_shared<OutMessage>();
  m->cls = cls;
  m->text = std::move(text);
  return m;
}

// The worker endpoint (worker -> server): only the per-run secret gets in; a message that is
// not JSON or breaks its schema is logged and dropped, the socket stays up, and the next good
// frame still reaches the server.
TEST(ServerWorker, SecretRequiredAndBadMessagesAreDroppedNotFatal) {
  const std::string secret(32, 'w');
  ServerOptions o;
  o.worker_secret = secret;
  TestServer s(o);
  std::mutex m;
  std::vector<json> got;
  std::condition_variable cv;
  s.server->set_worker_handlers({nullptr,
                                 [&](const json& doc) {
                                   std::lock_guard lock(m);
                                   got.push_back(doc);
                                   cv.notify_all();
                                 },
                                 nullptr});
  EXPECT_EQ(upgrade_status(s.port, "/worker"), 403);
  EXPECT_EQ(upgrade_status(s.port, "/worker?secret=" + std::string(32, 'x')), 403);
  EXPECT_EQ(upgrade_status(s.port, "/worker?secret=" + secret.substr(1)), 403);
  WsClient worker;
  worker.connect(s.port, "/worker?secret=" + secret);
  const json good = {{"type", "frame"},  {"frame_id", 7},     {"capture_time", "2026-01-01T00:00:00.000Z"},
                     {"source", "test"}, {"width", 640},      {"height", 480},
                     {"latency_ms", 1.0}, {"hands", json::array()}, {"gesture_event", nullptr}};
  worker.send("not json at all");
  worker.send("{\"type\": \"frame\"}");
  auto wrong_type = good;
  wrong_type["frame_id"] = "seven";
  worker.send(wrong_type.dump());
  worker.send(json{{"type", "heartbeat"}, {"fps", "fast"}}.dump());
  worker.send(json::array({1, 2, 3}).dump());
  // The live feed's picture: checked against vision_picture (a JPEG is required).
  const json picture = {{"type", "picture"}, {"frame_id", 8},
                        {"capture_time", "2026-01-01T00:00:00.033Z"}, {"width", 480},
                        {"height", 360}, {"jpeg", "AA=="}};
  auto no_jpeg = picture;
  no_jpeg.erase("jpeg");
  worker.send(no_jpeg.dump());
  auto frame_with_pixels = good;  // pixels travel only in pictures now
  frame_with_pixels["jpeg"] = "AA==";
  worker.send(frame_with_pixels.dump());
  worker.send(good.dump());
  worker.send(picture.dump());
  std::unique_lock lock(m);
  ASSERT_TRUE(cv.wait_for(lock, 10s, [&] { return got.size() >= 2; }));
  ASSERT_EQ(got.size(), 2u) << "only the valid frame and picture get through";
  EXPECT_EQ(got[0]["frame_id"], 7);
  EXPECT_EQ(got[1]["type"], "picture");
  EXPECT_EQ(got[1]["frame_id"], 8);
}

TEST(ClientQueue, PicturesAreDroppedFirstLikeFrames) {
  EXPECT_EQ(class_of("picture"), MessageClass::kFrame);
  EXPECT_EQ(class_of("frame"), MessageClass::kFrame);
  EXPECT_EQ(class_of("alert"), MessageClass::kNeverDrop);
}

TEST(ClientQueue, DropsFramesThenTelemetryNeverAlerts) {
  ClientQueue q(4, 6);
  EXPECT_TRUE(q.push(msg(MessageClass::kNeverDrop, "alert1")));
  EXPECT_TRUE(q.push(msg(MessageClass::kTelemetry, "t1")));
  EXPECT_TRUE(q.push(msg(MessageClass::kFrame, "f1")));
  EXPECT_TRUE(q.push(msg(MessageClass::kOther, "g1")));
  EXPECT_TRUE(q.push(msg(MessageClass::kTelemetry, "t2")));  // drops f1
  EXPECT_TRUE(q.push(msg(MessageClass::kNeverDrop, "alert2")));  // drops t1
  EXPECT_EQ(q.dropped(), 2u);
  std::vector<std::string> order;
  while (auto m = q.pop()) order.push_back((*m)->text);
  EXPECT_EQ(order, (std::vector<std::string>{"alert1", "g1", "t2", "alert2"}));
  for (int i = 0; i < 6; ++i) EXPECT_TRUE(q.push(msg(MessageClass::kNeverDrop, "a")));
  EXPECT_FALSE(q.push(msg(MessageClass::kNeverDrop, "a")));  // too slow: disconnect
}

}  // namespace
}  // namespace gbdcs::server::testing
