#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "gbdcs/sim/scenario_criteria.hpp"

namespace gbdcs::sim {

namespace {

using contracts::CommandSource;

std::string num(double v, int decimals = 0) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(decimals) << v;
  return s.str();
}

Verdict lower_is_better(double actual, const Criterion& c) {
  if (actual <= c.success) return Verdict::kSuccess;
  if (actual <= c.acceptable) return Verdict::kAcceptable;
  return Verdict::kFailure;
}

Verdict higher_is_better(double actual, const Criterion& c) {
  if (actual >= c.success) return Verdict::kSuccess;
  if (actual >= c.acceptable) return Verdict::kAcceptable;
  return Verdict::kFailure;
}

std::string band(const Criterion& c, const std::string& op, const std::string& unit,
                 int decimals = 0) {
  std::string s = op + " " + num(c.success, decimals) + unit;
  if (c.acceptable != c.success) {
    s += " (acceptable " + op + " " + num(c.acceptable, decimals) + unit + ")";
  }
  return s;
}

bool reached_adapter(const std::string& outcome) {
  return outcome.rfind("REFUSED", 0) != 0 && outcome.rfind("DROPPED", 0) != 0;
}

// The segment shown at t_s; past the last one the camera shows no hand.
LabelledSegment segment_at(const RunRecord& r, double t_s) {
  for (const auto& s : r.segments) {
    if (t_s >= s.start_s && t_s < s.end_s) return s;
  }
  LabelledSegment none;
  none.start_s = r.segments.empty() ? 0 : r.segments.back().end_s;
  none.end_s = std::max(r.end_s, none.start_s);
  none.label = "NO_HAND";
  return none;
}

std::string list(const std::vector<std::string>& items, std::size_t max_items = 12) {
  std::string out;
  for (std::size_t i = 0; i < items.size() && i < max_items; ++i) {
    if (!out.empty()) out += ", ";
    out += items[i];
  }
  if (items.size() > max_items) out += ", ... (" + std::to_string(items.size()) + " in all)";
  return out.empty() ? "none" : out;
}

CriterionResult latency(const Criterion& c, const RunRecord& r) {
  CriterionResult out;
  out.expected = "p95 " + band(c, "<=", " ms");
  std::vector<double> samples;
  std::string what;
  if (c.measure == LatencyMeasure::kProcessing) {
    out.expected = "processing (capture -> dispatch, wall) " + out.expected;
    for (const auto& cmd : r.commands) {
      if (cmd.processing_ms >= 0) samples.push_back(cmd.processing_ms);
    }
    what = "gesture commands dispatched";
  } else {
    out.expected = "onset -> dispatch (video time) " + out.expected;
    int segments = 0;
    std::optional<contracts::GestureType> previous;
    for (const auto& s : r.segments) {
      const bool counted = s.gesture && s.frames_shown > 0 && s.gesture != previous &&
                           std::find(r.mapped_gestures.begin(), r.mapped_gestures.end(),
                                     *s.gesture) != r.mapped_gestures.end();
      previous = s.gesture;
      if (!counted) continue;
      ++segments;
      const std::string name(contracts::to_string(*s.gesture));
      for (const auto& cmd : r.commands) {
        if (cmd.command.source == CommandSource::kGesture && cmd.command.source_id == name &&
            reached_adapter(cmd.outcome) && cmd.t_s >= s.start_s &&
            cmd.t_s <= s.end_s + c.grace_s) {
          samples.push_back((cmd.t_s - s.start_s) * 1000.0);
          break;
        }
      }
    }
    what = "of " + std::to_string(segments) + " gesture onsets dispatched";
  }
  if (samples.empty()) {
    out.actual = "not evaluated: no " + what + " to measure";
    return out;
  }
  const double p95 = percentile(samples, 95);
  out.actual = "p95 " + num(p95, 1) + " ms, p50 " + num(percentile(samples, 50), 1) + " ms (" +
               std::to_string(samples.size()) + " " + what + ")";
  out.verdict = lower_is_better(p95, c);
  return out;
}

CriterionResult accuracy(const Criterion& c, const RunRecord& r) {
  CriterionResult out;
  out.expected = "deliberate segments recognised " + band(c, ">=", "", 2);
  int shown = 0, recognised = 0;
  std::vector<std::string> missed;
  for (const auto& s : r.segments) {
    if (!s.gesture || s.frames_shown == 0) continue;
    ++shown;
    const bool hit = std::any_of(r.gestures.begin(), r.gestures.end(), [&](const auto& g) {
      return g.event.gesture == *s.gesture && g.t_s >= s.start_s && g.t_s <= s.end_s + c.grace_s;
    });
    if (hit) {
      ++recognised;
    } else {
      missed.push_back(s.label + "@" + num(s.start_s, 1) + "s");
    }
  }
  if (shown == 0) {
    out.actual = "not evaluated: no deliberate gesture segment reached the core";
    return out;
  }
  const double acc = static_cast<double>(recognised) / shown;
  out.actual = num(acc, 2) + " (" + std::to_string(recognised) + " of " + std::to_string(shown) +
               (missed.empty() ? ")" : "; missed " + list(missed, 6) + ")");
  out.verdict = higher_is_better(acc, c);
  return out;
}

CriterionResult false_positives(const Criterion& c, const RunRecord& r) {
  CriterionResult out;
  out.expected = std::string(c.all_segments ? "commands for a gesture not shown"
                                            : "commands while no gesture is shown") +
                 " " + band(c, "<=", "");
  if (r.segments.empty()) {
    out.actual = "not evaluated: the camera has no labelled segments";
    return out;
  }
  std::vector<std::string> found;
  for (const auto& cmd : r.commands) {
    if (cmd.command.source != CommandSource::kGesture) continue;
    const auto s = segment_at(r, cmd.t_s);
    if (cmd.t_s - s.start_s < c.grace_s) continue;  // the previous gesture being released
    const bool wrong = !s.gesture || (c.all_segments &&
                                      cmd.command.source_id != contracts::to_string(*s.gesture));
    if (wrong) {
      found.push_back(short_form(cmd) + " during " + s.label + " at " + num(cmd.t_s, 2) + " s");
    }
  }
  const double n = static_cast<double>(found.size());
  out.actual = std::to_string(found.size()) + (found.empty() ? "" : ": " + list(found, 4));
  out.verdict = lower_is_better(n, c);
  return out;
}

CriterionResult failsafe(const Criterion& c, const RunRecord& r) {
  CriterionResult out;
  out.expected = c.alert + (c.severity ? " (" + std::string(contracts::to_string(*c.severity)) + ")"
                                       : std::string()) +
                 (c.action ? " + " + std::string(contracts::to_string(*c.action)) : "") + " " +
                 band(c, "<=", " ms") + " after " + num(c.from_s, 2) + " s" +
                 (c.not_before_ms > 0 ? " (not before " + num(c.not_before_ms) + " ms)" : "");
  const RecordedAlert* alert = nullptr;
  for (const auto& a : r.alerts) {
    if (a.alert.code == c.alert && a.t_s >= c.from_s - 1e-9 &&
        (!c.severity || a.alert.severity == *c.severity)) {
      alert = &a;
      break;
    }
  }
  if (!alert) {
    std::vector<std::string> seen;
    for (const auto& a : r.alerts) seen.push_back(a.alert.code + "@" + num(a.t_s, 2) + "s");
    out.actual = c.alert + " never raised after " + num(c.from_s, 2) + " s (alerts: " +
                 list(seen, 6) + ")";
    return out;
  }
  double done_s = alert->t_s;
  out.actual = c.alert + " at +" + num((alert->t_s - c.from_s) * 1000) + " ms";
  if ((alert->t_s - c.from_s) * 1000.0 < c.not_before_ms) {
    out.actual += ", too early (before " + num(c.not_before_ms) + " ms)";
    return out;
  }
  if (c.action) {
    const RecordedCommand* action = nullptr;
    for (const auto& cmd : r.commands) {
      if (cmd.command.source == CommandSource::kFailsafe && cmd.command.source_id == c.alert &&
          cmd.command.type == *c.action && cmd.t_s >= alert->t_s - 1e-9 &&
          reached_adapter(cmd.outcome)) {
        action = &cmd;
        break;
      }
    }
    if (!action) {
      out.actual += ", but no " + std::string(contracts::to_string(*c.action)) +
                    " from the failsafe reached the drone";
      return out;
    }
    done_s = std::max(done_s, action->t_s);
    out.actual += ", " + std::string(contracts::to_string(*c.action)) + " at +" +
                  num((action->t_s - c.from_s) * 1000) + " ms (" + action->outcome + ")";
  }
  out.verdict = lower_is_better((done_s - c.from_s) * 1000.0, c);
  return out;
}

CriterionResult alerts(const Criterion& c, const RunRecord& r) {
  CriterionResult out;
  std::vector<std::string> parts;
  if (!c.alerts_contain.empty()) parts.push_back("contains " + list(c.alerts_contain));
  if (!c.alerts_never.empty()) parts.push_back("never " + list(c.alerts_never));
  out.expected = list(parts);
  std::vector<std::string> missing, forbidden, seen;
  for (const auto& a : r.alerts) seen.push_back(a.alert.code + "@" + num(a.t_s, 2) + "s");
  auto raised = [&](const std::string& code) {
    return std::any_of(r.alerts.begin(), r.alerts.end(),
                       [&](const auto& a) { return a.alert.code == code; });
  };
  for (const auto& code : c.alerts_contain) {
    if (!raised(code)) missing.push_back(code);
  }
  for (const auto& code : c.alerts_never) {
    if (raised(code)) forbidden.push_back(code);
  }
  out.actual = "alerts: " + list(seen, 8);
  if (!missing.empty()) out.actual += "; missing " + list(missing);
  if (!forbidden.empty()) out.actual += "; raised but forbidden " + list(forbidden);
  out.verdict = missing.empty() && forbidden.empty() ? Verdict::kSuccess : Verdict::kFailure;
  return out;
}

std::string patterns(const std::vector<CommandPattern>& ps) {
  std::vector<std::string> s;
  for (const auto& p : ps) s.push_back(p.describe());
  return list(s, 20);
}

CriterionResult sequence(const Criterion& c, const RunRecord& r) {
  CriterionResult out;
  std::vector<std::string> parts;
  if (!c.contains.empty()) parts.push_back("contains [" + patterns(c.contains) + "]");
  if (!c.in_order.empty()) parts.push_back("in order [" + patterns(c.in_order) + "]");
  if (!c.never.empty()) parts.push_back("never [" + patterns(c.never) + "]");
  out.expected = list(parts);
  std::vector<std::string> problems;
  for (const auto& p : c.contains) {
    if (std::none_of(r.commands.begin(), r.commands.end(),
                     [&](const auto& cmd) { return matches(p, cmd); })) {
      problems.push_back("missing " + p.describe());
    }
  }
  std::size_t next = 0;
  for (const auto& cmd : r.commands) {
    if (next < c.in_order.size() && matches(c.in_order[next], cmd)) ++next;
  }
  if (next < c.in_order.size()) {
    problems.push_back("order broken at " + c.in_order[next].describe() + " (matched " +
                       std::to_string(next) + " of " + std::to_string(c.in_order.size()) + ")");
  }
  for (const auto& p : c.never) {
    for (const auto& cmd : r.commands) {
      if (matches(p, cmd)) {
        problems.push_back("forbidden " + short_form(cmd) + " at " + num(cmd.t_s, 2) + " s");
        break;
      }
    }
  }
  // The distinct commands, consecutive repeats folded ("MOVE:POINT_LEFT=OK x3").
  std::vector<std::string> seen;
  std::string last;
  int repeats = 0;
  auto flush = [&] {
    if (!last.empty()) seen.push_back(repeats > 1 ? last + " x" + std::to_string(repeats) : last);
  };
  for (const auto& cmd : r.commands) {
    const auto s = short_form(cmd);
    if (s == last) {
      ++repeats;
      continue;
    }
    flush();
    last = s;
    repeats = 1;
  }
  flush();
  out.actual = (problems.empty() ? std::string() : list(problems, 6) + "; ") + "commands: " +
               list(seen, 14);
  out.verdict = problems.empty() ? Verdict::kSuccess : Verdict::kFailure;
  return out;
}

CriterionResult final_state(const Criterion& c, const RunRecord& r) {
  CriterionResult out;
  std::vector<std::string> parts;
  if (!c.flight_states.empty()) {
    std::vector<std::string> st;
    for (auto s : c.flight_states) st.emplace_back(contracts::to_string(s));
    parts.push_back(list(st, 5));
  }
  auto range = [](const std::array<double, 2>& a) {
    return "[" + num(a[0], 2) + ", " + num(a[1], 2) + "]";
  };
  if (c.altitude_range_m) parts.push_back("altitude " + range(*c.altitude_range_m) + " m");
  if (c.x_range_m) parts.push_back("x " + range(*c.x_range_m) + " m");
  if (c.y_range_m) parts.push_back("y " + range(*c.y_range_m) + " m");
  out.expected = list(parts);
  if (r.telemetry.empty()) {
    out.actual = "not evaluated: no telemetry received";
    return out;
  }
  const auto& f = r.telemetry.back().frame;
  out.actual = std::string(contracts::to_string(f.flight_state)) + ", altitude " +
               num(f.altitude_m, 2) + " m, x " + num(f.x_m, 2) + " m, y " + num(f.y_m, 2) +
               " m (at " + num(r.telemetry.back().t_s, 2) + " s)";
  bool ok = c.flight_states.empty() ||
            std::find(c.flight_states.begin(), c.flight_states.end(), f.flight_state) !=
                c.flight_states.end();
  auto in = [](const std::optional<std::array<double, 2>>& rg, double v) {
    return !rg || (v >= (*rg)[0] && v <= (*rg)[1]);
  };
  ok = ok && in(c.altitude_range_m, f.altitude_m) && in(c.x_range_m, f.x_m) &&
       in(c.y_range_m, f.y_m);
  out.verdict = ok ? Verdict::kSuccess : Verdict::kFailure;
  return out;
}

CriterionResult max_altitude(const Criterion& c, const RunRecord& r) {
  CriterionResult out;
  out.expected = "max altitude " + band(c, "<=", " m", 2);
  if (r.telemetry.empty()) {
    out.actual = "not evaluated: no telemetry received";
    return out;
  }
  double top = 0, at = 0;
  for (const auto& t : r.telemetry) {
    if (t.frame.altitude_m > top) {
      top = t.frame.altitude_m;
      at = t.t_s;
    }
  }
  out.actual = num(top, 2) + " m at " + num(at, 2) + " s";
  out.verdict = lower_is_better(top, c);
  return out;
}

CriterionResult no_collision(const Criterion& c, const RunRecord& r) {
  CriterionResult out;
  out.expected = "collisions " + band(c, "<=", "");
  if (!r.collisions) {
    out.actual = "not evaluated: this drone cannot report collisions (fly the twin or an "
                 "emulator)";
    return out;
  }
  out.actual = std::to_string(*r.collisions);
  out.verdict = lower_is_better(*r.collisions, c);
  return out;
}

CriterionResult battery_above(const Criterion& c, const RunRecord& r) {
  CriterionResult out;
  out.expected = "battery " + band(c, ">=", " %", 1);
  if (r.telemetry.empty()) {
    out.actual = "not evaluated: no telemetry received";
    return out;
  }
  double low = 1e9;
  for (const auto& t : r.telemetry) low = std::min(low, t.frame.battery_pct);
  out.actual = "lowest " + num(low, 1) + " %";
  out.verdict = higher_is_better(low, c);
  return out;
}

}  // namespace

std::string_view to_string(Verdict v) {
  switch (v) {
    case Verdict::kSuccess: return "SUCCESS";
    case Verdict::kAcceptable: return "ACCEPTABLE";
    case Verdict::kFailure: return "FAILURE";
  }
  return "?";
}

double percentile(std::vector<double> v, double p) {
  std::sort(v.begin(), v.end());
  const auto rank = static_cast<std::size_t>(std::ceil(p / 100.0 * static_cast<double>(v.size())));
  return v[std::clamp<std::size_t>(rank, 1, v.size()) - 1];
}

bool matches(const CommandPattern& p, const RecordedCommand& cmd) {
  if (cmd.command.type != p.type) return false;
  if (p.source && cmd.command.source != *p.source) return false;
  if (!p.source_id.empty() && cmd.command.source_id != p.source_id) return false;
  if (p.outcome == "any") return true;
  return cmd.outcome.rfind(p.outcome, 0) == 0;
}

std::string short_form(const RecordedCommand& cmd) {
  std::string s(contracts::to_string(cmd.command.type));
  if (!cmd.command.source_id.empty()) s += ":" + cmd.command.source_id;
  const auto colon = cmd.outcome.find(':');
  s += "=" + (colon == std::string::npos ? cmd.outcome : cmd.outcome.substr(0, colon));
  return s;
}

CriterionResult evaluate(const Criterion& c, const RunRecord& r) {
  CriterionResult out;
  switch (c.type) {
    case CriterionType::kLatency: out = latency(c, r); break;
    case CriterionType::kRecognitionAccuracy: out = accuracy(c, r); break;
    case CriterionType::kFalsePositives: out = false_positives(c, r); break;
    case CriterionType::kFailsafe: out = failsafe(c, r); break;
    case CriterionType::kAlerts: out = alerts(c, r); break;
    case CriterionType::kCommandSequence: out = sequence(c, r); break;
    case CriterionType::kFinalState: out = final_state(c, r); break;
    case CriterionType::kMaxAltitude: out = max_altitude(c, r); break;
    case CriterionType::kNoCollision: out = no_collision(c, r); break;
    case CriterionType::kBatteryAbove: out = battery_above(c, r); break;
  }
  out.name = c.name;
  out.type = c.type;
  return out;
}

std::vector<CriterionResult> evaluate_all(const Scenario& scenario, const RunRecord& record) {
  std::vector<CriterionResult> out;
  for (const auto& c : scenario.criteria) out.push_back(evaluate(c, record));
  return out;
}

}  // namespace gbdcs::sim
