// Criteria judged on hand-made records: each can succeed, be acceptable and fail, and a
// criterion that cannot be evaluated fails.
#include <gtest/gtest.h>

#include "gbdcs/sim/scenario.hpp"
#include "gbdcs/sim/scenario_criteria.hpp"

namespace gbdcs::sim {
namespace {

using contracts::CommandSource;
using contracts::CommandType;

RecordedCommand cmd(double t, CommandType type, CommandSource source, std::string id,
                    std::string outcome = "OK") {
  RecordedCommand c;
  c.t_s = t;
  c.command.type = type;
  c.command.source = source;
  c.command.source_id = std::move(id);
  c.outcome = std::move(outcome);
  return c;
}

RecordedAlert alert(double t, std::string code) {
  RecordedAlert a;
  a.t_s = t;
  a.alert.code = std::move(code);
  return a;
}

Criterion failsafe_criterion() {
  Criterion c;
  c.type = CriterionType::kFailsafe;
  c.alert = "LINK_LOSS";
  c.action = CommandType::kHover;
  c.from_s = 5;
  c.success = 2500;
  c.acceptable = 3000;
  return c;
}

TEST(ScenarioCriteria, FailsafeSucceedsAcceptsAndFails) {
  RunRecord r;
  r.alerts.push_back(alert(7.0, "LINK_LOSS"));
  r.commands.push_back(cmd(7.0, CommandType::kHover, CommandSource::kFailsafe, "LINK_LOSS",
                           "NOT_CONNECTED: link lost"));
  EXPECT_EQ(evaluate(failsafe_criterion(), r).verdict, Verdict::kSuccess);

  r.alerts[0].t_s = 7.8;
  r.commands[0].t_s = 7.8;
  EXPECT_EQ(evaluate(failsafe_criterion(), r).verdict, Verdict::kAcceptable);

  r.alerts[0].t_s = 8.5;
  r.commands[0].t_s = 8.5;
  auto late = evaluate(failsafe_criterion(), r);
  EXPECT_EQ(late.verdict, Verdict::kFailure);
  EXPECT_NE(late.actual.find("LINK_LOSS at +3500 ms"), std::string::npos) << late.actual;

  RunRecord no_action;
  no_action.alerts.push_back(alert(6.0, "LINK_LOSS"));
  no_action.commands.push_back(
      cmd(6.0, CommandType::kHover, CommandSource::kFailsafe, "LINK_LOSS", "REFUSED: x"));
  auto r2 = evaluate(failsafe_criterion(), no_action);
  EXPECT_EQ(r2.verdict, Verdict::kFailure);
  EXPECT_NE(r2.actual.find("no HOVER from the failsafe reached the drone"), std::string::npos);

  auto never = evaluate(failsafe_criterion(), RunRecord{});
  EXPECT_EQ(never.verdict, Verdict::kFailure);
  EXPECT_NE(never.actual.find("LINK_LOSS never raised after 5.00 s"), std::string::npos);
}

TEST(ScenarioCriteria, CommandSequenceContainsInOrderNever) {
  RunRecord r;
  r.commands.push_back(cmd(1, CommandType::kTakeoff, CommandSource::kGesture, "THUMB_UP"));
  r.commands.push_back(cmd(2, CommandType::kMove, CommandSource::kGesture, "POINT_LEFT"));
  r.commands.push_back(cmd(3, CommandType::kLand, CommandSource::kGesture, "FIST"));
  Criterion c;
  c.type = CriterionType::kCommandSequence;
  c.in_order = {{CommandType::kTakeoff, {}, "", "OK"}, {CommandType::kLand, {}, "FIST", "OK"}};
  EXPECT_EQ(evaluate(c, r).verdict, Verdict::kSuccess);
  c.in_order = {{CommandType::kLand, {}, "", "OK"}, {CommandType::kTakeoff, {}, "", "OK"}};
  EXPECT_EQ(evaluate(c, r).verdict, Verdict::kFailure);
  c.in_order.clear();
  c.never = {{CommandType::kMove, {}, "", "any"}};
  auto forbidden = evaluate(c, r);
  EXPECT_EQ(forbidden.verdict, Verdict::kFailure);
  EXPECT_NE(forbidden.actual.find("forbidden MOVE:POINT_LEFT=OK at 2.00 s"), std::string::npos);
  c.never.clear();
  c.contains = {{CommandType::kTakeoff, {}, "", "REFUSED"}};
  EXPECT_EQ(evaluate(c, r).verdict, Verdict::kFailure);
}

TEST(ScenarioCriteria, FalsePositivesCountCommandsOutsideTheirGesture) {
  RunRecord r;
  r.segments = {{0, 2, "THUMB_UP", contracts::GestureType::kThumbUp, 60},
                {2, 4, "FOUR_FINGERS", std::nullopt, 60}};
  r.end_s = 6;
  r.commands.push_back(cmd(1, CommandType::kTakeoff, CommandSource::kGesture, "THUMB_UP"));
  r.commands.push_back(cmd(2.2, CommandType::kTakeoff, CommandSource::kGesture, "THUMB_UP"));
  Criterion c;
  c.type = CriterionType::kFalsePositives;
  EXPECT_EQ(evaluate(c, r).verdict, Verdict::kSuccess);  // 2.2 s is within the grace
  r.commands.push_back(cmd(3, CommandType::kHover, CommandSource::kGesture, "OPEN_PALM"));
  r.commands.push_back(cmd(5, CommandType::kHover, CommandSource::kGesture, "OPEN_PALM"));
  auto two = evaluate(c, r);
  EXPECT_EQ(two.verdict, Verdict::kFailure);
  EXPECT_EQ(two.actual.substr(0, 1), "2") << two.actual;
  c.acceptable = 2;
  EXPECT_EQ(evaluate(c, r).verdict, Verdict::kAcceptable);
  // scope all: a command for another gesture than the one shown counts too.
  RunRecord wrong;
  wrong.segments = {{0, 2, "THUMB_UP", contracts::GestureType::kThumbUp, 60}};
  wrong.commands.push_back(cmd(1, CommandType::kLand, CommandSource::kGesture, "FIST"));
  Criterion all;
  all.type = CriterionType::kFalsePositives;
  EXPECT_EQ(evaluate(all, wrong).verdict, Verdict::kSuccess);
  all.all_segments = true;
  EXPECT_EQ(evaluate(all, wrong).verdict, Verdict::kFailure);
}

TEST(ScenarioCriteria, AccuracyAndLatencyOnSegments) {
  RunRecord r;
  r.mapped_gestures = {contracts::GestureType::kThumbUp, contracts::GestureType::kFist};
  r.segments = {{0, 2, "THUMB_UP", contracts::GestureType::kThumbUp, 60},
                {2, 4, "FIST", contracts::GestureType::kFist, 60}};
  RecordedGesture g;
  g.t_s = 0.3;
  g.event.gesture = contracts::GestureType::kThumbUp;
  r.gestures.push_back(g);
  r.commands.push_back(cmd(0.3, CommandType::kTakeoff, CommandSource::kGesture, "THUMB_UP"));
  Criterion acc;
  acc.type = CriterionType::kRecognitionAccuracy;
  acc.success = 1.0;
  acc.acceptable = 0.5;
  auto half = evaluate(acc, r);
  EXPECT_EQ(half.verdict, Verdict::kAcceptable);
  EXPECT_NE(half.actual.find("missed FIST@2.0s"), std::string::npos) << half.actual;

  Criterion lat;
  lat.type = CriterionType::kLatency;
  lat.measure = LatencyMeasure::kOnsetToDispatch;
  lat.success = 400;
  lat.acceptable = 400;
  EXPECT_EQ(evaluate(lat, r).verdict, Verdict::kSuccess);
  lat.success = lat.acceptable = 200;
  EXPECT_EQ(evaluate(lat, r).verdict, Verdict::kFailure);

  Criterion proc;
  proc.type = CriterionType::kLatency;
  proc.measure = LatencyMeasure::kProcessing;
  proc.success = proc.acceptable = 50;
  auto none = evaluate(proc, r);  // no command carries a processing time: cannot evaluate
  EXPECT_EQ(none.verdict, Verdict::kFailure);
  EXPECT_NE(none.actual.find("not evaluated"), std::string::npos);
}

TEST(ScenarioCriteria, UnevaluableCriteriaFail) {
  RunRecord empty;
  for (auto type : {CriterionType::kFinalState, CriterionType::kMaxAltitude,
                    CriterionType::kNoCollision, CriterionType::kBatteryAbove,
                    CriterionType::kRecognitionAccuracy, CriterionType::kFalsePositives}) {
    Criterion c;
    c.type = type;
    c.flight_states = {contracts::FlightState::kReady};
    const auto r = evaluate(c, empty);
    EXPECT_EQ(r.verdict, Verdict::kFailure) << to_string(type);
    EXPECT_NE(r.actual.find("not evaluated"), std::string::npos) << r.actual;
  }
}

TEST(ScenarioCriteria, FinalStateAltitudeBattery) {
  RunRecord r;
  RecordedTelemetry t;
  t.t_s = 1;
  t.frame.altitude_m = 1.2;
  t.frame.battery_pct = 40;
  t.frame.flight_state = contracts::FlightState::kFlying;
  r.telemetry.push_back(t);
  t.t_s = 2;
  t.frame.altitude_m = 0;
  t.frame.battery_pct = 38;
  t.frame.flight_state = contracts::FlightState::kReady;
  t.frame.x_m = 3;
  r.telemetry.push_back(t);
  Criterion fs;
  fs.type = CriterionType::kFinalState;
  fs.flight_states = {contracts::FlightState::kReady};
  fs.altitude_range_m = std::array<double, 2>{0, 0.05};
  EXPECT_EQ(evaluate(fs, r).verdict, Verdict::kSuccess);
  fs.x_range_m = std::array<double, 2>{-2, 2};
  EXPECT_EQ(evaluate(fs, r).verdict, Verdict::kFailure);

  Criterion top;
  top.type = CriterionType::kMaxAltitude;
  top.success = 1.0;
  top.acceptable = 1.5;
  EXPECT_EQ(evaluate(top, r).verdict, Verdict::kAcceptable);

  Criterion bat;
  bat.type = CriterionType::kBatteryAbove;
  bat.success = 39;
  bat.acceptable = 35;
  EXPECT_EQ(evaluate(bat, r).verdict, Verdict::kAcceptable);
  bat.acceptable = 39;
  EXPECT_EQ(evaluate(bat, r).verdict, Verdict::kFailure);

  r.collisions = 1;
  Criterion col;
  col.type = CriterionType::kNoCollision;
  EXPECT_EQ(evaluate(col, r).verdict, Verdict::kFailure);
  r.collisions = 0;
  EXPECT_EQ(evaluate(col, r).verdict, Verdict::kSuccess);
}

}  // namespace
}  // namespace gbdcs::sim
