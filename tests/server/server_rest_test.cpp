// REST over real sockets: every route, each failure status with its envelope, auth (policy,
// rate limit, expiry on an injected clock, revocation), hostile input, static files.
#include <fstream>
#include <regex>

#include "gbdcs/server/routes.hpp"
#include "server_test_support.hpp"

namespace gbdcs::server::testing {
namespace {

using namespace std::chrono_literals;

TEST(ServerAuth, RegisterLoginLogoutAndEveryAuthFailure) {
  TestServer s;
  const json good = {{"email", "pilot@example.com"}, {"password", "correct horse battery"}};
  auto r = http_call(s.port, "POST", "/api/v1/auth/register", good.dump());
  ASSERT_EQ(r.status, 201) << r.body;
  EXPECT_TRUE(contracts::violations("api_user", r.doc()).empty()) << r.body;
  EXPECT_EQ(r.body.find("argon2"), std::string::npos);
  expect_error(http_call(s.port, "POST", "/api/v1/auth/register", good.dump()), 409, "conflict");
  expect_error(http_call(s.port, "POST", "/api/v1/auth/register",
                         json{{"email", "a@example.com"}, {"password", "short"}}.dump()),
               400, "weak_password");
  expect_error(http_call(s.port, "POST", "/api/v1/auth/register",
                         json{{"email", "longname@example.com"}, {"password", "xxlongnamexx"}}.dump()),
               400, "weak_password");
  // The hash is Argon2id in the database.
  EXPECT_EQ(s.storage.find_user("pilot@example.com")->password_hash.rfind("$argon2id$", 0), 0u);

  r = http_call(s.port, "POST", "/api/v1/auth/login", good.dump());
  ASSERT_EQ(r.status, 200) << r.body;
  EXPECT_TRUE(contracts::violations("api_login_response", r.doc()).empty()) << r.body;
  EXPECT_LE(r.doc()["expires_in_s"].get<int>(), 1800);
  const auto token = r.doc()["token"].get<std::string>();
  EXPECT_EQ(http_call(s.port, "GET", "/api/v1/config", "", token).status, 200);

  expect_error(http_call(s.port, "GET", "/api/v1/config"), 401, "unauthorized");
  expect_error(http_call(s.port, "GET", "/api/v1/config", "", token + "x"), 401, "unauthorized");
  expect_error(http_call(s.port, "GET", "/api/v1/config", "", "a.b.c"), 401, "unauthorized");

  EXPECT_EQ(http_call(s.port, "POST", "/api/v1/auth/logout", "", token).status, 204);
  expect_error(http_call(s.port, "GET", "/api/v1/config", "", token), 401, "token_revoked");
  EXPECT_TRUE(s.storage.is_token_revoked(
      [&] { TokenClaims c; s.tokens.verify(token, c); return c.jti; }()));
}

TEST(ServerAuth, TokensExpireOnTheClock) {
  TestServer s;
  const auto token = s.register_and_login();
  EXPECT_EQ(http_call(s.port, "GET", "/api/v1/sessions", "", token).status, 200);
  s.clock.advance(29min);
  EXPECT_EQ(http_call(s.port, "GET", "/api/v1/sessions", "", token).status, 200);
  s.clock.advance(61s);
  expect_error(http_call(s.port, "GET", "/api/v1/sessions", "", token), 401, "token_expired");
}

TEST(ServerAuth, LoginBacksOffAfterRepeatedFailures) {
  TestServer s;
  s.register_and_login("target@example.com", "the real password!");
  const json bad = {{"email", "target@example.com"}, {"password", "guess guess guess"}};
  for (int i = 0; i < 5; ++i) {
    expect_error(http_call(s.port, "POST", "/api/v1/auth/login", bad.dump()), 401,
                 "invalid_credentials");
  }
  auto r = http_call(s.port, "POST", "/api/v1/auth/login", bad.dump());
  expect_error(r, 429, "rate_limited");
  ASSERT_TRUE(r.headers.count("Retry-After"));
  EXPECT_GE(std::stoi(r.headers["Retry-After"]), 1);
  // Even the right password waits out the back-off, then works.
  const json good = {{"email", "target@example.com"}, {"password", "the real password!"}};
  expect_error(http_call(s.port, "POST", "/api/v1/auth/login", good.dump()), 429, "rate_limited");
  s.clock.advance(std::chrono::seconds(std::stoi(r.headers["Retry-After"]) + 1));
  EXPECT_EQ(http_call(s.port, "POST", "/api/v1/auth/login", good.dump()).status, 200);
}

TEST(ServerHostile, MalformedWrongTypesHugeAndSqlMetacharacters) {
  TestServer s;
  expect_error(http_call(s.port, "POST", "/api/v1/auth/login", "{\"email\": "), 400, "malformed_json");
  expect_error(http_call(s.port, "POST", "/api/v1/auth/login", "[1,2,3]"), 400, "invalid_body");
  auto r = http_call(s.port, "POST", "/api/v1/auth/login",
                     json{{"email", 42}, {"password", true}}.dump());
  expect_error(r, 400, "invalid_body");
  EXPECT_FALSE(r.doc().value("field", "").empty());
  expect_error(http_call(s.port, "POST", "/api/v1/auth/login", "email=a", "", "text/plain"), 415,
               "unsupported_media_type");
  // A 10 MB body is refused from its declared length, before the server reads any of it.
  expect_error(raw_call(s.port, "POST /api/v1/auth/register HTTP/1.1\r\nHost: x\r\n"
                                "Content-Type: application/json\r\nContent-Length: 10485760\r\n\r\n"),
               413, "body_too_large");
  // The server still answers after all that.
  const std::string evil = "robert');DROP/**/TABLE/**/users;--@example.com";
  const auto token = s.register_and_login(evil, "a perfectly fine password");
  ASSERT_FALSE(token.empty());
  EXPECT_TRUE(s.storage.find_user(evil).has_value());
  expect_error(http_call(s.port, "GET", "/api/v1/sessions/1;DROP%20TABLE%20sessions", "", token),
               400, "invalid_parameter");
  expect_error(http_call(s.port, "GET", "/api/v1/sessions?limit=1%20OR%201=1", "", token), 400,
               "invalid_parameter");
  expect_error(http_call(s.port, "GET", "/api/v1/sessions/999999", "", token), 404, "not_found");
  EXPECT_EQ(http_call(s.port, "GET", "/api/v1/sessions", "", token).status, 200);
  r = http_call(s.port, "DELETE", "/api/v1/sessions", "", token);
  expect_error(r, 405, "method_not_allowed");
  EXPECT_EQ(r.headers["Allow"], "GET");
  expect_error(http_call(s.port, "GET", "/api/v1/nope"), 404, "not_found");
}

TEST(ServerRoutes, ConfigSessionsTelemetryEmergencyHealthMetrics) {
  TestServer s;
  const auto token = s.register_and_login();
  ASSERT_EQ(s.drone->connect("dummy", json::object()), "");
  const auto first_session = *s.drone->session_id();

  auto r = http_call(s.port, "GET", "/api/v1/config", "", token);
  ASSERT_EQ(r.status, 200);
  EXPECT_TRUE(contracts::violations("api_config", r.doc()).empty()) << r.body;
  EXPECT_EQ(r.doc()["adapter"]["name"], "dummy");

  r = http_call(s.port, "PUT", "/api/v1/config", json{{"theme", "dark"}}.dump(), token);
  ASSERT_EQ(r.status, 200) << r.body;
  EXPECT_EQ(r.doc()["theme"], "dark");
  expect_error(http_call(s.port, "PUT", "/api/v1/config", json::object().dump(), token), 400,
               "invalid_body");
  expect_error(http_call(s.port, "PUT", "/api/v1/config",
                         json{{"adapter", {{"name", "warp_drive"}, {"options", json::object()}}}}.dump(),
                         token),
               400, "invalid_body");

  // Bad options for a known adapter: 400 naming them, and nothing changes — the connected
  // drone and its session stay, nothing is stored for the next start, the theme is not set.
  r = http_call(s.port, "PUT", "/api/v1/config",
                json{{"theme", "light"},
                     {"adapter", {{"name", "tello"}, {"options", {{"port", 1}}}}}}.dump(), token);
  expect_error(r, 400, "invalid_body");
  EXPECT_EQ(r.doc()["field"], "adapter.options");
  EXPECT_NE(r.doc()["cause"].get<std::string>().find("'port' is not a known option"), std::string::npos)
      << r.body;
  EXPECT_EQ(s.drone->adapter_name(), "dummy");
  EXPECT_EQ(s.drone->session_id(), first_session);
  EXPECT_FALSE(s.storage.get_session(first_session)->ended_at.has_value());
  EXPECT_FALSE(s.storage.get_config("adapter").has_value());
  EXPECT_EQ(http_call(s.port, "GET", "/api/v1/config", "", token).doc()["theme"], "dark");

  // Adapter swap: the old session ends, a new one opens.
  r = http_call(s.port, "PUT", "/api/v1/config",
                json{{"adapter", {{"name", "dummy"}, {"options", json::object()}}}}.dump(), token);
  ASSERT_EQ(r.status, 200) << r.body;
  const auto second_session = *s.drone->session_id();
  EXPECT_NE(first_session, second_session);
  EXPECT_TRUE(s.storage.get_session(first_session)->ended_at.has_value());
  EXPECT_FALSE(s.storage.get_session(second_session)->ended_at.has_value());

  // Telemetry flows on the manual clock.
  for (int i = 0; i < 20; ++i) {
    s.clock.advance(100ms);
    s.drone->submit({});  // HOVER from the API keeps the loop busy; refused or not, it is logged
  }
  r = http_call(s.port, "GET", "/api/v1/sessions", "", token);
  ASSERT_EQ(r.status, 200);
  EXPECT_TRUE(contracts::violations("api_session_list", r.doc()).empty()) << r.body;
  EXPECT_GE(r.doc()["total"].get<int>(), 2);
  r = http_call(s.port, "GET", "/api/v1/sessions/" + std::to_string(second_session), "", token);
  ASSERT_EQ(r.status, 200);
  EXPECT_TRUE(contracts::violations("api_session_detail", r.doc()).empty()) << r.body;
  r = http_call(s.port, "GET", "/api/v1/sessions/" + std::to_string(second_session) + "/telemetry?limit=5", "", token);
  ASSERT_EQ(r.status, 200);
  EXPECT_TRUE(contracts::violations("api_telemetry_history", r.doc()).empty()) << r.body;

  r = http_call(s.port, "POST", "/api/v1/control/emergency-stop", "", token);
  ASSERT_EQ(r.status, 200) << r.body;
  EXPECT_TRUE(contracts::violations("api_control_state", r.doc()).empty()) << r.body;
  EXPECT_TRUE(r.doc()["emergency_latched"].get<bool>());
  r = http_call(s.port, "POST", "/api/v1/control/emergency-reset", "", token);
  ASSERT_EQ(r.status, 200) << r.body;
  EXPECT_FALSE(r.doc()["emergency_latched"].get<bool>());
  auto cmds = s.storage.commands(second_session);
  EXPECT_TRUE(std::any_of(cmds.begin(), cmds.end(), [](const storage::CommandRecord& c) {
    return c.command.type == contracts::CommandType::kEmergencyStop && c.command.source == contracts::CommandSource::kApi;
  }));

  r = http_call(s.port, "GET", "/api/v1/healthz");
  ASSERT_EQ(r.status, 200);
  EXPECT_TRUE(contracts::violations("api_health", r.doc()).empty()) << r.body;
  EXPECT_EQ(r.doc()["status"], "ok");
  r = http_call(s.port, "GET", "/metrics");
  ASSERT_EQ(r.status, 200);
  EXPECT_NE(r.body.find("gbdcs_http_requests_total{status=\"200\"}"), std::string::npos);
  EXPECT_NE(r.body.find("gbdcs_ws_clients"), std::string::npos);
  EXPECT_EQ(r.headers["Content-Type"].rfind("text/plain", 0), 0u);
}

TEST(ServerRoutes, OpenApiDocumentListsExactlyTheRoutes) {
  TestServer s;
  auto r = http_call(s.port, "GET", "/api/v1/openapi.json");
  ASSERT_EQ(r.status, 200);
  auto doc = r.doc();
  EXPECT_EQ(doc["openapi"].get<std::string>().rfind("3.", 0), 0u);
  std::set<std::pair<std::string, std::string>> documented, served;
  for (const auto& [path, ops] : doc["paths"].items()) {
    for (const auto& [method, op] : ops.items()) {
      std::string m = method;
      std::transform(m.begin(), m.end(), m.begin(), ::toupper);
      documented.insert({m, path});
    }
  }
  for (const auto& rt : api_routes()) served.insert(rt);
  EXPECT_EQ(documented, served);
  // Every schema it names exists.
  std::regex ref(R"(schemas/([a-z_]+)\.schema\.json)");
  const auto names = contracts::schema_names();
  for (std::sregex_iterator it(r.body.begin(), r.body.end(), ref), end; it != end; ++it) {
    EXPECT_NE(std::find(names.begin(), names.end(), (*it)[1].str()), names.end()) << (*it)[1];
  }
}

TEST(ServerStatic, PlaceholderMimeTypesAndNoTraversal) {
  {
    TestServer s;
    auto r = http_call(s.port, "GET", "/");
    ASSERT_EQ(r.status, 200);
    EXPECT_NE(r.body.find("npm run build"), std::string::npos);
  }
  TempDir web;
  std::filesystem::create_directories(web.path() / "dist/assets");
  std::ofstream(web.path() / "dist/index.html") << "<html>app</html>";
  std::ofstream(web.path() / "dist/assets/app.js") << "console.log(1)";
  std::ofstream(web.path() / "dist/assets/app.css") << "body{}";
  std::ofstream(web.path() / "secret.txt") << "do not serve";
  TestServer s({}, (web.path() / "dist").string());
  auto r = http_call(s.port, "GET", "/");
  EXPECT_EQ(r.body, "<html>app</html>");
  EXPECT_EQ(r.headers["Content-Type"], "text/html; charset=utf-8");
  EXPECT_EQ(http_call(s.port, "GET", "/assets/app.js").headers["Content-Type"],
            "text/javascript; charset=utf-8");
  EXPECT_EQ(http_call(s.port, "GET", "/assets/app.css").headers["Content-Type"],
            "text/css; charset=utf-8");
  EXPECT_EQ(http_call(s.port, "GET", "/sessions/3").body, "<html>app</html>");  // client route
  expect_error(http_call(s.port, "GET", "/assets/missing.js"), 404, "not_found");
  for (const char* evil : {"/../secret.txt", "/assets/../../secret.txt", "/%2e%2e/secret.txt",
                           "/..%2fsecret.txt", "/assets/..%5c..%5csecret.txt"}) {
    auto e = http_call(s.port, "GET", evil);
    EXPECT_EQ(e.status, 404) << evil;
    EXPECT_EQ(e.body.find("do not serve"), std::string::npos) << evil;
  }
  expect_error(http_call(s.port, "POST", "/index.html", "{}"), 405, "method_not_allowed");
}

}  // namespace
}  // namespace gbdcs::server::testing
