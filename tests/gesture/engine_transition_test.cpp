// The recognizer and the engine together on synthesized hands: a FIST -> OPEN_PALM
// transition through half-open poses (blend()) yields one OPEN_PALM onset and nothing else;
// holding a direction gesture through landmark jitter yields one onset.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "gbdcs/contracts/clock.hpp"
#include "gbdcs/gesture/gesture_engine.hpp"
#include "gbdcs/gesture/rule_based_recognizer.hpp"
#include "synthetic_hands.hpp"

namespace gbdcs::gesture {
namespace {

using contracts::GestureEvent;
using contracts::GestureType;
using sim::PoseName;

struct Playback {
  std::vector<GestureEvent> events;
  std::vector<GestureType> per_frame;  // what the recognizer said, for the failure message
};

std::string describe(const Playback& run) {
  std::string out = "frames:";
  for (GestureType g : run.per_frame) out += " " + std::string(contracts::to_string(g));
  out += "\nevents:";
  for (const auto& e : run.events) {
    out += " " + std::string(contracts::to_string(e.gesture)) + "@" + std::to_string(e.frame_id) +
           (e.repeat ? "(repeat)" : "");
  }
  return out;
}

// Feeds the poses at 30 fps on a ManualClock; each frame gets the same placement and its own
// landmark jitter, as a steady hand in front of a camera would.
Playback play(const std::vector<sim::HandPose>& poses, const sim::Placement& placement,
         std::mt19937& rng, double repeat_interval_s) {
  contracts::ManualClock clock;
  GestureEngineOptions options;
  options.repeat_interval_s = repeat_interval_s;
  GestureEngine engine(clock, std::make_unique<RuleBasedRecognizer>(), options);
  const RuleBasedRecognizer probe;
  Playback run;
  std::int64_t frame_id = 0;
  for (const sim::HandPose& pose : poses) {
    clock.advance(std::chrono::milliseconds(33));
    contracts::Landmarks hand = sim::synthesize(pose, placement);
    sim::add_landmark_noise(hand, 0.01, placement.size, rng);
    run.per_frame.push_back(probe.recognize(hand).gesture);
    if (auto e = engine.process(hand, frame_id++)) run.events.push_back(*e);
  }
  return run;
}

TEST(EngineOnSynthesizedHands, FistToOpenPalmGivesExactlyOneOpenPalmOnset) {
  std::mt19937 rng(2024);
  testing::PlacementRange range;
  range.max_roll_deg = 180;
  constexpr int kTransitionFrames = 12;  // ~0.4 s from fist to open hand
  for (int trial = 0; trial < 40; ++trial) {
    const sim::HandPose fist = sim::pose_for(PoseName::kFist, rng);
    sim::HandPose open = sim::pose_for(PoseName::kOpenPalm, rng);
    open.orientation = fist.orientation;  // the hand opens where it is
    std::vector<sim::HandPose> poses(10, fist);
    for (int i = 1; i < kTransitionFrames; ++i) {
      poses.push_back(sim::blend(fist, open, static_cast<double>(i) / kTransitionFrames));
    }
    poses.insert(poses.end(), 15, open);

    const sim::Placement placement = testing::random_placement(rng, range);
    const Playback run = play(poses, placement, rng, 100.0);
    ASSERT_GE(run.events.size(), 1u) << describe(run);
    EXPECT_EQ(run.events.front().gesture, GestureType::kFist) << describe(run);
    const std::vector<GestureEvent> after(run.events.begin() + 1, run.events.end());
    ASSERT_EQ(after.size(), 1u) << "trial " << trial << "\n" << describe(run);
    EXPECT_EQ(after[0].gesture, GestureType::kOpenPalm);
    EXPECT_FALSE(after[0].repeat);
    EXPECT_GE(after[0].frame_id, 10 + kTransitionFrames - 1);  // not before the hand is open
  }
}

TEST(EngineOnSynthesizedHands, HeldPointLeftGivesOneOnsetThenTimedRefreshes) {
  std::mt19937 rng(99);
  const sim::HandPose pose = sim::pose_for(PoseName::kPointLeft, rng);
  sim::Placement placement = testing::random_placement(rng, testing::range_for(PoseName::kPointLeft));
  placement.presence = 0.95;
  const Playback run = play(std::vector<sim::HandPose>(60, pose), placement, rng, 0.5);  // ~2 s
  ASSERT_FALSE(run.events.empty()) << describe(run);
  EXPECT_EQ(run.events[0].gesture, GestureType::kPointLeft);
  EXPECT_FALSE(run.events[0].repeat);
  EXPECT_EQ(run.events[0].frame_id, 4);
  // 2 s of hold from frame 4 (0.165 s): refreshes at +0.5, +1.0, +1.5 s.
  ASSERT_EQ(run.events.size(), 4u) << describe(run);
  for (std::size_t i = 1; i < run.events.size(); ++i) {
    EXPECT_TRUE(run.events[i].repeat);
    EXPECT_EQ(run.events[i].gesture, GestureType::kPointLeft);
  }
}

}  // namespace
}  // namespace gbdcs::gesture
