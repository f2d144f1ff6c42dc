// What a scenario run recorded, and the criteria judged on it (the CARLA ScenarioRunner
// model: each criterion has an expected and an actual value and a verdict SUCCESS,
// ACCEPTABLE or FAILURE; a scenario passes when no criterion is a FAILURE).
//
// Inputs : a RunRecord (the runner fills it; tests build one by hand) and the Scenario.
// Output : one CriterionResult per criterion, in the scenario's order.
// Rule   : a criterion that cannot be evaluated (no samples, no labelled segment, a drone
//          that cannot report collisions, ...) is a FAILURE whose actual says why, never a
//          pass.
// Times  : t_s is simulated seconds since the scenario started; for a camera, video time is
//          the same clock (frame i is shown at i / fps).
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "gbdcs/contracts/messages.hpp"
#include "gbdcs/sim/scenario.hpp"

namespace gbdcs::sim {

enum class Verdict { kSuccess, kAcceptable, kFailure };
std::string_view to_string(Verdict v);  // "SUCCESS", "ACCEPTABLE", "FAILURE"

struct RecordedCommand {
  double t_s = 0;
  contracts::DroneCommand command;
  std::string outcome;  // "OK", "REFUSED: ...", "DROPPED: ...", "NOT_CONNECTED: ..."
  double processing_ms = -1;  // gesture commands that reached the adapter: capture -> dispatch
};

struct RecordedGesture {
  double t_s = 0;
  contracts::GestureEvent event;
};

struct RecordedAlert {
  double t_s = 0;
  contracts::Alert alert;
};

struct RecordedTelemetry {
  double t_s = 0;
  contracts::TelemetryFrame frame;
};

// A stretch of the camera's video with its ground-truth label (timeline segments, a recipe's
// labels.json). gesture is set when the label is a deliberate gesture.
struct LabelledSegment {
  double start_s = 0;
  double end_s = 0;
  std::string label;
  std::optional<contracts::GestureType> gesture;
  long frames_shown = 0;  // frames of it that reached the core (0: vision was down throughout)
};

struct RunRecord {
  std::vector<RecordedCommand> commands;
  std::vector<RecordedGesture> gestures;
  std::vector<RecordedAlert> alerts;
  std::vector<RecordedTelemetry> telemetry;
  std::vector<LabelledSegment> segments;
  std::optional<int> collisions;  // nullopt: the drone cannot tell
  double end_s = 0;
  // The gestures the profile maps to a command (onset-to-dispatch needs one).
  std::vector<contracts::GestureType> mapped_gestures;
};

struct CriterionResult {
  std::string name;
  CriterionType type = CriterionType::kFinalState;
  std::string expected;
  std::string actual;
  Verdict verdict = Verdict::kFailure;
};

CriterionResult evaluate(const Criterion& criterion, const RunRecord& record);
std::vector<CriterionResult> evaluate_all(const Scenario& scenario, const RunRecord& record);

bool matches(const CommandPattern& pattern, const RecordedCommand& command);
std::string short_form(const RecordedCommand& command);  // "MOVE:POINT_LEFT=OK"

// The p-th percentile (nearest rank) of v; v must not be empty.
double percentile(std::vector<double> v, double p);

}  // namespace gbdcs::sim
