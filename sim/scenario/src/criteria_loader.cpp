// The scenario loader's criteria part: criteria[i] of a scenario file (with their command
// patterns and thresholds), and their names.
#include <algorithm>

#include "gbdcs/contracts/codec.hpp"
#include "json_fields.hpp"
#include "loader_parts.hpp"

namespace gbdcs::sim {

namespace {

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

}  // namespace

namespace detail {
namespace {

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

}  // namespace

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

}  // namespace detail

std::string_view to_string(CriterionType t) { return detail::name_in(kCriteria, t); }
std::optional<CriterionType> criterion_type_from_string(std::string_view s) {
  return detail::find_in(kCriteria, s);
}

std::string CommandPattern::describe() const {
  std::string s(contracts::to_string(type));
  if (source) s += "@" + std::string(contracts::to_string(*source));
  if (!source_id.empty()) s += ":" + source_id;
  if (outcome != "OK") s += "=" + outcome;
  return s;
}

}  // namespace gbdcs::sim
