// GestureEngine: k-of-n onset, blips, hysteresis, switching, repeats on the ManualClock,
// run-time recognizer swap, options. A scripted recognizer reads the gesture it should
// report straight out of the landmarks, so each frame's verdict is exactly what the test says.
#include <gtest/gtest.h>

#include <atomic>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "gbdcs/contracts/clock.hpp"
#include "gbdcs/gesture/gesture_engine.hpp"

namespace gbdcs::gesture {
namespace {

using contracts::GestureEvent;
using contracts::GestureType;
using contracts::Landmarks;
using std::chrono::milliseconds;

// points[0].x = the gesture's index, points[0].y = its confidence.
Landmarks frame(GestureType g, double confidence = 0.9,
                contracts::Handedness hand = contracts::Handedness::kRight) {
  Landmarks h;
  h.points[0] = {static_cast<double>(g), confidence, 0};
  h.handedness = hand;
  h.score = 1;
  return h;
}

class ScriptedRecognizer final : public GestureRecognizer {
 public:
  explicit ScriptedRecognizer(std::string_view name = "scripted") : name_(name) {}
  std::string_view name() const override { return name_; }
  Recognition recognize(const Landmarks& h) const override {
    return {static_cast<GestureType>(static_cast<int>(h.points[0].x)), h.points[0].y};
  }

 private:
  std::string_view name_;
};

// Reports one fixed gesture whatever it sees.
class FixedRecognizer final : public GestureRecognizer {
 public:
  FixedRecognizer(std::string_view name, GestureType g) : name_(name), gesture_(g) {}
  std::string_view name() const override { return name_; }
  Recognition recognize(const Landmarks&) const override { return {gesture_, 0.95}; }

 private:
  std::string_view name_;
  GestureType gesture_;
};

struct Harness {
  contracts::ManualClock clock;
  GestureEngine engine;
  std::int64_t next_frame = 1;
  std::vector<GestureEvent> events;

  explicit Harness(GestureEngineOptions o = {})
      : engine(clock, std::make_unique<ScriptedRecognizer>(), o) {}

  // Feeds `count` frames 33 ms apart; returns how many events they produced.
  int feed(std::optional<Landmarks> hand, int count = 1) {
    int produced = 0;
    for (int i = 0; i < count; ++i) {
      clock.advance(milliseconds(33));
      if (auto e = engine.process(hand, next_frame++)) {
        events.push_back(*e);
        ++produced;
      }
    }
    return produced;
  }
  int feed(GestureType g, int count = 1) { return feed(frame(g), count); }
};

TEST(GestureEngine, OnsetNeedsKOfNFrames) {
  Harness h;
  EXPECT_EQ(h.feed(GestureType::kFist, 4), 0);
  EXPECT_EQ(h.engine.active(), GestureType::kNone);
  EXPECT_EQ(h.feed(GestureType::kFist), 1);
  const GestureEvent& e = h.events.back();
  EXPECT_EQ(e.gesture, GestureType::kFist);
  EXPECT_FALSE(e.repeat);
  EXPECT_EQ(e.frame_id, 5);
  EXPECT_NEAR(e.confidence, 0.9, 1e-12);
  EXPECT_EQ(e.timestamp, h.clock.utc_now());
  EXPECT_EQ(h.engine.active(), GestureType::kFist);
  EXPECT_NEAR(h.engine.active_confidence(), 0.9, 1e-12);
}

TEST(GestureEngine, KOfNNotConsecutive) {
  Harness h;
  // F F - F F F: five of the last six (window seven) agree.
  h.feed(GestureType::kFist, 2);
  h.feed(GestureType::kNone);
  EXPECT_EQ(h.feed(GestureType::kFist, 2), 0);
  EXPECT_EQ(h.feed(GestureType::kFist), 1);
}

TEST(GestureEngine, ShortBlipProducesNoEvent) {
  Harness h;
  h.feed(GestureType::kNone, 7);
  EXPECT_EQ(h.feed(GestureType::kOpenPalm, 4), 0);  // k - 1 frames
  EXPECT_EQ(h.feed(GestureType::kNone, 10), 0);
  EXPECT_EQ(h.feed(std::nullopt, 3), 0);
  EXPECT_TRUE(h.events.empty());
  EXPECT_EQ(h.engine.active(), GestureType::kNone);
}

TEST(GestureEngine, LowConfidenceFramesDoNotCount) {
  Harness h;
  EXPECT_EQ(h.feed(frame(GestureType::kFist, 0.59), 10), 0);
  EXPECT_EQ(h.feed(frame(GestureType::kFist, 0.6), 4), 0);
  EXPECT_EQ(h.feed(frame(GestureType::kFist, 0.6)), 1);
}

TEST(GestureEngine, NoneIsNeverAnEvent) {
  Harness h;
  h.feed(GestureType::kNone, 30);
  h.feed(std::nullopt, 30);
  EXPECT_TRUE(h.events.empty());
}

TEST(GestureEngine, HysteresisKeepsAGestureThroughNoisyFrames) {
  Harness h({.repeat_interval_s = 100});  // onsets only
  h.feed(GestureType::kFist, 5);
  ASSERT_EQ(h.events.size(), 1u);
  // Two bad frames, two good, over and over: at least three of any seven agree.
  for (int i = 0; i < 6; ++i) {
    h.feed(GestureType::kNone);
    EXPECT_EQ(h.engine.active(), GestureType::kFist) << i;
    h.feed(std::nullopt);
    EXPECT_EQ(h.engine.active(), GestureType::kFist) << i;
    h.feed(GestureType::kFist, 2);
    EXPECT_EQ(h.engine.active(), GestureType::kFist) << i;
  }
  EXPECT_EQ(h.events.size(), 1u);  // no second onset
  // Release: fewer than three of seven.
  h.feed(GestureType::kNone, 5);
  EXPECT_EQ(h.engine.active(), GestureType::kNone);
  EXPECT_EQ(h.engine.active_confidence(), 0);
  // A fresh onset needs k of n again.
  const auto before = h.events.size();
  h.feed(GestureType::kFist, 4);
  EXPECT_EQ(h.events.size(), before);
  h.feed(GestureType::kFist);
  ASSERT_EQ(h.events.size(), before + 1);
  EXPECT_FALSE(h.events.back().repeat);
}

TEST(GestureEngine, NoHandReleasesTheGesture) {
  Harness h;
  h.feed(GestureType::kVictory, 5);
  h.feed(std::nullopt, 4);
  EXPECT_EQ(h.engine.active(), GestureType::kVictory);  // three of seven left
  h.feed(std::nullopt);
  EXPECT_EQ(h.engine.active(), GestureType::kNone);
}

TEST(GestureEngine, SwitchingNeedsKOfNForTheNewGesture) {
  Harness h;
  h.feed(GestureType::kFist, 7);
  h.events.clear();
  EXPECT_EQ(h.feed(GestureType::kOpenPalm, 4), 0);
  EXPECT_EQ(h.engine.active(), GestureType::kFist);  // still three fists in the window
  EXPECT_EQ(h.feed(GestureType::kOpenPalm), 1);
  EXPECT_EQ(h.events.back().gesture, GestureType::kOpenPalm);
  EXPECT_FALSE(h.events.back().repeat);
  EXPECT_EQ(h.engine.active(), GestureType::kOpenPalm);
}

TEST(GestureEngine, AlternatingGesturesNeverSettle) {
  Harness h;
  for (int i = 0; i < 20; ++i) {
    h.feed(GestureType::kPointLeft);
    h.feed(GestureType::kPointRight);
  }
  EXPECT_TRUE(h.events.empty());
}

TEST(GestureEngine, RepeatsAreTimedOnTheInjectedClock) {
  GestureEngineOptions o;
  o.repeat_interval_s = 0.5;
  Harness h(o);
  for (int i = 0; i < 5; ++i) {
    h.clock.advance(milliseconds(100));
    h.engine.process(frame(GestureType::kThumbUp), i);
  }
  ASSERT_EQ(h.engine.active(), GestureType::kThumbUp);
  const auto onset = h.clock.now();
  std::vector<double> refresh_s;
  for (int i = 0; i < 25; ++i) {  // 2.5 s at 10 fps
    h.clock.advance(milliseconds(100));
    if (auto e = h.engine.process(frame(GestureType::kThumbUp), 100 + i)) {
      EXPECT_TRUE(e->repeat);
      EXPECT_EQ(e->gesture, GestureType::kThumbUp);
      EXPECT_EQ(e->timestamp, h.clock.utc_now());
      refresh_s.push_back(contracts::to_seconds(h.clock.now() - onset));
    }
  }
  ASSERT_EQ(refresh_s.size(), 5u);
  for (std::size_t i = 0; i < refresh_s.size(); ++i) EXPECT_NEAR(refresh_s[i], 0.5 * (i + 1), 1e-9);

  // Without the clock moving, no refresh however many frames come.
  for (int i = 0; i < 50; ++i) EXPECT_FALSE(h.engine.process(frame(GestureType::kThumbUp), 500));
}

TEST(GestureEngine, RefreshWaitsForAFrameThatShowsTheGesture) {
  Harness h;
  h.feed(GestureType::kFist, 5);
  h.clock.advance(milliseconds(600));
  EXPECT_FALSE(h.engine.process(frame(GestureType::kNone), 50));  // due, but not shown
  const auto e = h.engine.process(frame(GestureType::kFist), 51);
  ASSERT_TRUE(e);
  EXPECT_TRUE(e->repeat);
  EXPECT_EQ(e->frame_id, 51);
}

TEST(GestureEngine, EventCarriesTheHandedness) {
  Harness h;
  h.feed(frame(GestureType::kFist, 0.8, contracts::Handedness::kLeft), 5);
  ASSERT_EQ(h.events.size(), 1u);
  EXPECT_EQ(h.events[0].handedness, contracts::Handedness::kLeft);
}

TEST(GestureEngine, RecognizerSwapAtRunTimeClearsTheWindow) {
  contracts::ManualClock clock;
  GestureEngine engine(clock, std::make_unique<FixedRecognizer>("fists", GestureType::kFist));
  EXPECT_EQ(engine.recognizer_name(), "fists");
  for (int i = 0; i < 5; ++i) engine.process(frame(GestureType::kNone), i);
  ASSERT_EQ(engine.active(), GestureType::kFist);

  engine.set_recognizer(std::make_unique<FixedRecognizer>("palms", GestureType::kOpenPalm));
  EXPECT_EQ(engine.recognizer_name(), "palms");
  EXPECT_EQ(engine.active(), GestureType::kNone);
  for (int i = 0; i < 4; ++i) EXPECT_FALSE(engine.process(frame(GestureType::kNone), 10 + i));
  const auto e = engine.process(frame(GestureType::kNone), 14);
  ASSERT_TRUE(e);
  EXPECT_EQ(e->gesture, GestureType::kOpenPalm);
  EXPECT_THROW(engine.set_recognizer(nullptr), std::invalid_argument);
  EXPECT_EQ(engine.recognizer_name(), "palms");
}

TEST(GestureEngine, SwapWhileAnotherThreadProcesses) {
  contracts::ManualClock clock;
  GestureEngine engine(clock, std::make_unique<FixedRecognizer>("a", GestureType::kFist));
  std::atomic<bool> stop{false};
  std::thread worker([&] {
    for (std::int64_t i = 0; !stop; ++i) {
      if (auto e = engine.process(frame(GestureType::kNone), i)) {
        EXPECT_NE(e->gesture, GestureType::kNone);
      }
    }
  });
  for (int i = 0; i < 200; ++i) {
    engine.set_recognizer(std::make_unique<FixedRecognizer>(
        i % 2 ? "a" : "b", i % 2 ? GestureType::kFist : GestureType::kVictory));
    const std::string_view name = engine.recognizer_name();
    EXPECT_TRUE(name == "a" || name == "b");
    std::this_thread::yield();
  }
  stop = true;
  worker.join();
  // Still coherent afterwards: a fresh window, k frames to an onset.
  engine.set_recognizer(std::make_unique<FixedRecognizer>("c", GestureType::kILoveYou));
  for (int i = 0; i < 4; ++i) EXPECT_FALSE(engine.process(frame(GestureType::kNone), i));
  const auto e = engine.process(frame(GestureType::kNone), 4);
  ASSERT_TRUE(e);
  EXPECT_EQ(e->gesture, GestureType::kILoveYou);
}

TEST(GestureEngine, ResetForgetsEverything) {
  Harness h;
  h.feed(GestureType::kFist, 6);
  h.engine.reset();
  EXPECT_EQ(h.engine.active(), GestureType::kNone);
  EXPECT_EQ(h.feed(GestureType::kFist, 4), 0);
  EXPECT_EQ(h.feed(GestureType::kFist), 1);
}

TEST(GestureEngine, ConstructorRejectsNullRecognizerAndBadOptions) {
  contracts::ManualClock clock;
  EXPECT_THROW(GestureEngine(clock, nullptr), std::invalid_argument);
  GestureEngineOptions o;
  o.agree_frames = 8;
  EXPECT_THROW(GestureEngine(clock, std::make_unique<ScriptedRecognizer>(), o),
               std::invalid_argument);
}

void expect_rejected(const nlohmann::json& doc, const std::string& key) {
  try {
    gesture_engine_options_from_json(doc);
    ADD_FAILURE() << "accepted " << doc.dump();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'" + key + "'"), std::string::npos) << e.what();
  }
}

TEST(GestureEngineOptions, FromJson) {
  const GestureEngineOptions d = gesture_engine_options_from_json(nlohmann::json::object());
  EXPECT_EQ(d.window_frames, 7);
  EXPECT_EQ(d.agree_frames, 5);
  EXPECT_EQ(d.release_frames, 3);
  EXPECT_EQ(d.min_confidence, 0.6);
  EXPECT_EQ(d.repeat_interval_s, 0.5);
  const GestureEngineOptions o = gesture_engine_options_from_json(
      {{"window_frames", 10}, {"agree_frames", 6}, {"repeat_interval_s", 1.5}});
  EXPECT_EQ(o.window_frames, 10);
  EXPECT_EQ(o.agree_frames, 6);
  EXPECT_EQ(o.repeat_interval_s, 1.5);
  EXPECT_EQ(gesture_engine_options_from_json(to_json(o)).window_frames, 10);

  expect_rejected({{"window", 7}}, "window");
  expect_rejected({{"window_frames", 7.5}}, "window_frames");
  expect_rejected({{"window_frames", "7"}}, "window_frames");
  expect_rejected({{"min_confidence", "high"}}, "min_confidence");
  expect_rejected({{"min_confidence", 1.2}}, "min_confidence");
  expect_rejected({{"agree_frames", 9}}, "agree_frames");
  expect_rejected({{"release_frames", 6}}, "release_frames");
  expect_rejected({{"release_frames", 0}}, "release_frames");
  expect_rejected({{"repeat_interval_s", 0}}, "repeat_interval_s");
  expect_rejected({{"repeat_interval_s", false}}, "repeat_interval_s");
  expect_rejected({{"window_frames", 1000000000000LL}}, "window_frames");
  EXPECT_THROW(gesture_engine_options_from_json("7"), std::invalid_argument);
}

}  // namespace
}  // namespace gbdcs::gesture
