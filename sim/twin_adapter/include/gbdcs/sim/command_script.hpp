// CommandScript: a timed list of Tello-semantic commands for the twin (`gbdcs twin --script`).
//
// File (JSON, docs/TWIN.md "Command scripts"):
//   {"seed": 1,
//    "faults": [ ...the fault schedule, as sim::FaultSchedule::from_json reads it... ],
//    "commands": [{"at_s": 1.0, "cmd": "takeoff"},
//                 {"at_s": 5, "cmd": "rc", "args": [0, 50, 0, 0]},
//                 {"at_s": 7, "cmd": "land"}],
//    "duration_s": 20}
//   cmd  : takeoff | land | emergency | hover | rc | stop (stop = rc 0 0 0 0: sticks centred,
//          the controller brakes to a hover); args only for rc: four integers in [-100, 100]
//          (a = right, b = forward, c = up, d = yaw clockwise, as the Tello SDK's rc).
//   at_s : seconds of simulated time from the start, in non-decreasing order, <= duration_s.
//   seed (default 1), faults (default none), duration_s (default 20, at most 3600).
// Errors: ScriptError naming the entry and the field, e.g. "commands[2]: unknown cmd 'flip'";
//   load_file prefixes the path.
// run_script(): flies a script on a TwinAdapter: waits (through the caller's wait_until, so the
//   same code runs lockstep or in real time) until each command's time, applies it, and calls
//   on_frame every frame_period_s of simulated time (rendering) until duration_s.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "gbdcs/control/drone_adapter.hpp"
#include "gbdcs/sim/faults.hpp"

namespace gbdcs::sim {

class TwinAdapter;

class ScriptError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

enum class ScriptCmd { kTakeoff, kLand, kEmergency, kHover, kRc, kStop };
std::string_view to_string(ScriptCmd c);  // "takeoff", ...

struct ScriptCommand {
  double at_s = 0;
  ScriptCmd cmd = ScriptCmd::kHover;
  std::array<int, 4> rc{};  // a b c d, only for kRc
};

struct CommandScript {
  std::uint32_t seed = 1;
  FaultSchedule faults;
  std::vector<ScriptCommand> commands;
  double duration_s = 20;

  static CommandScript from_json(const nlohmann::json& doc);  // throws ScriptError
  static CommandScript load_file(const std::string& path);    // throws ScriptError
  // Take off, hover, forward, yaw, land: about 16 s.
  static CommandScript builtin_demo();
};

// Sends one script command to the twin (rc and stop through TwinAdapter::rc).
control::Result apply(TwinAdapter& twin, const ScriptCommand& command);

struct ScriptHooks {
  // Blocks until the twin's simulated time reaches t_s (lockstep: set the clock and poll;
  // real time: sleep). Required.
  std::function<void(double t_s)> wait_until;
  std::function<void(const ScriptCommand&, control::Result, const std::string& error)> on_command;
  std::function<void(double t_s)> on_frame;  // every frame_period_s when set and > 0
  double frame_period_s = 0;
  double max_step_s = 0.05;  // wait_until is called at least this often (lockstep polling)
};

void run_script(const CommandScript& script, TwinAdapter& twin, const ScriptHooks& hooks);

}  // namespace gbdcs::sim
