// Scenario: one end-to-end check of the production core, read from scenarios/*.json (the
// format is scenarios/schema.json and docs/SCENARIOS.md).
//
//   {"name": "idle_hover", "description": "...", "drone": "twin", "timeout_s": 12,
//    "camera": {"timeline": {...a gesture timeline, docs/TIMELINES.md...}},
//    "profile": "default", "failsafe": {...FailsafeOptions...},
//    "events": [{"at_s": 5, "type": "link_loss", "duration_s": 3}, ...],
//    "criteria": [{"type": "failsafe", "alert": "IDLE_HOVER", "action": "HOVER",
//                  "from_s": 4, "within_ms": 3600}, ...]}
//
// Loading is strict: an unknown key, a missing required key, a wrong type or a value out of
// range throws ScenarioError whose message names the file, the field as a JSON path
// ("criteria[2].within_ms") and how to fix it. Paths inside the file (timeline_file, recipe,
// video, labels, profile) are relative to the scenario file's folder.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "gbdcs/contracts/messages.hpp"

namespace gbdcs::sim {

class ScenarioError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

enum class DroneKind { kTwin, kDummy, kTelloEmulator, kAirsimEmulator, kXflyEmulator };
std::string_view to_string(DroneKind k);  // "twin", "dummy", "tello-emulator", ...
std::optional<DroneKind> drone_kind_from_string(std::string_view s);

struct DroneSpec {
  DroneKind kind = DroneKind::kTwin;
  nlohmann::json options = nlohmann::json::object();  // the adapter's own options
};

enum class CameraKind { kTimeline, kRecipe, kRecorded };
std::string_view to_string(CameraKind k);

struct CameraSpec {
  CameraKind kind = CameraKind::kTimeline;
  nlohmann::json timeline;  // kTimeline: the timeline document (inline or read from the file)
  std::string path;         // kRecipe: the recipe file; kRecorded: the video file
  std::string labels_path;  // kRecorded: the labels.json of the video
  double fps = 0;           // kRecorded: frames per second of the video (0: labels.json's)
};

enum class EventType {
  kLinkLoss,
  kTelemetryDelay,
  kBatteryJump,
  kWindGust,
  kMotorFault,
  kVisionCrash,
  kVisionUnhealthy,
  kEmergencyStop,
  kKey,
};
std::string_view to_string(EventType t);  // "link_loss", ...
std::optional<EventType> event_type_from_string(std::string_view s);

inline constexpr double kForever = std::numeric_limits<double>::infinity();

struct ScenarioEvent {
  EventType type = EventType::kLinkLoss;
  double at_s = 0;
  double duration_s = kForever;  // link_loss, telemetry_delay, wind_gust, motor_fault, vision_*
  double delay_ms = 0;           // telemetry_delay
  double jitter_ms = 0;
  double battery_pct = 0;           // battery_jump
  std::array<double, 3> force_n{};  // wind_gust: x forward, y right, z up
  int motor = 0;                    // motor_fault: 0 front-left ... 3 rear-left
  double thrust_factor = 1;
  bool detected_at_exit = false;  // vision_crash: "detect": "exit" (true) or "silence"
  std::string reason;             // vision_unhealthy
  std::string key;                // key: a KeyboardInput key name
  contracts::CommandSource source = contracts::CommandSource::kApi;  // emergency_stop

  std::string describe() const;  // "link_loss for 3 s", "key 't'", ...
};

enum class CriterionType {
  kLatency,
  kRecognitionAccuracy,
  kFalsePositives,
  kFailsafe,
  kAlerts,
  kCommandSequence,
  kFinalState,
  kMaxAltitude,
  kNoCollision,
  kBatteryAbove,
};
std::string_view to_string(CriterionType t);  // "latency", "recognition_accuracy", ...
std::optional<CriterionType> criterion_type_from_string(std::string_view s);

// Matches a recorded command: type, and optionally source, source_id and outcome (a prefix of
// the ControlLoop outcome: "OK", "REFUSED", "DROPPED", "REJECTED", "NOT_CONNECTED"; "any").
// Text form: "TYPE", "TYPE:SOURCE_ID", either with "=OUTCOME" ("TAKEOFF=REFUSED").
struct CommandPattern {
  contracts::CommandType type = contracts::CommandType::kHover;
  std::optional<contracts::CommandSource> source;
  std::string source_id;  // empty = any
  std::string outcome = "OK";

  std::string describe() const;  // the text form (with @source when set)
};

enum class LatencyMeasure { kProcessing, kOnsetToDispatch };

struct Criterion {
  CriterionType type = CriterionType::kFinalState;
  std::string name;  // "name" or the type plus a number

  // Thresholds. Lower-is-better criteria pass at <= success, are acceptable at <= acceptable;
  // higher-is-better ones (accuracy, battery) the other way round.
  double success = 0;
  double acceptable = 0;

  LatencyMeasure measure = LatencyMeasure::kProcessing;  // latency
  bool all_segments = false;  // false_positives: "scope": "all" (else "non_deliberate")
  double grace_s = 0.6;       // false_positives, recognition_accuracy, latency
  std::string alert;          // failsafe
  std::optional<contracts::CommandType> action;  // failsafe; nullopt = "none"
  std::optional<contracts::Severity> severity;   // failsafe
  double from_s = 0;                             // failsafe: the fault's time
  double not_before_ms = 0;  // failsafe: earlier than this after from_s is a FAILURE (too eager)
  std::vector<std::string> alerts_contain;       // alerts
  std::vector<std::string> alerts_never;
  std::vector<CommandPattern> contains;  // command_sequence
  std::vector<CommandPattern> in_order;
  std::vector<CommandPattern> never;
  std::vector<contracts::FlightState> flight_states;    // final_state
  std::optional<std::array<double, 2>> altitude_range_m;
  std::optional<std::array<double, 2>> x_range_m;
  std::optional<std::array<double, 2>> y_range_m;
};

struct Scenario {
  std::string name;
  std::string description;
  std::string path;  // the file it came from ("" when built in memory)
  DroneSpec drone;
  CameraSpec camera;
  nlohmann::json profile;   // a gesture profile document
  nlohmann::json failsafe;  // FailsafeOptions JSON (empty object = production defaults)
  double timeout_s = 30;
  std::vector<ScenarioEvent> events;  // sorted by at_s (stable)
  std::vector<Criterion> criteria;

  // `base_dir` resolves the relative paths; `origin` prefixes every error ("file.json").
  static Scenario from_json(const nlohmann::json& doc, const std::string& base_dir = ".",
                            const std::string& origin = "scenario");
  static Scenario load_file(const std::string& path);
};

// The scenario files in `path`: the file itself, or the *.json of a folder (not schema.json),
// sorted. Throws ScenarioError for a path that does not exist.
std::vector<std::string> scenario_files(const std::string& path);

}  // namespace gbdcs::sim
