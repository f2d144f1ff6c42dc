// Command scripts: strict validation, and run_script flying one lockstep on the twin.
#include "gbdcs/sim/command_script.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "twin_test_support.hpp"

namespace gbdcs::sim {
namespace {

std::string error_of(const std::string& text) {
  try {
    CommandScript::from_json(nlohmann::json::parse(text));
  } catch (const ScriptError& e) {
    return e.what();
  }
  return "(accepted)";
}

TEST(CommandScript, ParsesTheDocumentedExample) {
  const auto s = CommandScript::from_json(nlohmann::json::parse(R"({
    "seed": 1,
    "faults": [{"type": "wind_gust", "start_s": 4, "duration_s": 1, "force_n": [0.2, 0, 0]}],
    "commands": [{"at_s": 1.0, "cmd": "takeoff"}, {"at_s": 5, "cmd": "rc", "args": [0, 50, 0, 0]},
                 {"at_s": 7, "cmd": "land"}],
    "duration_s": 20})"));
  EXPECT_EQ(s.seed, 1u);
  EXPECT_EQ(s.duration_s, 20);
  ASSERT_EQ(s.commands.size(), 3u);
  EXPECT_EQ(s.commands[1].cmd, ScriptCmd::kRc);
  EXPECT_EQ(s.commands[1].rc, (std::array<int, 4>{0, 50, 0, 0}));
  EXPECT_EQ(s.faults.faults().size(), 1u);
  EXPECT_EQ(CommandScript::from_json(nlohmann::json::parse(R"({"commands": []})")).duration_s, 20);
}

TEST(CommandScript, ErrorsNameTheEntryAndTheField) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {R"({"commands": [{"at_s": 0, "cmd": "takeoff"}, {"at_s": 1, "cmd": "land"},
                        {"at_s": 2, "cmd": "flip"}]})",
       "commands[2]: unknown cmd 'flip' (known: takeoff, land, emergency, hover, rc, stop)"},
      {R"({"commands": [{"at_s": 0, "cmd": "rc"}]})", "commands[0]: 'args' is missing"},
      {R"({"commands": [{"at_s": 0, "cmd": "rc", "args": [0, 50, 0]}]})",
       "commands[0]: 'args' must be four integers"},
      {R"({"commands": [{"at_s": 0, "cmd": "rc", "args": [0, 150, 0, 0]}]})",
       "commands[0]: 'args[1]' must be an integer in [-100, 100], got 150"},
      {R"({"commands": [{"at_s": 0, "cmd": "rc", "args": [0, 0.5, 0, 0]}]})",
       "commands[0]: 'args[1]' must be an integer"},
      {R"({"commands": [{"at_s": 0, "cmd": "takeoff", "args": [1]}]})",
       "commands[0]: 'args' is only for rc"},
      {R"({"commands": [{"cmd": "takeoff"}]})", "commands[0]: 'at_s' is missing"},
      {R"({"commands": [{"at_s": 1}]})", "commands[0]: 'cmd' is missing"},
      {R"({"commands": [{"at_s": "1", "cmd": "land"}]})",
       "commands[0]: 'at_s' must be a number, got string"},
      {R"({"commands": [{"at_s": -1, "cmd": "land"}]})",
       "commands[0]: 'at_s' must not be negative"},
      {R"({"commands": [{"at_s": 0, "cmd": "land", "when": 2}]})",
       "commands[0]: unknown field 'when' (known: at_s, cmd, args)"},
      {R"({"commands": [{"at_s": 3, "cmd": "takeoff"}, {"at_s": 1, "cmd": "land"}]})",
       "commands[1]: 'at_s' 1 is before the previous command's 3"},
      {R"({"commands": [{"at_s": 30, "cmd": "land"}], "duration_s": 20})",
       "commands[0]: 'at_s' 30 is after the end of the script (duration_s 20)"},
      {R"({"commands": ["takeoff"]})", "commands[0]: must be an object"},
      {R"({"comands": []})", "script: unknown field 'comands'"},
      {R"({"seed": 1})", "'commands' is missing"},
      {R"({"commands": {}})", "commands: must be a list"},
      {R"({"commands": [], "seed": -3})", "seed: must be an integer in [0, 4294967295]"},
      {R"({"commands": [], "duration_s": 0})", "duration_s: must be within (0, 3600]"},
      {R"({"commands": [], "faults": [{"type": "meteor"}]})", "faults: "},
      {R"([1, 2])", "a command script must be a JSON object"},
  };
  for (const auto& [text, expected] : cases) {
    const auto message = error_of(text);
    EXPECT_NE(message.find(expected), std::string::npos)
        << "script " << text << "\n  said:     " << message << "\n  expected: " << expected;
  }
}

TEST(CommandScript, LoadFileNamesThePath) {
  const auto dir = std::filesystem::temp_directory_path() / "gbdcs_sim_twin_tests";
  std::filesystem::create_directories(dir);
  const auto bad = dir / "bad.json";
  std::ofstream(bad) << R"({"commands": [{"at_s": 0, "cmd": "flip"}]})";
  const auto broken = dir / "broken.json";
  std::ofstream(broken) << "{\"commands\": [";
  auto message_of = [](const std::filesystem::path& p) -> std::string {
    try {
      CommandScript::load_file(p.string());
    } catch (const ScriptError& e) {
      return e.what();
    }
    return "(accepted)";
  };
  EXPECT_EQ(message_of(bad),
            bad.string() +
                ": commands[0]: unknown cmd 'flip' (known: takeoff, land, emergency, "
                "hover, rc, stop)");
  EXPECT_NE(message_of(broken).find(broken.string() + ": malformed JSON at byte"),
            std::string::npos);
  EXPECT_NE(message_of(dir / "missing.json").find("cannot read"), std::string::npos);
  std::filesystem::remove_all(dir);
}

TEST(CommandScript, BuiltinDemoFliesLockstepAndLands) {
  const auto script = CommandScript::builtin_demo();
  TwinAdapterOptions o;
  o.seed = script.seed;
  o.twin.faults = script.faults;
  testing::TwinRig rig(o);
  ASSERT_EQ(rig.twin.connect(), control::Result::kOk);
  std::vector<std::string> outcomes;
  std::vector<double> frame_times;
  ScriptHooks hooks;
  hooks.wait_until = [&](double t_s) {
    rig.clock.set(contracts::from_seconds(t_s));
    rig.twin.poll();
  };
  hooks.on_command = [&](const ScriptCommand& c, control::Result r, const std::string& e) {
    outcomes.push_back(std::string(to_string(c.cmd)) + "@" + std::to_string(c.at_s) + ":" +
                       std::string(control::to_string(r)) + e);
    EXPECT_NEAR(rig.twin.sim_time_s(), c.at_s, 0.0021);  // applied at its time (2 ms steps)
  };
  hooks.frame_period_s = 0.1;
  hooks.on_frame = [&](double t_s) { frame_times.push_back(t_s); };
  run_script(script, rig.twin, hooks);

  ASSERT_EQ(outcomes.size(), script.commands.size());
  for (const auto& o2 : outcomes) EXPECT_NE(o2.find(":OK"), std::string::npos) << o2;
  EXPECT_NEAR(rig.now_s(), script.duration_s, 1e-9);
  EXPECT_EQ(frame_times.size(), static_cast<std::size_t>(script.duration_s / 0.1) + 1);
  const auto end = rig.twin.snapshot();
  EXPECT_EQ(end.flight_state, contracts::FlightState::kReady);
  EXPECT_NEAR(end.x_m, 1.0, 0.35);        // rc b 50 for 2 s: 0.5 m/s
  EXPECT_NEAR(end.heading_deg, 100, 20);  // rc d 50 for 2 s: 50 deg/s clockwise
  EXPECT_LT(end.altitude_m, 0.03);
}

}  // namespace
}  // namespace gbdcs::sim
