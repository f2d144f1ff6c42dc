// ScenarioRunner: runs one Scenario through the production core, lockstep and faster than
// real time, and judges its criteria.
//
// Wiring (the same classes as `gbdcs fly` and `gbdcs serve`): camera frames -> ControlLoop
// (GestureEngine with the RuleBasedRecognizer, CommandTranslator with the scenario's profile,
// CommandArbiter, FailsafeMonitor with the scenario's failsafe options) -> the drone's adapter
// (sim::TwinAdapter, adapters::DummyDroneAdapter, or the registry's real Tello / AirSim /
// XFly adapter talking over loopback sockets to the twin's in-process emulator). A
// ManualClock is the only clock: each step sets it to frame i / fps, applies the events due,
// hands the frame to the loop, and ticks the loop (which steps the twin to that time and runs
// the failsafe timers). An emulator drone's twin is stepped by the runner too, and each step
// waits (real time, bounded) until nothing is in flight on its sockets (docs/SCENARIOS.md).
//
// Events : physical and radio faults (link_loss, telemetry_delay, battery_jump, wind_gust,
//          motor_fault) go into the twin's FaultSchedule on simulated time (the dummy takes
//          link_loss and battery_jump); vision_crash stops delivering frames (detect "exit":
//          the supervisor also reports the worker dead at once, as gbdcs serve does) until
//          duration_s is over; vision_unhealthy reports the pipeline unhealthy while frames
//          still flow; emergency_stop and key act like the operator.
// Output : ScenarioResult with every criterion's verdict. Artifacts (when asked, or when the
//          scenario failed and an artifacts folder is set): <dir>/<name>/events.jsonl (every
//          gesture, command, alert, event and telemetry frame), trajectory.png, and video.mp4
//          (the twin's chase camera beside the hand the camera saw, 10 frames per simulated
//          second, so it plays at real speed).
// Errors : a drone or event the run cannot provide, a model that will not load: the result
//          carries the error and fails (never a pass).
// Threads: run_scenario is re-entrant; run several on separate threads (the twin model is
//          shared read-only, each run renders with its own OSMesa context).
#pragma once

#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "gbdcs/sim/scenario.hpp"
#include "gbdcs/sim/scenario_criteria.hpp"

namespace gbdcs::sim {

struct RunOptions {
  std::string artifacts_dir;        // empty: write no artifacts
  bool artifacts_always = false;    // false: only for failed scenarios
  nlohmann::json failsafe_override;  // merged over the scenario's failsafe (tests of the suite)
  double video_fps = 10;
  bool keep_record = false;  // copy the RunRecord into the result (tests)
  // Pixel cameras (recipe, video): where recipes are rendered once and kept (the cache
  // `gbdcs eval --cache` uses; empty: <temp>/gbdcs-fixture-cache) and the hand models.
  std::string fixture_cache_dir;
  std::string model = "full";  // full | lite
  std::string model_dir;       // empty: $GBDCS_MODEL_DIR or the build tree's models/
};

struct ScenarioResult {
  std::string name;
  std::string path;
  std::string description;
  std::string drone;
  std::string camera;
  std::string error;  // why the scenario could not run (malformed file, ...); empty when it ran
  std::vector<CriterionResult> criteria;
  bool passed = false;
  double sim_s = 0;
  double wall_s = 0;
  std::vector<std::string> artifacts;  // files written
  RunRecord record;                    // when RunOptions::keep_record
};

ScenarioResult run_scenario(const Scenario& scenario, const RunOptions& options = {});
// Loads and runs; a file that does not load is a failed result whose error names the field.
ScenarioResult run_scenario_file(const std::string& path, const RunOptions& options = {});

}  // namespace gbdcs::sim
