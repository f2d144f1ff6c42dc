// The REST routes of /api/v1 (docs/API.md). Each handler validates its body against its
// schema, does its work and answers JSON; errors are thrown as ApiError.
#include <algorithm>
#include <charconv>

#include "api.hpp"
#include "gbdcs/contracts/codec.hpp"

namespace gbdcs::server {

namespace embedded {
std::vector<std::pair<std::string_view, std::string_view>> embedded_files();
}

using nlohmann::json;

namespace {

const std::string kPrefix = "/api/v1";

json body_of(const ApiRequest& r, std::string_view schema, bool optional = false) {
  if (r.body.empty() && optional) return json::object();
  if (!r.body.empty() && r.content_type.find("application/json") == std::string::npos) {
    throw ApiError(415, "unsupported_media_type",
                   "the body is sent as '" + r.content_type + "', not JSON",
                   "send Content-Type: application/json");
  }
  json doc;
  try {
    doc = contracts::parse_json(r.body);
  } catch (const contracts::ContractError& e) {
    throw ApiError(400, "malformed_json", e.what(), "send one well-formed JSON object");
  }
  try {
    contracts::validate(schema, doc);
  } catch (const contracts::ContractError& e) {
    throw ApiError(400, "invalid_body", e.what(),
                   "send a JSON object matching core/contracts/schemas/" + std::string(schema) +
                       ".schema.json (docs/API.md)",
                   e.field());
  }
  return doc;
}

std::int64_t parse_int(const std::string& text, const std::string& what, std::int64_t lo,
                       std::int64_t hi) {
  std::int64_t v = 0;
  auto [p, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (ec != std::errc() || p != text.data() + text.size() || v < lo || v > hi) {
    throw ApiError(400, "invalid_parameter",
                   what + " is '" + text.substr(0, 40) + "', not a whole number from " +
                       std::to_string(lo) + " to " + std::to_string(hi),
                   "pass " + what + " as a whole number in range", what);
  }
  return v;
}

std::string bearer(const ApiRequest& r) {
  const std::string_view h = r.authorization;
  if (h.size() > 7 && (h.substr(0, 7) == "Bearer " || h.substr(0, 7) == "bearer "))
    return std::string(h.substr(7));
  return {};
}

json user_json(const storage::UserRecord& u) {
  return {{"id", u.id}, {"email", u.username}, {"theme", u.theme == "dark" ? "dark" : "light"},
          {"created_at", contracts::format_utc(u.created_at)}};
}

json summary_json(const storage::SessionSummary& s) {
  return {{"id", s.id},
          {"user_id", s.user_id ? json(*s.user_id) : json(nullptr)},
          {"drone", s.drone},
          {"profile", s.profile},
          {"started_at", contracts::format_utc(s.started_at)},
          {"ended_at", s.ended_at ? json(contracts::format_utc(*s.ended_at)) : json(nullptr)},
          {"open", !s.ended_at.has_value()},
          {"duration_s", std::max(0.0, s.duration_s)},
          {"command_count", s.command_count},
          {"alert_count", s.alert_count}};
}

ApiResponse ok(const json& body, int status = 200) {
  ApiResponse r;
  r.status = status;
  r.body = body.dump(-1, ' ', false, json::error_handler_t::replace);
  return r;
}

storage::SessionSummary session_or_404(ApiContext& ctx, std::int64_t id) {
  auto s = ctx.storage.get_session(id);
  if (!s) {
    throw ApiError(404, "not_found", "there is no session " + std::to_string(id),
                   "list the sessions with GET /api/v1/sessions");
  }
  return *s;
}

json config_json(ApiContext& ctx, const TokenClaims& who) {
  auto user = ctx.storage.find_user_by_id(who.user_id);
  return {{"profile", ctx.drone.profile().to_json()},
          {"theme", user && user->theme == "dark" ? "dark" : "light"},
          {"adapter", {{"name", ctx.drone.adapter_name()}, {"options", ctx.drone.adapter_options()}}},
          {"adapters_available", ctx.options.adapters_available},
          {"source", ctx.options.source}};
}

// ---- handlers ---------------------------------------------------------------------------

ApiResponse do_register(ApiContext& ctx, const ApiRequest& r) {
  auto body = body_of(r, "api_register_request");
  const auto email = body["email"].get<std::string>();
  const auto password = body["password"].get<std::string>();
  if (auto why = check_password_strength(email, password); !why.empty()) {
    throw ApiError(400, "weak_password", why,
                   "choose a password of at least 10 characters that is not your e-mail address",
                   "password");
  }
  auto id = ctx.storage.create_user(email, hash_password(password));
  if (!id) {
    throw ApiError(409, "conflict", "the e-mail " + email + " is already registered",
                   "log in with POST /api/v1/auth/login, or register another address", "email");
  }
  if (ctx.log) ctx.log("info", {{"event", "user_registered"}, {"user_id", *id}});
  return ok(user_json(*ctx.storage.find_user_by_id(*id)), 201);
}

ApiResponse do_login(ApiContext& ctx, const ApiRequest& r) {
  auto body = body_of(r, "api_login_request");
  auto email = body["email"].get<std::string>();
  std::transform(email.begin(), email.end(), email.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  const std::string by_addr = "addr:" + r.remote;
  const std::string by_email = "email:" + email;
  const double wait = std::max(ctx.limiter.retry_after_s(by_addr), ctx.limiter.retry_after_s(by_email));
  if (wait > 0) {
    ApiError e(429, "rate_limited",
               "too many failed logins from this address or for this e-mail",
               "wait " + std::to_string(static_cast<int>(wait + 0.999)) +
                   " s (Retry-After) before trying again");
    e.headers.emplace_back("Retry-After", std::to_string(static_cast<int>(wait + 0.999)));
    if (ctx.log) ctx.log("warn", {{"event", "login_rate_limited"}, {"remote", r.remote}});
    throw e;
  }
  auto user = ctx.storage.find_user(email);
  if (!user || !verify_password(user->password_hash, body["password"].get<std::string>())) {
    ctx.limiter.record_failure(by_addr);
    ctx.limiter.record_failure(by_email);
    if (ctx.log) ctx.log("warn", {{"event", "login_failed"}, {"remote", r.remote}});
    throw ApiError(401, "invalid_credentials", "the e-mail or the password is wrong",
                   "check both; register with POST /api/v1/auth/register if you have no account");
  }
  ctx.limiter.record_success(by_email);
  auto issued = ctx.tokens.issue(user->id, user->username);
  if (ctx.log) ctx.log("info", {{"event", "login"}, {"user_id", user->id}, {"jti", issued.claims.jti}});
  return ok({{"token", issued.token},
             {"token_type", "Bearer"},
             {"expires_at", contracts::format_utc(issued.claims.expires_at)},
             {"expires_in_s", ctx.tokens.ttl_s()},
             {"user", user_json(*user)}});
}

ApiResponse do_logout(ApiContext& ctx, const ApiRequest& r) {
  auto who = authenticate(ctx, bearer(r));
  ctx.storage.revoke_token(who.jti, who.user_id, who.expires_at);
  ctx.hub.close_token(who.jti, "logged out");
  if (ctx.log) ctx.log("info", {{"event", "logout"}, {"user_id", who.user_id}, {"jti", who.jti}});
  ApiResponse resp;
  resp.status = 204;
  return resp;
}

ApiResponse do_put_config(ApiContext& ctx, const ApiRequest& r, const TokenClaims& who) {
  auto body = body_of(r, "api_config_update");
  std::optional<control::GestureProfile> profile;
  if (body.contains("profile")) {
    try {
      profile = control::GestureProfile::from_json(body["profile"]);
    } catch (const std::exception& e) {
      throw ApiError(400, "invalid_body", e.what(), "fix the profile (docs/GESTURES.md)", "profile");
    }
  }
  if (body.contains("adapter")) {
    const auto name = body["adapter"]["name"].get<std::string>();
    const auto& avail = ctx.options.adapters_available;
    if (!avail.empty() && std::find(avail.begin(), avail.end(), name) == avail.end()) {
      std::string list;
      for (const auto& a : avail) list += (list.empty() ? "" : ", ") + a;
      throw ApiError(400, "invalid_body", "there is no drone adapter '" + name + "'",
                     "choose one of: " + list, "adapter.name");
    }
    // Bad options are refused before anything changes: the connected drone stays, and nothing
    // is stored for the next start.
    if (auto bad = ctx.drone.check_adapter(name, body["adapter"]["options"]); !bad.empty()) {
      throw ApiError(400, "invalid_body", bad,
                     "fix the adapter's options (docs/ADAPTERS.md lists each adapter's)",
                     "adapter.options");
    }
  }
  if (body.contains("theme")) {
    ctx.storage.set_user_theme(who.user_id, body["theme"].get<std::string>());
  }
  if (profile) {
    ctx.drone.set_profile(*profile);
    ctx.storage.put_config("profile", profile->to_json());
    if (ctx.log) ctx.log("info", {{"event", "profile_changed"}, {"user_id", who.user_id},
                                  {"profile", profile->name}});
  }
  if (body.contains("adapter")) {
    const auto name = body["adapter"]["name"].get<std::string>();
    const auto options = body["adapter"]["options"];
    if (ctx.log) ctx.log("warn", {{"event", "adapter_swap"}, {"user_id", who.user_id},
                                  {"from", ctx.drone.adapter_name()}, {"to", name}});
    ctx.storage.put_config("adapter", {{"name", name}, {"options", options}});
    if (auto error = ctx.drone.connect(name, options); !error.empty()) {
      throw ApiError(500, "adapter_failed", error,
                     "check the drone is on and reachable and the options (docs/ADAPTERS.md), "
                     "then PUT /api/v1/config again");
    }
  }
  return ok(config_json(ctx, who));
}

ApiResponse do_sessions(ApiContext& ctx, const ApiRequest& r) {
  std::int64_t limit = 50, offset = 0;
  if (auto it = r.query.find("limit"); it != r.query.end())
    limit = parse_int(it->second, "limit", 1, 500);
  if (auto it = r.query.find("offset"); it != r.query.end())
    offset = parse_int(it->second, "offset", 0, 1'000'000'000);
  json list = json::array();
  for (const auto& s : ctx.storage.list_sessions(limit, offset)) list.push_back(summary_json(s));
  return ok({{"sessions", list},
             {"total", ctx.storage.session_count()},
             {"limit", limit},
             {"offset", offset}});
}

ApiResponse do_session(ApiContext& ctx, std::int64_t id) {
  auto s = session_or_404(ctx, id);
  json gestures = json::array(), commands = json::array(), alerts = json::array();
  for (const auto& g : ctx.storage.gestures(id)) gestures.push_back(contracts::to_json(g));
  for (const auto& c : ctx.storage.commands(id)) {
    commands.push_back({{"command", contracts::to_json(c.command)},
                        {"outcome", c.result},
                        {"recorded_at", contracts::format_utc(c.recorded_at)}});
  }
  for (const auto& a : ctx.storage.alerts(id)) {
    alerts.push_back({{"alert", contracts::to_json(a.alert)},
                      {"acknowledged_at", a.acknowledged_at
                                              ? json(contracts::format_utc(*a.acknowledged_at))
                                              : json(nullptr)}});
  }
  return ok({{"session", summary_json(s)},
             {"gestures", gestures},
             {"commands", commands},
             {"alerts", alerts}});
}

ApiResponse do_telemetry(ApiContext& ctx, const ApiRequest& r, std::int64_t id) {
  session_or_404(ctx, id);
  std::optional<std::int64_t> limit;
  if (auto it = r.query.find("limit"); it != r.query.end())
    limit = parse_int(it->second, "limit", 1, 100000);
  json frames = json::array();
  for (const auto& f : ctx.storage.telemetry(id, limit)) frames.push_back(contracts::to_json(f));
  return ok({{"session_id", id}, {"count", frames.size()}, {"frames", frames}});
}

ApiResponse do_replay(ApiContext& ctx, const ApiRequest& r, std::int64_t id) {
  session_or_404(ctx, id);
  auto body = body_of(r, "api_replay_request", true);
  const double speed = body.value("speed", 1.0);
  auto info = ctx.replays.start(id, speed);
  if (!info) {
    throw ApiError(409, "conflict", "session " + std::to_string(id) + " is already replaying",
                   "wait for the state message with data.replay.finished, then ask again");
  }
  if (ctx.log) ctx.log("info", {{"event", "replay"}, {"session_id", id}, {"speed", speed},
                                {"replay_id", info->replay_id}});
  return ok({{"replay_id", info->replay_id},
             {"session_id", id},
             {"speed", speed},
             {"messages", info->messages},
             {"duration_s", info->duration_s}},
            202);
}

ApiResponse do_ack(ApiContext& ctx, std::int64_t alert_id, const TokenClaims& who) {
  if (!ctx.storage.acknowledge_alert_by(alert_id, who.user_id)) {
    throw ApiError(404, "not_found", "there is no alert " + std::to_string(alert_id),
                   "acknowledge the id of an alert message (data.id)");
  }
  auto a = ctx.storage.find_alert(alert_id);
  if (ctx.log) ctx.log("info", {{"event", "alert_ack"}, {"alert_id", alert_id}, {"user_id", who.user_id}});
  return ok({{"alert_id", alert_id},
             {"acknowledged_at", contracts::format_utc(a && a->acknowledged_at ? *a->acknowledged_at
                                                                               : ctx.clock.utc_now())}});
}

ApiResponse do_estop(ApiContext& ctx, const ApiRequest& r, const TokenClaims& who) {
  auto body = body_of(r, "api_emergency_stop_request", true);
  auto d = ctx.drone.emergency_stop(contracts::CommandSource::kApi,
                                    "user:" + std::to_string(who.user_id));
  return ok({{"accepted", d.accepted},
             {"outcome", d.accepted ? "OK" : d.reason},
             {"emergency_latched", ctx.drone.emergency_latched()},
             {"command_id", d.accepted ? json(d.command.id) : json(nullptr)}});
}

ApiResponse do_ereset(ApiContext& ctx) {
  ctx.drone.reset_emergency();
  return ok({{"accepted", true},
             {"outcome", "OK"},
             {"emergency_latched", ctx.drone.emergency_latched()},
             {"command_id", nullptr}});
}

ApiResponse do_health(ApiContext& ctx) {
  bool db_ok = true;
  try {
    ctx.storage.session_count();
  } catch (const std::exception&) {
    db_ok = false;
  }
  auto drone = ctx.drone.state();
  const auto writes = ctx.storage.write_health();
  const bool good = db_ok && writes.ok && drone.value("connected", false);
  json db = {{"ok", db_ok},
             {"path", ctx.storage.path()},
             {"write_failures", ctx.storage.write_failures()},
             {"writable", writes.ok}};
  if (!writes.ok) {
    db["disk_full"] = writes.disk_full;
    db["error"] = writes.error;
    db["suggestion"] = writes.suggestion.empty()
                           ? "check the server log for the cause of the failing writes"
                           : writes.suggestion;
  }
  return ok({{"status", good ? "ok" : "degraded"},
             {"version", ctx.options.version},
             {"uptime_s", contracts::to_seconds(ctx.clock.now() - ctx.started)},
             {"db", db},
             {"drone", drone}});
}

std::vector<std::string> split_path(const std::string& path) {
  std::vector<std::string> parts;
  std::size_t i = 0;
  while (i < path.size()) {
    auto j = path.find('/', i);
    if (j == std::string::npos) j = path.size();
    if (j > i) parts.push_back(path.substr(i, j - i));
    i = j + 1;
  }
  return parts;
}

[[noreturn]] void method_not_allowed(const std::string& allowed) {
  ApiError e(405, "method_not_allowed", "this route does not take that method",
             "use " + allowed);
  e.headers.emplace_back("Allow", allowed);
  throw e;
}

}  // namespace

ApiResponse error_response(const ApiError& e, const std::string& request_id) {
  json body = {{"error", e.code}, {"cause", e.cause}, {"suggestion", e.suggestion},
               {"request_id", request_id}};
  if (!e.field.empty()) body["field"] = e.field;
  ApiResponse r;
  r.status = e.status;
  r.body = body.dump(-1, ' ', false, json::error_handler_t::replace);
  r.headers = e.headers;
  r.log_detail = e.cause;
  return r;
}

TokenClaims authenticate(ApiContext& ctx, std::string_view token) {
  TokenClaims claims;
  switch (ctx.tokens.verify(token, claims)) {
    case TokenError::kNone:
      break;
    case TokenError::kMissing:
      throw ApiError(401, "unauthorized", "no token was sent",
                     "log in (POST /api/v1/auth/login) and send Authorization: Bearer <token>");
    case TokenError::kExpired:
      throw ApiError(401, "token_expired", "the token has expired", "log in again");
    case TokenError::kMalformed:
    case TokenError::kBadSignature:
      throw ApiError(401, "unauthorized", "the token is not one this server issued",
                     "log in again (tokens do not survive a server restart without "
                     "GBDCS_JWT_SECRET)");
  }
  if (ctx.storage.is_token_revoked(claims.jti)) {
    throw ApiError(401, "token_revoked", "the token was logged out", "log in again");
  }
  return claims;
}

std::vector<std::pair<std::string, std::string>> api_routes() {
  return {{"POST", "/api/v1/auth/register"},     {"POST", "/api/v1/auth/login"},
          {"POST", "/api/v1/auth/logout"},       {"GET", "/api/v1/config"},
          {"PUT", "/api/v1/config"},             {"GET", "/api/v1/sessions"},
          {"GET", "/api/v1/sessions/{id}"},      {"GET", "/api/v1/sessions/{id}/telemetry"},
          {"POST", "/api/v1/sessions/{id}/replay"}, {"POST", "/api/v1/alerts/{id}/ack"},
          {"POST", "/api/v1/control/emergency-stop"}, {"POST", "/api/v1/control/emergency-reset"},
          {"GET", "/api/v1/openapi.json"},       {"GET", "/api/v1/healthz"},
          {"GET", "/api/v1/metrics"}};
}

std::string_view openapi_document() {
  for (const auto& [name, text] : embedded::embedded_files()) {
    if (name == "openapi.json") return text;
  }
  return "{}";
}

ApiResponse handle_api(ApiContext& ctx, const ApiRequest& r) {
  const auto parts = split_path(r.path);  // "api", "v1", ...
  const std::string& m = r.method;
  auto is = [&](std::initializer_list<const char*> want) {
    if (parts.size() != want.size() + 2) return false;
    std::size_t i = 2;
    for (const char* w : want) {
      if (std::string_view(w) != "*" && parts[i] != w) return false;
      ++i;
    }
    return true;
  };
  auto id_at = [&](std::size_t i) { return parse_int(parts[i], "id", 1, INT64_MAX); };
  auto need = [&](const char* method) {
    if (m != method) method_not_allowed(method);
  };

  if (is({"auth", "register"})) { need("POST"); return do_register(ctx, r); }
  if (is({"auth", "login"})) { need("POST"); return do_login(ctx, r); }
  if (is({"auth", "logout"})) { need("POST"); return do_logout(ctx, r); }
  if (is({"healthz"})) { need("GET"); return do_health(ctx); }
  if (is({"openapi.json"})) {
    need("GET");
    ApiResponse resp;
    resp.body = std::string(openapi_document());
    return resp;
  }
  if (is({"metrics"})) {
    need("GET");
    ApiResponse resp;
    resp.body = ctx.metrics.render();
    resp.content_type = "text/plain; version=0.0.4";
    return resp;
  }
  const bool known = is({"config"}) || is({"sessions"}) || is({"sessions", "*"}) ||
                     is({"sessions", "*", "telemetry"}) || is({"sessions", "*", "replay"}) ||
                     is({"alerts", "*", "ack"}) || is({"control", "emergency-stop"}) ||
                     is({"control", "emergency-reset"});
  if (!known) {
    throw ApiError(404, "not_found", "there is no route " + m + " " + r.path.substr(0, 200),
                   "see GET /api/v1/openapi.json for the routes");
  }
  const auto who = authenticate(ctx, bearer(r));
  if (is({"config"})) {
    if (m == "GET") return ok(config_json(ctx, who));
    if (m == "PUT") return do_put_config(ctx, r, who);
    method_not_allowed("GET, PUT");
  }
  if (is({"sessions"})) { need("GET"); return do_sessions(ctx, r); }
  if (is({"sessions", "*"})) { need("GET"); return do_session(ctx, id_at(3)); }
  if (is({"sessions", "*", "telemetry"})) { need("GET"); return do_telemetry(ctx, r, id_at(3)); }
  if (is({"sessions", "*", "replay"})) { need("POST"); return do_replay(ctx, r, id_at(3)); }
  if (is({"alerts", "*", "ack"})) { need("POST"); return do_ack(ctx, id_at(3), who); }
  if (is({"control", "emergency-stop"})) { need("POST"); return do_estop(ctx, r, who); }
  need("POST");
  return do_ereset(ctx);
}

}  // namespace gbdcs::server
