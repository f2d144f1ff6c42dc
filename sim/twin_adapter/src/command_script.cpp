#include "gbdcs/sim/command_script.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>

#include "gbdcs/contracts/json_file.hpp"
#include "gbdcs/sim/twin_adapter.hpp"

namespace gbdcs::sim {
namespace {

constexpr double kMaxDurationS = 3600;
constexpr std::array<std::pair<ScriptCmd, std::string_view>, 6> kCmdNames = {{
    {ScriptCmd::kTakeoff, "takeoff"},
    {ScriptCmd::kLand, "land"},
    {ScriptCmd::kEmergency, "emergency"},
    {ScriptCmd::kHover, "hover"},
    {ScriptCmd::kRc, "rc"},
    {ScriptCmd::kStop, "stop"},
}};

std::string known_cmds() {
  std::string out;
  for (const auto& [c, n] : kCmdNames) out += (out.empty() ? "" : ", ") + std::string(n);
  return out;
}

std::optional<ScriptCmd> cmd_from_string(std::string_view s) {
  for (const auto& [c, n] : kCmdNames) {
    if (n == s) return c;
  }
  return std::nullopt;
}

[[noreturn]] void fail(const std::string& where, const std::string& problem) {
  throw ScriptError(where.empty() ? problem : where + ": " + problem);
}

void reject_unknown_keys(const nlohmann::json& obj, const std::string& where,
                         std::initializer_list<std::string_view> known) {
  for (const auto& [key, value] : obj.items()) {
    if (std::find(known.begin(), known.end(), key) == known.end()) {
      std::string list;
      for (auto k : known) list += (list.empty() ? "" : ", ") + std::string(k);
      fail(where, "unknown field '" + key + "' (known: " + list + ")");
    }
  }
}

double read_number(const nlohmann::json& obj, const std::string& where, const std::string& key) {
  const auto& v = obj.at(key);
  if (!v.is_number()) {
    fail(where,
         "'" + key + "' must be a number, got " + std::string(v.type_name()) + " " + v.dump());
  }
  const double x = v.get<double>();
  if (!std::isfinite(x)) fail(where, "'" + key + "' must be finite");
  return x;
}

ScriptCommand parse_command(const nlohmann::json& entry, const std::string& where) {
  if (!entry.is_object()) {
    fail(where, "must be an object like {\"at_s\": 1.0, \"cmd\": \"takeoff\"}, got " +
                    std::string(entry.type_name()));
  }
  reject_unknown_keys(entry, where, {"at_s", "cmd", "args"});
  if (!entry.contains("at_s")) fail(where, "'at_s' is missing (seconds from the start)");
  if (!entry.contains("cmd")) fail(where, "'cmd' is missing (one of " + known_cmds() + ")");
  ScriptCommand c;
  c.at_s = read_number(entry, where, "at_s");
  if (c.at_s < 0) fail(where, "'at_s' must not be negative, got " + entry.at("at_s").dump());
  const auto& cmd = entry.at("cmd");
  if (!cmd.is_string()) fail(where, "'cmd' must be a string, got " + cmd.dump());
  const auto parsed = cmd_from_string(cmd.get<std::string>());
  if (!parsed) {
    fail(where, "unknown cmd '" + cmd.get<std::string>() + "' (known: " + known_cmds() + ")");
  }
  c.cmd = *parsed;
  if (c.cmd != ScriptCmd::kRc) {
    if (entry.contains("args")) {
      fail(where,
           "'args' is only for rc ('" + std::string(to_string(c.cmd)) + "' takes no arguments)");
    }
    return c;
  }
  if (!entry.contains("args")) fail(where, "'args' is missing: rc needs [a, b, c, d]");
  const auto& args = entry.at("args");
  if (!args.is_array() || args.size() != 4) {
    fail(where, "'args' must be four integers [a, b, c, d] in [-100, 100], got " + args.dump());
  }
  for (std::size_t i = 0; i < 4; ++i) {
    const auto& a = args[i];
    if (!a.is_number_integer() || a.get<std::int64_t>() < -100 || a.get<std::int64_t>() > 100) {
      fail(where,
           "'args[" + std::to_string(i) + "]' must be an integer in [-100, 100], got " + a.dump());
    }
    c.rc[i] = static_cast<int>(a.get<std::int64_t>());
  }
  return c;
}

}  // namespace

std::string_view to_string(ScriptCmd c) {
  for (const auto& [cmd, n] : kCmdNames) {
    if (cmd == c) return n;
  }
  return "?";
}

CommandScript CommandScript::from_json(const nlohmann::json& doc) {
  if (!doc.is_object()) {
    fail("", "a command script must be a JSON object with \"commands\", got " +
                 std::string(doc.type_name()));
  }
  reject_unknown_keys(doc, "script", {"seed", "faults", "commands", "duration_s"});
  CommandScript s;
  if (doc.contains("seed")) {
    const auto& seed = doc.at("seed");
    if (!seed.is_number_unsigned() ||
        seed.get<std::uint64_t>() > std::numeric_limits<std::uint32_t>::max()) {
      fail("seed", "must be an integer in [0, 4294967295], got " + seed.dump());
    }
    s.seed = static_cast<std::uint32_t>(seed.get<std::uint64_t>());
  }
  if (doc.contains("duration_s")) {
    s.duration_s = read_number(doc, "script", "duration_s");
    if (s.duration_s <= 0 || s.duration_s > kMaxDurationS) {
      fail("duration_s", "must be within (0, 3600] seconds, got " + doc.at("duration_s").dump());
    }
  }
  if (doc.contains("faults")) {
    try {
      s.faults = FaultSchedule::from_json(doc.at("faults"));
    } catch (const std::exception& e) {
      fail("faults", e.what());
    }
  }
  if (!doc.contains("commands")) fail("", "'commands' is missing (a list of timed commands)");
  const auto& commands = doc.at("commands");
  if (!commands.is_array()) {
    fail("commands", "must be a list, got " + std::string(commands.type_name()));
  }
  for (std::size_t i = 0; i < commands.size(); ++i) {
    const std::string where = "commands[" + std::to_string(i) + "]";
    auto c = parse_command(commands[i], where);
    if (!s.commands.empty() && c.at_s < s.commands.back().at_s) {
      std::ostringstream msg;
      msg << "'at_s' " << c.at_s << " is before the previous command's " << s.commands.back().at_s
          << " (commands must be in time order)";
      fail(where, msg.str());
    }
    if (c.at_s > s.duration_s) {
      std::ostringstream msg;
      msg << "'at_s' " << c.at_s << " is after the end of the script (duration_s " << s.duration_s
          << ")";
      fail(where, msg.str());
    }
    s.commands.push_back(c);
  }
  return s;
}

CommandScript CommandScript::load_file(const std::string& path) {
  const auto doc = contracts::read_json_file<ScriptError>(path, "command script");
  return contracts::prefix_errors<ScriptError>(path, [&] { return from_json(doc); });
}

CommandScript CommandScript::builtin_demo() {
  return from_json(nlohmann::json::parse(R"({
    "seed": 1,
    "commands": [
      {"at_s": 1.0, "cmd": "takeoff"},
      {"at_s": 5.0, "cmd": "rc", "args": [0, 50, 0, 0]},
      {"at_s": 7.0, "cmd": "stop"},
      {"at_s": 8.0, "cmd": "rc", "args": [0, 0, 0, 50]},
      {"at_s": 10.0, "cmd": "hover"},
      {"at_s": 11.0, "cmd": "land"}
    ],
    "duration_s": 16
  })"));
}

control::Result apply(TwinAdapter& twin, const ScriptCommand& command) {
  switch (command.cmd) {
    case ScriptCmd::kTakeoff:
      return twin.takeoff();
    case ScriptCmd::kLand:
      return twin.land();
    case ScriptCmd::kEmergency:
      return twin.emergency_stop();
    case ScriptCmd::kHover:
      return twin.hover();
    case ScriptCmd::kRc:
      return twin.rc(command.rc[0], command.rc[1], command.rc[2], command.rc[3]);
    case ScriptCmd::kStop:
      return twin.rc(0, 0, 0, 0);
  }
  return control::Result::kError;
}

void run_script(const CommandScript& script, TwinAdapter& twin, const ScriptHooks& hooks) {
  if (!hooks.wait_until) throw std::invalid_argument("run_script: wait_until is required");
  const double max_step = hooks.max_step_s > 0 ? hooks.max_step_s : 0.05;
  const bool frames = hooks.on_frame && hooks.frame_period_s > 0;
  std::size_t next_cmd = 0;
  long frame_index = 0;
  double t = 0;
  for (;;) {
    // Commands and frames due now first, then the next event (or a polling step).
    while (next_cmd < script.commands.size() && script.commands[next_cmd].at_s <= t + 1e-12) {
      const auto& c = script.commands[next_cmd++];
      const auto r = apply(twin, c);
      if (hooks.on_command)
        hooks.on_command(c, r, r == control::Result::kOk ? "" : twin.last_error());
    }
    if (frames) {
      const double frame_t = static_cast<double>(frame_index) * hooks.frame_period_s;
      if (frame_t <= t + 1e-12) {
        hooks.on_frame(t);
        ++frame_index;
      }
    }
    if (t >= script.duration_s) break;
    double next = std::min(script.duration_s, t + max_step);
    if (next_cmd < script.commands.size()) next = std::min(next, script.commands[next_cmd].at_s);
    if (frames) next = std::min(next, static_cast<double>(frame_index) * hooks.frame_period_s);
    t = std::max(next, t);
    hooks.wait_until(t);
  }
}

}  // namespace gbdcs::sim
