// Scenario::from_json: the strict loader (scenarios/schema.json says the same in JSON Schema;
// tests/scenario checks that the two agree on every file of the suite).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "gbdcs/contracts/codec.hpp"
#include "gbdcs/control/command_translator.hpp"
#include "gbdcs/control/keyboard_input.hpp"
#include "gbdcs/sim/gesture_timeline.hpp"
#include "gbdcs/sim/scenario.hpp"
#include "gbdcs/telemetry/failsafe_monitor.hpp"
#include "json_fields.hpp"

namespace gbdcs::sim {

using detail::Fields;
using detail::join;

namespace {

namespace fs = std::filesystem;

template <class Enum, std::size_t N>
std::vector<std::string> names_of(const std::array<std::pair<Enum, std::string_view>, N>& table) {
  std::vector<std::string> out;
  for (const auto& [e, n] : table) out.emplace_back(n);
  return out;
}

constexpr std::array<std::pair<DroneKind, std::string_view>, 5> kDrones{{
    {DroneKind::kTwin, "twin"},
    {DroneKind::kDummy, "dummy"},
    {DroneKind::kTelloEmulator, "tello-emulator"},
    {DroneKind::kAirsimEmulator, "airsim-emulator"},
    {DroneKind::kXflyEmulator, "xfly-emulator"},
}};

constexpr std::array<std::pair<EventType, std::string_view>, 9> kEvents{{
    {EventType::kLinkLoss, "link_loss"},
    {EventType::kTelemetryDelay, "telemetry_delay"},
    {EventType::kBatteryJump, "battery_jump"},
    {EventType::kWindGust, "wind_gust"},
    {EventType::kMotorFault, "motor_fault"},
    {EventType::kVisionCrash, "vision_crash"},
    {EventType::kVisionUnhealthy, "vision_unhealthy"},
    {EventType::kEmergencyStop, "emergency_stop"},
    {EventType::kKey, "key"},
}};

constexpr std::array<std::pair<CriterionType, std::string_view>, 10> kCriteria{{
    {CriterionType::kLatency, "latency"},
    {CriterionType::kRecognitionAccuracy, "recognition_accuracy"},
    {CriterionType::kFalsePositives, "false_positives"},
    {CriterionType::kFailsafe, "failsafe"},
    {CriterionType::kAlerts, "alerts"},
    {CriterionType::kCommandSequence, "command_sequence"},
    {CriterionType::kFinalState, "final_state"},
    {CriterionType::kMaxAltitude, "max_altitude"},
    {CriterionType::kNoCollision, "no_collision"},
    {CriterionType::kBatteryAbove, "battery_above"},
}};

template <class Enum, std::size_t N>
std::string_view name_in(const std::array<std::pair<Enum, std::string_view>, N>& table, Enum e) {
  for (const auto& [k, n] : table) {
    if (k == e) return n;
  }
  return "?";
}

template <class Enum, std::size_t N>
std::optional<Enum> find_in(const std::array<std::pair<Enum, std::string_view>, N>& table,
                            std::string_view s) {
  for (const auto& [k, n] : table) {
    if (n == s) return k;
  }
  return std::nullopt;
}

std::string read_text(const std::string& path, const std::string& what) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ScenarioError(what + ": cannot read '" + path + "' (check the path)");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

nlohmann::json read_json(const std::string& path, const std::string& what) {
  const auto text = read_text(path, what);
  try {
    return contracts::parse_json(text);
  } catch (const std::exception& e) {
    throw ScenarioError(what + ": '" + path + "' is not valid JSON: " + e.what());
  }
}

std::string resolve(const std::string& base_dir, const std::string& p) {
  fs::path path(p);
  if (path.is_absolute()) return path.lexically_normal().string();
  return (fs::path(base_dir) / path).lexically_normal().string();
}

DroneSpec read_drone(Fields& f) {
  DroneSpec d;
  const auto& v = f.get("drone");
  auto parse_kind = [&](const std::string& name, const std::string& key) {
    auto k = find_in(kDrones, name);
    if (!k) f.fail(key, "unknown drone '" + name + "'; use one of: " + join(names_of(kDrones)));
    return *k;
  };
  if (v.is_string()) {
    d.kind = parse_kind(v.get<std::string>(), "drone");
    return d;
  }
  Fields g(v, f.origin(), f.field("drone"));
  d.kind = parse_kind(g.string("type"), "drone.type");
  if (g.has("options")) {
    d.options = g.get("options");
    if (!d.options.is_object()) g.fail("options", "must be an object of the adapter's options");
  }
  g.finish("the drone");
  return d;
}

CameraSpec read_camera(Fields& f, const std::string& base_dir) {
  CameraSpec c;
  Fields g(f.get("camera"), f.origin(), f.field("camera"));
  const bool has_timeline = g.has("timeline");
  const bool has_timeline_file = g.has("timeline_file");
  const bool has_recipe = g.has("recipe");
  const bool has_video = g.has("video");
  const int kinds = int{has_timeline} + int{has_timeline_file} + int{has_recipe} + int{has_video};
  if (kinds != 1) {
    g.fail("", "give exactly one of timeline (inline), timeline_file, recipe or video");
  }
  if (has_timeline || has_timeline_file) {
    c.kind = CameraKind::kTimeline;
    if (has_timeline) {
      c.timeline = g.get("timeline");
    } else {
      c.path = resolve(base_dir, g.string("timeline_file"));
      c.timeline = read_json(c.path, g.origin() + ": " + g.field("timeline_file"));
    }
    try {
      (void)GestureTimeline::from_json(c.timeline);
    } catch (const std::exception& e) {
      g.fail(has_timeline ? "timeline" : "timeline_file", e.what());
    }
  } else if (has_recipe) {
    c.kind = CameraKind::kRecipe;
    c.path = resolve(base_dir, g.string("recipe"));
    if (!fs::exists(c.path)) g.fail("recipe", "no such file '" + c.path + "'");
  } else {
    c.kind = CameraKind::kRecorded;
    c.path = resolve(base_dir, g.string("video"));
    if (!fs::exists(c.path)) g.fail("video", "no such file '" + c.path + "'");
    c.labels_path = resolve(base_dir, g.string("labels"));
    if (!fs::exists(c.labels_path)) g.fail("labels", "no such file '" + c.labels_path + "'");
    c.fps = g.opt_number("fps", 1, 240).value_or(30);
  }
  if (c.kind != CameraKind::kRecorded) {
    if (g.has("labels")) g.fail("labels", "only a recorded video takes labels");
  }
  g.finish("the camera");
  return c;
}

nlohmann::json read_profile(Fields& f, const std::string& base_dir) {
  nlohmann::json doc;
  std::string key = "profile";
  if (!f.has("profile")) return control::GestureProfile::builtin_default().to_json();
  const auto& v = f.get("profile");
  if (v.is_string()) {
    const auto s = v.get<std::string>();
    if (s == "default") return control::GestureProfile::builtin_default().to_json();
    doc = read_json(resolve(base_dir, s), f.origin() + ": profile");
  } else if (v.is_object()) {
    doc = v;
  } else {
    f.fail(key, "must be \"default\", a profile file's path or a profile object");
  }
  try {
    (void)control::GestureProfile::from_json(doc);
  } catch (const std::exception& e) {
    f.fail(key, e.what());
  }
  return doc;
}

ScenarioEvent read_event(const nlohmann::json& v, const std::string& origin,
                         const std::string& path, double timeout_s) {
  Fields g(v, origin, path);
  ScenarioEvent e;
  const auto type = g.string("type");
  auto t = find_in(kEvents, type);
  if (!t) g.fail("type", "unknown event '" + type + "'; use one of: " + join(names_of(kEvents)));
  e.type = *t;
  e.at_s = g.number("at_s", 0, timeout_s);
  auto duration = [&](bool required) {
    if (required) {
      e.duration_s = g.number("duration_s", 0.001, 3600);
    } else {
      e.duration_s = g.opt_number("duration_s", 0.001, 3600).value_or(kForever);
    }
  };
  switch (e.type) {
    case EventType::kLinkLoss:
      duration(true);
      break;
    case EventType::kTelemetryDelay:
      duration(true);
      e.delay_ms = g.number("delay_ms", 0, 60000);
      e.jitter_ms = g.opt_number("jitter_ms", 0, 60000).value_or(0);
      break;
    case EventType::kBatteryJump:
      e.battery_pct = g.number("battery_pct", 0, 100);
      break;
    case EventType::kWindGust: {
      duration(true);
      const auto& force = g.get("force_n");
      if (!force.is_array() || force.size() != 3 ||
          !std::all_of(force.begin(), force.end(), [](const auto& x) { return x.is_number(); })) {
        g.fail("force_n", "must be [x, y, z] in newtons (x forward, y right, z up)");
      }
      for (int i = 0; i < 3; ++i) {
        e.force_n[static_cast<std::size_t>(i)] = force[static_cast<std::size_t>(i)].get<double>();
        if (std::abs(e.force_n[static_cast<std::size_t>(i)]) > 5) {
          g.fail("force_n", "a component above 5 N would throw an 80 g drone across the room; "
                            "use at most 5");
        }
      }
      break;
    }
    case EventType::kMotorFault:
      duration(false);
      e.motor = g.opt_int("motor", 0, 3).value_or(0);
      e.thrust_factor = g.number("thrust_factor", 0, 1);
      break;
    case EventType::kVisionCrash: {
      duration(false);
      const auto detect = g.opt_string("detect").value_or("exit");
      if (detect != "exit" && detect != "silence") {
        g.fail("detect", "use \"exit\" (the supervisor sees the worker die) or \"silence\" "
                         "(the worker hangs; only the missing frames tell)");
      }
      e.detected_at_exit = detect == "exit";
      break;
    }
    case EventType::kVisionUnhealthy:
      duration(false);
      e.reason = g.opt_string("reason").value_or("the camera reports a fault");
      break;
    case EventType::kEmergencyStop: {
      const auto source = g.opt_string("source").value_or("api");
      if (source != "api" && source != "keyboard") {
        g.fail("source", "use \"api\" (the dashboard's button) or \"keyboard\" (Space)");
      }
      e.source = source == "api" ? contracts::CommandSource::kApi
                                 : contracts::CommandSource::kKeyboard;
      break;
    }
    case EventType::kKey:
      e.key = g.string("key");
      if (!control::KeyboardInput{}.command_for(e.key)) {
        g.fail("key", "'" + e.key + "' means nothing to the keyboard input; use w a s d q e r f "
                      "t l h, an arrow key name or \" \" (docs/SAFETY.md)");
      }
      break;
  }
  g.finish("a " + type + " event");
  return e;
}

CommandPattern read_pattern(const nlohmann::json& v, const Fields& owner, const std::string& key) {
  CommandPattern p;
  auto type_of = [&](const std::string& s) {
    auto t = contracts::command_type_from_string(s);
    if (!t) {
      owner.fail(key, "unknown command '" + s +
                          "'; use TAKEOFF, LAND, HOVER, MOVE or EMERGENCY_STOP");
    }
    return *t;
  };
  if (v.is_string()) {
    std::string s = v.get<std::string>();
    if (auto eq = s.find('='); eq != std::string::npos) {
      p.outcome = s.substr(eq + 1);
      s = s.substr(0, eq);
    }
    if (auto colon = s.find(':'); colon != std::string::npos) {
      p.source_id = s.substr(colon + 1);
      s = s.substr(0, colon);
    }
    p.type = type_of(s);
  } else if (v.is_object()) {
    Fields g(v, owner.origin(), owner.field(key));
    p.type = type_of(g.string("command"));
    if (auto src = g.opt_string("source")) {
      p.source = contracts::command_source_from_string(*src);
      if (!p.source) {
        g.fail("source", "unknown source '" + *src +
                             "'; use gesture, keyboard, api, failsafe or scenario");
      }
    }
    p.source_id = g.opt_string("source_id").value_or("");
    p.outcome = g.opt_string("outcome").value_or("OK");
    g.finish("a command pattern");
  } else {
    owner.fail(key, "a command pattern is \"TYPE[:SOURCE_ID][=OUTCOME]\" or an object "
                    "{command, source, source_id, outcome}");
  }
  static const std::vector<std::string> kOutcomes = {"OK",       "REFUSED",       "DROPPED",
                                                     "REJECTED", "NOT_CONNECTED", "TIMEOUT",
                                                     "ERROR",    "UNSUPPORTED",   "any"};
  if (std::find(kOutcomes.begin(), kOutcomes.end(), p.outcome) == kOutcomes.end()) {
    owner.fail(key, "unknown outcome '" + p.outcome + "'; use one of: " + join(kOutcomes));
  }
  return p;
}

std::vector<CommandPattern> read_patterns(Fields& g, const std::string& key) {
  std::vector<CommandPattern> out;
  if (!g.has(key)) return out;
  const auto& v = g.get(key);
  if (!v.is_array()) g.fail(key, "must be an array of command patterns");
  for (std::size_t i = 0; i < v.size(); ++i) {
    out.push_back(read_pattern(v[i], g, key + "[" + std::to_string(i) + "]"));
  }
  return out;
}

// Reads success/acceptable thresholds: `key` (success) and `acceptable_key` (defaults to it).
void thresholds(Fields& g, Criterion& c, const std::string& key, const std::string& acceptable_key,
                double min, double max, bool higher_is_better, std::optional<double> dflt = {}) {
  c.success = dflt && !g.has(key) ? *dflt : g.number(key, min, max);
  c.acceptable = g.opt_number(acceptable_key, min, max).value_or(c.success);
  if (higher_is_better ? c.acceptable > c.success : c.acceptable < c.success) {
    g.fail(acceptable_key, std::string("must be ") + (higher_is_better ? "at most " : "at least ") +
                               key + " (acceptable is the band between success and failure)");
  }
}

Criterion read_criterion(const nlohmann::json& v, const std::string& origin,
                         const std::string& path, std::size_t index, const Scenario& s) {
  Fields g(v, origin, path);
  Criterion c;
  const auto type = g.string("type");
  auto t = find_in(kCriteria, type);
  if (!t) {
    g.fail("type", "unknown criterion '" + type + "'; use one of: " + join(names_of(kCriteria)));
  }
  c.type = *t;
  c.name = g.opt_string("name").value_or(type + "#" + std::to_string(index + 1));
  switch (c.type) {
    case CriterionType::kLatency: {
      const auto measure = g.string("measure");
      if (measure == "processing") {
        c.measure = LatencyMeasure::kProcessing;
      } else if (measure == "onset_to_dispatch") {
        c.measure = LatencyMeasure::kOnsetToDispatch;
      } else {
        g.fail("measure", "use \"processing\" (wall time, frame capture to dispatch) or "
                          "\"onset_to_dispatch\" (video time, gesture onset to dispatch)");
      }
      thresholds(g, c, "p95_ms", "acceptable_p95_ms", 0, 60000, false);
      c.grace_s = g.opt_number("grace_s", 0, 10).value_or(0.6);
      break;
    }
    case CriterionType::kRecognitionAccuracy:
      thresholds(g, c, "min", "acceptable_min", 0, 1, true);
      c.grace_s = g.opt_number("grace_s", 0, 10).value_or(0.6);
      break;
    case CriterionType::kFalsePositives: {
      thresholds(g, c, "max", "acceptable_max", 0, 1e6, false, 0.0);
      const auto scope = g.opt_string("scope").value_or("non_deliberate");
      if (scope != "non_deliberate" && scope != "all") {
        g.fail("scope", "use \"non_deliberate\" (commands while no gesture is shown) or \"all\" "
                        "(also a command for another gesture than the one shown)");
      }
      c.all_segments = scope == "all";
      c.grace_s = g.opt_number("grace_s", 0, 10).value_or(0.6);
      break;
    }
    case CriterionType::kFailsafe: {
      c.alert = g.string("alert");
      const auto action = g.opt_string("action").value_or("none");
      if (action != "none") {
        c.action = contracts::command_type_from_string(action);
        if (!c.action) g.fail("action", "use HOVER, LAND, EMERGENCY_STOP or none");
      }
      if (auto sev = g.opt_string("severity")) {
        c.severity = contracts::severity_from_string(*sev);
        if (!c.severity) g.fail("severity", "use INFO, WARNING or CRITICAL");
      }
      thresholds(g, c, "within_ms", "acceptable_ms", 0, 3.6e6, false);
      c.not_before_ms = g.opt_number("not_before_ms", 0, 3.6e6).value_or(0);
      if (c.not_before_ms > c.success) {
        g.fail("not_before_ms", "must be at most within_ms (the window is [not_before_ms, within_ms])");
      }
      const bool has_from = g.has("from_s");
      const bool has_event = g.has("from_event");
      if (has_from && has_event) g.fail("from_s", "give from_s or from_event, not both");
      if (has_from) {
        c.from_s = g.number("from_s", 0, s.timeout_s);
      } else if (has_event) {
        const auto i = g.opt_int("from_event", 0, 1000).value_or(0);
        if (static_cast<std::size_t>(i) >= s.events.size()) {
          g.fail("from_event", "there are only " + std::to_string(s.events.size()) +
                                   " events (counted from 0)");
        }
        c.from_s = s.events[static_cast<std::size_t>(i)].at_s;
      } else if (!s.events.empty()) {
        c.from_s = s.events.front().at_s;
      } else {
        g.fail("from_s", "say when the fault starts: from_s (seconds) or from_event (index)");
      }
      break;
    }
    case CriterionType::kAlerts:
      c.alerts_contain = g.strings("contains");
      c.alerts_never = g.strings("never");
      if (c.alerts_contain.empty() && c.alerts_never.empty()) {
        g.fail("contains", "an alerts criterion needs contains or never (alert codes)");
      }
      break;
    case CriterionType::kCommandSequence:
      c.contains = read_patterns(g, "contains");
      c.in_order = read_patterns(g, "in_order");
      c.never = read_patterns(g, "never");
      if (c.contains.empty() && c.in_order.empty() && c.never.empty()) {
        g.fail("contains", "a command_sequence needs contains, in_order or never");
      }
      break;
    case CriterionType::kFinalState: {
      for (const auto& st : g.strings("flight_state")) {
        auto fs_ = contracts::flight_state_from_string(st);
        if (!fs_) g.fail("flight_state", "unknown state '" + st + "'; use INIT, READY, FLYING, "
                                         "LANDING or FAULT");
        c.flight_states.push_back(*fs_);
      }
      c.altitude_range_m = g.range("altitude_m", -1, 100);
      if (g.has("position_box_m")) {
        Fields b(g.get("position_box_m"), origin, g.field("position_box_m"));
        c.x_range_m = b.range("x", -1000, 1000);
        c.y_range_m = b.range("y", -1000, 1000);
        b.finish("position_box_m (x and y ranges in metres)");
      }
      if (c.flight_states.empty() && !c.altitude_range_m && !c.x_range_m && !c.y_range_m) {
        g.fail("flight_state", "a final_state needs flight_state, altitude_m or position_box_m");
      }
      break;
    }
    case CriterionType::kMaxAltitude:
      thresholds(g, c, "max_m", "acceptable_max_m", 0, 100, false);
      break;
    case CriterionType::kNoCollision:
      thresholds(g, c, "max", "acceptable_max", 0, 1000, false, 0.0);
      break;
    case CriterionType::kBatteryAbove:
      thresholds(g, c, "min_pct", "acceptable_min_pct", 0, 100, true);
      break;
  }
  g.finish("a " + type + " criterion");
  return c;
}

}  // namespace

std::string_view to_string(DroneKind k) { return name_in(kDrones, k); }
std::optional<DroneKind> drone_kind_from_string(std::string_view s) { return find_in(kDrones, s); }
std::string_view to_string(EventType t) { return name_in(kEvents, t); }
std::optional<EventType> event_type_from_string(std::string_view s) { return find_in(kEvents, s); }
std::string_view to_string(CriterionType t) { return name_in(kCriteria, t); }
std::optional<CriterionType> criterion_type_from_string(std::string_view s) {
  return find_in(kCriteria, s);
}
std::string_view to_string(CameraKind k) {
  switch (k) {
    case CameraKind::kTimeline: return "timeline";
    case CameraKind::kRecipe: return "recipe";
    case CameraKind::kRecorded: return "video";
  }
  return "?";
}

Scenario Scenario::from_json(const nlohmann::json& doc, const std::string& base_dir,
                             const std::string& origin) {
  Fields f(doc, origin, "");
  Scenario s;
  f.has("$schema");
  s.name = f.string("name");
  if (s.name.empty() || s.name.find_first_of("/\\ \t") != std::string::npos) {
    f.fail("name", "must be a non-empty identifier without spaces or slashes (it names the "
                   "report's folder and the JUnit test)");
  }
  s.description = f.string("description");
  s.timeout_s = f.number("timeout_s", 0.1, 3600);
  s.drone = read_drone(f);
  s.camera = read_camera(f, base_dir);
  s.profile = read_profile(f, base_dir);
  if (f.has("failsafe")) {
    s.failsafe = f.get("failsafe");
    try {
      (void)telemetry::FailsafeOptions::from_json(s.failsafe);
    } catch (const std::exception& e) {
      f.fail("failsafe", e.what());
    }
  } else {
    s.failsafe = nlohmann::json::object();
  }
  if (f.has("events")) {
    const auto& events = f.get("events");
    if (!events.is_array()) f.fail("events", "must be an array of timed events");
    for (std::size_t i = 0; i < events.size(); ++i) {
      s.events.push_back(
          read_event(events[i], origin, "events[" + std::to_string(i) + "]", s.timeout_s));
    }
    std::stable_sort(s.events.begin(), s.events.end(),
                     [](const auto& a, const auto& b) { return a.at_s < b.at_s; });
  }
  const auto& criteria = f.get("criteria");
  if (!criteria.is_array() || criteria.empty()) {
    f.fail("criteria", "must be a non-empty array: a scenario without criteria checks nothing");
  }
  for (std::size_t i = 0; i < criteria.size(); ++i) {
    s.criteria.push_back(
        read_criterion(criteria[i], origin, "criteria[" + std::to_string(i) + "]", i, s));
  }
  for (std::size_t i = 0; i < s.criteria.size(); ++i) {
    for (std::size_t j = 0; j < i; ++j) {
      if (s.criteria[i].name == s.criteria[j].name) {
        f.fail("criteria[" + std::to_string(i) + "].name",
               "'" + s.criteria[i].name + "' is used twice; give each criterion its own name");
      }
    }
  }
  f.finish("a scenario");
  return s;
}

Scenario Scenario::load_file(const std::string& path) {
  const auto doc = read_json(path, path);
  auto base = fs::path(path).parent_path().string();
  if (base.empty()) base = ".";
  auto s = from_json(doc, base, path);
  s.path = path;
  return s;
}

std::vector<std::string> scenario_files(const std::string& path) {
  std::error_code ec;
  if (fs::is_regular_file(path, ec)) return {path};
  if (!fs::is_directory(path, ec)) {
    throw ScenarioError(path + ": no such scenario file or folder");
  }
  std::vector<std::string> out;
  for (const auto& entry : fs::directory_iterator(path)) {
    if (!entry.is_regular_file() || entry.path().extension() != ".json") continue;
    if (entry.path().filename() == "schema.json") continue;
    out.push_back(entry.path().string());
  }
  std::sort(out.begin(), out.end());
  if (out.empty()) throw ScenarioError(path + ": no scenario files (*.json) in this folder");
  return out;
}

std::string ScenarioEvent::describe() const {
  std::ostringstream s;
  s << sim::to_string(type);
  switch (type) {
    case EventType::kTelemetryDelay: s << " " << delay_ms << " ms"; break;
    case EventType::kBatteryJump: s << " to " << battery_pct << " %"; break;
    case EventType::kWindGust:
      s << " [" << force_n[0] << ", " << force_n[1] << ", " << force_n[2] << "] N";
      break;
    case EventType::kMotorFault: s << " motor " << motor << " x" << thrust_factor; break;
    case EventType::kVisionCrash: s << (detected_at_exit ? " (exit)" : " (silent)"); break;
    case EventType::kVisionUnhealthy: s << " (" << reason << ")"; break;
    case EventType::kEmergencyStop: s << " from " << contracts::to_string(source); break;
    case EventType::kKey: s << " '" << key << "'"; break;
    default: break;
  }
  if (duration_s != kForever &&
      (type == EventType::kLinkLoss || type == EventType::kTelemetryDelay ||
       type == EventType::kWindGust || type == EventType::kMotorFault ||
       type == EventType::kVisionCrash || type == EventType::kVisionUnhealthy)) {
    s << " for " << duration_s << " s";
  }
  return s.str();
}

std::string CommandPattern::describe() const {
  std::string s(contracts::to_string(type));
  if (source) s += "@" + std::string(contracts::to_string(*source));
  if (!source_id.empty()) s += ":" + source_id;
  if (outcome != "OK") s += "=" + outcome;
  return s;
}

}  // namespace gbdcs::sim
