// to_json / from_json for every message. from_json validates against the schema first, so
// the conversions below can trust the shape of the document.
#include <cstdio>
#include <ctime>

#include "gbdcs/contracts/codec.hpp"

namespace gbdcs::contracts {

using nlohmann::json;

std::string format_utc(UtcTime t) {
  const auto ms_total = t.time_since_epoch().count();
  auto secs = static_cast<std::time_t>(ms_total / 1000);
  auto ms = static_cast<int>(ms_total % 1000);
  if (ms < 0) {
    ms += 1000;
    secs -= 1;
  }
  std::tm tm{};
  gmtime_r(&secs, &tm);
  char buf[64];
  std::snprintf(buf, sizeof buf, "%04d-%02d-%02dT%02d:%02d:%02d.%03dZ", tm.tm_year + 1900,
                tm.tm_mon + 1, tm.tm_mday, tm.tm_hour, tm.tm_min, tm.tm_sec, ms);
  return buf;
}

UtcTime parse_utc(std::string_view text) {
  std::tm tm{};
  int ms = 0;
  int consumed = 0;
  const std::string s(text);
  int n = std::sscanf(s.c_str(), "%4d-%2d-%2dT%2d:%2d:%2d%n", &tm.tm_year, &tm.tm_mon, &tm.tm_mday,
                      &tm.tm_hour, &tm.tm_min, &tm.tm_sec, &consumed);
  bool ok = n == 6;
  std::size_t pos = static_cast<std::size_t>(consumed);
  if (ok && pos < s.size() && s[pos] == '.') {
    int digits = 0;
    ++pos;
    while (pos < s.size() && s[pos] >= '0' && s[pos] <= '9' && digits < 3) {
      ms = ms * 10 + (s[pos] - '0');
      ++pos;
      ++digits;
    }
    for (; digits < 3 && digits > 0; ++digits) ms *= 10;
  }
  ok = ok && pos + 1 == s.size() && s[pos] == 'Z' && tm.tm_mon >= 1 && tm.tm_mon <= 12 &&
       tm.tm_mday >= 1 && tm.tm_mday <= 31 && tm.tm_hour < 24 && tm.tm_min < 60 && tm.tm_sec < 61;
  if (!ok) {
    throw ContractError("timestamp", "timestamp '" + s +
                                         "' is not UTC ISO 8601 (write it as "
                                         "2026-11-23T08:30:00.123Z)");
  }
  tm.tm_year -= 1900;
  tm.tm_mon -= 1;
  const auto secs = timegm(&tm);
  return UtcTime{std::chrono::milliseconds{static_cast<std::int64_t>(secs) * 1000 + ms}};
}

namespace {

template <class E>
E enum_field(const json& doc, const char* key, std::optional<E> (*parse)(std::string_view)) {
  const auto text = doc.at(key).get<std::string>();
  auto value = parse(text);
  if (!value) throw ContractError(key, std::string("unknown value '") + text + "' for " + key);
  return *value;
}

}  // namespace

json to_json(const Landmarks& m) {
  json points = json::array();
  for (const auto& p : m.points) points.push_back({p.x, p.y, p.z});
  return {{"points", points}, {"handedness", to_string(m.handedness)}, {"score", m.score}};
}

template <>
Landmarks from_json<Landmarks>(const json& doc) {
  validate("landmarks", doc);
  Landmarks m;
  const auto& points = doc.at("points");
  for (std::size_t i = 0; i < kLandmarkCount; ++i) {
    m.points[i] = {points[i][0].get<double>(), points[i][1].get<double>(),
                   points[i][2].get<double>()};
  }
  m.handedness = enum_field(doc, "handedness", &handedness_from_string);
  m.score = doc.at("score").get<double>();
  return m;
}

json to_json(const GestureEvent& m) {
  return {{"gesture", to_string(m.gesture)}, {"confidence", m.confidence},
          {"handedness", to_string(m.handedness)}, {"frame_id", m.frame_id},
          {"timestamp", format_utc(m.timestamp)}, {"repeat", m.repeat}};
}

template <>
GestureEvent from_json<GestureEvent>(const json& doc) {
  validate("gesture_event", doc);
  GestureEvent m;
  m.gesture = enum_field(doc, "gesture", &gesture_from_string);
  m.confidence = doc.at("confidence").get<double>();
  m.handedness = enum_field(doc, "handedness", &handedness_from_string);
  m.frame_id = doc.at("frame_id").get<std::int64_t>();
  m.timestamp = parse_utc(doc.at("timestamp").get<std::string>());
  m.repeat = doc.at("repeat").get<bool>();
  return m;
}

json to_json(const MotionPayload& m) {
  return {{"vx_m_s", m.vx_m_s}, {"vy_m_s", m.vy_m_s}, {"vz_m_s", m.vz_m_s},
          {"yaw_rate_deg_s", m.yaw_rate_deg_s}, {"duration_s", m.duration_s}};
}

namespace {
MotionPayload payload_from(const json& doc) {
  MotionPayload p;
  p.vx_m_s = doc.value("vx_m_s", 0.0);
  p.vy_m_s = doc.value("vy_m_s", 0.0);
  p.vz_m_s = doc.value("vz_m_s", 0.0);
  p.yaw_rate_deg_s = doc.value("yaw_rate_deg_s", 0.0);
  p.duration_s = doc.value("duration_s", 0.0);
  return p;
}
}  // namespace

MotionPayload motion_payload_from_json(const json& doc) { return payload_from(doc); }

json to_json(const DroneCommand& m) {
  json doc = {{"type", to_string(m.type)}, {"source", to_string(m.source)},
              {"source_id", m.source_id}, {"id", m.id}, {"issued_at", format_utc(m.issued_at)}};
  if (m.payload) doc["payload"] = to_json(*m.payload);
  return doc;
}

template <>
DroneCommand from_json<DroneCommand>(const json& doc) {
  validate("drone_command", doc);
  DroneCommand m;
  m.type = enum_field(doc, "type", &command_type_from_string);
  m.source = enum_field(doc, "source", &command_source_from_string);
  m.source_id = doc.value("source_id", std::string{});
  if (doc.contains("payload")) m.payload = payload_from(doc.at("payload"));
  m.id = doc.value("id", std::int64_t{0});
  if (doc.contains("issued_at")) m.issued_at = parse_utc(doc.at("issued_at").get<std::string>());
  return m;
}

json to_json(const TelemetryFrame& m) {
  return {{"timestamp", format_utc(m.timestamp)},
          {"altitude_m", m.altitude_m},
          {"speed_m_s", m.speed_m_s},
          {"vx_m_s", m.vx_m_s},
          {"vy_m_s", m.vy_m_s},
          {"vz_m_s", m.vz_m_s},
          {"x_m", m.x_m},
          {"y_m", m.y_m},
          {"heading_deg", m.heading_deg},
          {"battery_pct", m.battery_pct},
          {"flight_state", to_string(m.flight_state)},
          {"link", to_string(m.link)}};
}

template <>
TelemetryFrame from_json<TelemetryFrame>(const json& doc) {
  validate("telemetry_frame", doc);
  TelemetryFrame m;
  m.timestamp = parse_utc(doc.at("timestamp").get<std::string>());
  m.altitude_m = doc.at("altitude_m").get<double>();
  m.speed_m_s = doc.at("speed_m_s").get<double>();
  m.vx_m_s = doc.at("vx_m_s").get<double>();
  m.vy_m_s = doc.at("vy_m_s").get<double>();
  m.vz_m_s = doc.at("vz_m_s").get<double>();
  m.x_m = doc.at("x_m").get<double>();
  m.y_m = doc.at("y_m").get<double>();
  m.heading_deg = doc.at("heading_deg").get<double>();
  m.battery_pct = doc.at("battery_pct").get<double>();
  m.flight_state = enum_field(doc, "flight_state", &flight_state_from_string);
  m.link = enum_field(doc, "link", &link_state_from_string);
  return m;
}

json to_json(const Alert& m) {
  return {{"severity", to_string(m.severity)}, {"code", m.code},
          {"cause", m.cause},                  {"suggestion", m.suggestion},
          {"timestamp", format_utc(m.timestamp)}, {"id", m.id}};
}

template <>
Alert from_json<Alert>(const json& doc) {
  validate("alert", doc);
  Alert m;
  m.severity = enum_field(doc, "severity", &severity_from_string);
  m.code = doc.at("code").get<std::string>();
  m.cause = doc.at("cause").get<std::string>();
  m.suggestion = doc.at("suggestion").get<std::string>();
  m.timestamp = parse_utc(doc.at("timestamp").get<std::string>());
  m.id = doc.value("id", std::int64_t{0});
  return m;
}

}  // namespace gbdcs::contracts
