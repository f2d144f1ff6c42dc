// VisionPipeline with a fake HandFinder: order, the queue policies, preprocessing, the
// classify stage, timing from the injected clock, health, and shutdown.
#include <gtest/gtest.h>

#include <atomic>
#include <utility>
#include <nlohmann/json.hpp>

#include "gbdcs/vision/vision_pipeline.hpp"
#include "pipeline_fakes.hpp"

namespace gbdcs::vision {
namespace {

using namespace std::chrono_literals;
using contracts::GestureType;
using testing::FakeFinder;
using testing::Gate;
using testing::hand;
using testing::solid;
using testing::Waiter;

// Everything the callback saw, under a lock, with a waiter to block on.
struct Collected {
  Waiter waiter;
  std::vector<FrameResult> results;

  VisionPipeline::ResultCallback callback() {
    return [this](const FrameResult& r) {
      {
        std::lock_guard lock(waiter.mutex());
        results.push_back(r);
      }
      waiter.notify();
    };
  }
  bool wait_for_count(std::size_t n) {
    return waiter.wait_until([&] { return results.size() >= n; });
  }
  std::vector<std::int64_t> ids() {
    std::lock_guard lock(waiter.mutex());
    std::vector<std::int64_t> out;
    for (const auto& r : results) out.push_back(r.frame_id);
    return out;
  }
  std::size_t size() {
    std::lock_guard lock(waiter.mutex());
    return results.size();
  }
};

std::unique_ptr<CaptureSource> frames(const contracts::Clock& clock, int count, bool live,
                                      int width = 64, int height = 48) {
  return std::make_unique<GeneratorSource>(
      [=](std::int64_t id) -> std::optional<cv::Mat> {
        if (id >= count) return std::nullopt;
        return solid(width, height, {static_cast<std::uint8_t>(id % 256), 0, 0});
      },
      clock, live ? "fake:live" : "fake:offline", live);
}

TEST(VisionPipeline, OfflineSourceDeliversEveryFrameInOrder) {
  contracts::ManualClock clock;
  Collected got;
  PipelineOptions options;
  options.queue_capacity = 1;  // the smallest queues: a drop would show at once
  VisionPipeline p(frames(clock, 60, false), std::make_unique<FakeFinder>(), clock, got.callback(),
                   options);
  p.start();
  ASSERT_TRUE(p.wait_for(20s));
  std::vector<std::int64_t> expected(60);
  for (int i = 0; i < 60; ++i) expected[static_cast<std::size_t>(i)] = i;
  EXPECT_EQ(got.ids(), expected);
  const auto m = p.metrics();
  EXPECT_EQ(m.policy, OverflowPolicy::kBlock);
  EXPECT_TRUE(m.healthy) << m.reason;
  EXPECT_TRUE(m.finished);
  EXPECT_FALSE(m.running);
  EXPECT_EQ(m.frames_captured, 60);
  EXPECT_EQ(m.frames_done, 60);
  EXPECT_EQ(m.frames_dropped, 0);
}

TEST(VisionPipeline, LiveSourceDropsTheOldestFramesWhenTheTrackerFallsBehind) {
  contracts::ManualClock clock;
  Collected got;
  Gate finder_gate;     // holds the landmarks stage until every frame has been captured
  Gate generator_gate;  // holds the camera after its 100 frames
  std::atomic<int> produced{0};
  Waiter produced_all;
  auto source = std::make_unique<GeneratorSource>(
      [&](std::int64_t id) -> std::optional<cv::Mat> {
        if (id >= 100) {
          produced_all.notify();  // frame 99 has been counted by now
          generator_gate.wait();
        }
        produced = static_cast<int>(id) + 1;
        produced_all.notify();
        return solid(16, 12, {0, 0, 0});
      },
      clock, "fake:camera", /*live=*/true);
  PipelineOptions options;
  options.queue_capacity = 1;
  VisionPipeline p(std::move(source),
                   std::make_unique<FakeFinder>(FakeFinder::Script{},
                                                [&](int, const cv::Mat&) { finder_gate.wait(); }),
                   clock, got.callback(), options);
  p.start();
  ASSERT_TRUE(produced_all.wait_until([&] { return p.metrics().frames_captured >= 100; }));
  finder_gate.open();
  // Every captured frame ends up either through the pipeline or dropped by a queue, and every
  // frame done has reached the callback (the pipeline counts a frame done just before it calls
  // back: waiting on the count alone raced, as ThreadSanitizer's slower run showed).
  ASSERT_TRUE(got.waiter.wait_until([&] {
    const auto m = p.metrics();
    return m.frames_done + m.frames_dropped == 100 && std::cmp_equal(got.results.size(), m.frames_done);
  }));
  const auto m = p.metrics();
  EXPECT_EQ(m.policy, OverflowPolicy::kDropOldest);
  EXPECT_GE(m.frames_dropped, 90);  // at most four frames fit in the stages and queues
  const auto ids = got.ids();
  ASSERT_FALSE(ids.empty());
  EXPECT_TRUE(std::is_sorted(ids.begin(), ids.end()));
  EXPECT_EQ(std::adjacent_find(ids.begin(), ids.end()), ids.end());  // no duplicates
  EXPECT_EQ(ids.back(), 99);  // the newest frame always survives
  EXPECT_TRUE(m.healthy) << m.reason;
  generator_gate.open();
  p.stop();
}

TEST(VisionPipeline, PolicyCanBeForced) {
  contracts::ManualClock clock;
  Collected got;
  PipelineOptions options;
  options.policy = OverflowPolicy::kBlock;
  Gate generator_gate;
  auto source = std::make_unique<GeneratorSource>(
      [&](std::int64_t id) -> std::optional<cv::Mat> {
        if (id >= 30) generator_gate.wait();
        return solid(16, 12, {0, 0, 0});
      },
      clock, "fake:camera", true);
  VisionPipeline p(std::move(source), std::make_unique<FakeFinder>(), clock, got.callback(),
                   options);
  p.start();
  ASSERT_TRUE(got.wait_for_count(30));
  EXPECT_EQ(p.metrics().policy, OverflowPolicy::kBlock);
  EXPECT_EQ(p.metrics().frames_dropped, 0);
  auto ids = got.ids();
  ids.resize(30);
  for (int i = 0; i < 30; ++i) EXPECT_EQ(ids[static_cast<std::size_t>(i)], i);
  generator_gate.open();
  p.stop();
}

TEST(VisionPipeline, PreprocessTurnsBgrIntoRgbAndResizes) {
  contracts::ManualClock clock;
  Collected got;
  cv::Vec3b seen_pixel;
  cv::Size seen_size;
  auto source = std::make_unique<GeneratorSource>(
      [](std::int64_t id) -> std::optional<cv::Mat> {
        if (id > 0) return std::nullopt;
        return solid(64, 48, {10, 20, 30});  // B, G, R
      },
      clock, "fake:bgr", false, PixelOrder::kBgr);
  PipelineOptions options;
  options.resize_width = 32;  // height follows the aspect ratio
  VisionPipeline p(std::move(source),
                   std::make_unique<FakeFinder>(FakeFinder::Script{},
                                                [&](int, const cv::Mat& rgb) {
                                                  seen_pixel = rgb.at<cv::Vec3b>(0, 0);
                                                  seen_size = rgb.size();
                                                }),
                   clock, got.callback(), options);
  p.start();
  ASSERT_TRUE(p.wait_for(20s));
  EXPECT_EQ(seen_pixel, cv::Vec3b(30, 20, 10));
  EXPECT_EQ(seen_size, cv::Size(32, 24));
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got.results[0].width, 32);
  EXPECT_EQ(got.results[0].height, 24);
}

TEST(VisionPipeline, ClassifiesEveryHandAndFeedsTheStrongestToTheEngine) {
  contracts::ManualClock clock;
  Collected got;
  const auto palm = hand(sim::PoseName::kOpenPalm, 0.7, 0.3);
  const auto fist = hand(sim::PoseName::kFist, 0.95, 0.7);
  PipelineOptions options;  // engine: 5 of 7 frames
  VisionPipeline p(frames(clock, 8, false, 640, 480),
                   std::make_unique<FakeFinder>([&](int call, const cv::Mat&) {
                     if (call == 7) return std::vector<contracts::Landmarks>{};
                     return std::vector<contracts::Landmarks>{palm, fist};
                   }),
                   clock, got.callback(), options);
  p.start();
  ASSERT_TRUE(p.wait_for(20s));
  ASSERT_EQ(got.size(), 8u);
  for (int i = 0; i < 7; ++i) {
    const auto& r = got.results[static_cast<std::size_t>(i)];
    ASSERT_EQ(r.hands.size(), 2u);
    EXPECT_EQ(r.hands[0].gesture, GestureType::kOpenPalm);
    EXPECT_EQ(r.hands[1].gesture, GestureType::kFist);
    EXPECT_GT(r.hands[1].confidence, 0.6);
    EXPECT_DOUBLE_EQ(r.hands[1].landmarks.score, 0.95);
    // Onset on the fifth agreeing frame, of the strongest hand only.
    EXPECT_EQ(r.gesture_event.has_value(), i == 4) << "frame " << i;
    if (r.gesture_event) {
      EXPECT_EQ(r.gesture_event->gesture, GestureType::kFist);
      EXPECT_EQ(r.gesture_event->frame_id, 4);
      EXPECT_FALSE(r.gesture_event->repeat);
    }
  }
  EXPECT_TRUE(got.results[7].hands.empty());
}

TEST(HandClassifier, UsesTheFrameAspectRatio) {
  // An index pointing 30 degrees above the horizontal in a 4:1 frame: POINT_RIGHT. Read with
  // the default 4:3 aspect the same normalised points lean 60 degrees up: not POINT_RIGHT.
  std::mt19937 rng(3);
  sim::Placement placement;
  placement.aspect_ratio = 4.0;
  placement.size = 0.8;
  placement.roll_deg = -30;
  const auto pointing = sim::synthesize(sim::pose_for(sim::PoseName::kPointRight, rng), placement);
  HandClassifier classifier;
  EXPECT_NE(classifier.recognize(pointing).gesture, GestureType::kPointRight);
  classifier.set_frame_size(800, 200);
  EXPECT_EQ(classifier.recognize(pointing).gesture, GestureType::kPointRight);
  classifier.set_frame_size(0, 200);  // ignored
  EXPECT_EQ(classifier.classify({pointing}).at(0).gesture, GestureType::kPointRight);
}

TEST(VisionPipeline, StageTimingAndFpsComeFromTheInjectedClock) {
  contracts::ManualClock clock;
  Collected got;
  // The finder "takes" 1, 2, ..., 20 ms on the manual clock; nothing else advances it.
  VisionPipeline p(
      frames(clock, 20, false),
      std::make_unique<FakeFinder>(
          FakeFinder::Script{},
          [&](int call, const cv::Mat&) { clock.advance(std::chrono::milliseconds(call + 1)); }),
      clock, got.callback());
  p.start();
  ASSERT_TRUE(p.wait_for(20s));
  auto m = p.metrics();
  const auto& landmarks = m.stages[static_cast<std::size_t>(Stage::kLandmarks)];
  EXPECT_EQ(landmarks.samples, 20);
  EXPECT_DOUBLE_EQ(landmarks.p50_ms, 10);  // nearest rank: the 10th of 20
  EXPECT_DOUBLE_EQ(landmarks.p95_ms, 19);  // the 19th of 20
  EXPECT_DOUBLE_EQ(landmarks.max_ms, 20);
  // 20 frames over the 210 ms the clock moved since start().
  EXPECT_NEAR(m.fps, 20 / 0.210, 1e-9);
  clock.advance(2s);
  EXPECT_DOUBLE_EQ(p.metrics().fps, 0);
}

TEST(VisionPipeline, LiveSourceSilentForTooLongIsUnhealthyUntilAFrameArrives) {
  contracts::ManualClock clock;
  Collected got;
  Gate next_frame;
  std::atomic<bool> stopping{false};
  auto source = std::make_unique<GeneratorSource>(
      [&](std::int64_t id) -> std::optional<cv::Mat> {
        if (id == 1 || (id >= 2 && !stopping)) {
          next_frame.wait();
          next_frame.close();
        }
        return solid(16, 12, {0, 0, 0});
      },
      clock, "fake:camera", true);
  VisionPipeline p(std::move(source), std::make_unique<FakeFinder>(), clock, got.callback());
  p.start();
  ASSERT_TRUE(got.wait_for_count(1));
  EXPECT_TRUE(p.metrics().healthy);
  clock.advance(400ms);
  EXPECT_TRUE(p.metrics().healthy) << p.metrics().reason;
  clock.advance(200ms);
  auto m = p.metrics();
  EXPECT_FALSE(m.healthy);
  EXPECT_NE(m.reason.find("no frame from fake:camera for 0.60 s"), std::string::npos) << m.reason;
  next_frame.open();  // frame 1
  ASSERT_TRUE(got.wait_for_count(2));
  EXPECT_TRUE(p.metrics().healthy) << p.metrics().reason;
  stopping = true;
  next_frame.open();
  p.stop();
  EXPECT_TRUE(p.metrics().finished);
}

TEST(VisionPipeline, LiveSourceThatEndsIsUnhealthy) {
  contracts::ManualClock clock;
  Collected got;
  VisionPipeline p(frames(clock, 3, true), std::make_unique<FakeFinder>(), clock, got.callback());
  p.start();
  ASSERT_TRUE(p.wait_for(20s));
  const auto m = p.metrics();
  EXPECT_FALSE(m.healthy);
  EXPECT_NE(m.reason.find("fake:live ended unexpectedly"), std::string::npos) << m.reason;
  EXPECT_TRUE(m.finished);
}

TEST(VisionPipeline, SourceFailureIsUnhealthyWithItsReason) {
  contracts::ManualClock clock;
  Collected got;
  auto source = std::make_unique<GeneratorSource>(
      [](std::int64_t id) -> std::optional<cv::Mat> {
        if (id == 2) throw std::runtime_error("sensor unplugged");
        return solid(16, 12, {0, 0, 0});
      },
      clock, "fake:camera", true);
  VisionPipeline p(std::move(source), std::make_unique<FakeFinder>(), clock, got.callback());
  p.start();
  ASSERT_TRUE(p.wait_for(20s));
  const auto m = p.metrics();
  EXPECT_FALSE(m.healthy);
  EXPECT_NE(m.reason.find("capture stage"), std::string::npos) << m.reason;
  EXPECT_NE(m.reason.find("sensor unplugged"), std::string::npos) << m.reason;
}

TEST(VisionPipeline, FinderFailureStopsThePipelineAndSaysWhere) {
  contracts::ManualClock clock;
  Collected got;
  VisionPipeline p(frames(clock, 100, false),
                   std::make_unique<FakeFinder>(FakeFinder::Script{},
                                                [](int call, const cv::Mat&) {
                                                  if (call == 5)
                                                    throw std::runtime_error("bad tensor");
                                                }),
                   clock, got.callback());
  p.start();
  ASSERT_TRUE(p.wait_for(20s));
  const auto m = p.metrics();
  EXPECT_FALSE(m.healthy);
  EXPECT_NE(m.reason.find("landmarks stage: bad tensor"), std::string::npos) << m.reason;
  // Frames 0-4 may still have been queued for classify when the failure discarded the queues.
  EXPECT_LE(got.size(), 5u);
  for (auto id : got.ids()) EXPECT_LT(id, 5);
  EXPECT_LT(m.frames_captured, 100);
}

TEST(VisionPipeline, StopEndsAnEndlessLiveSourceAndNothingArrivesAfter) {
  contracts::ManualClock clock;
  Collected got;
  auto source = std::make_unique<GeneratorSource>(
      [](std::int64_t) -> std::optional<cv::Mat> {
        return solid(16, 12, {0, 0, 0});
      },
      clock, "fake:camera", true);
  VisionPipeline p(std::move(source), std::make_unique<FakeFinder>(), clock, got.callback());
  p.stop();  // before start: nothing to do
  p.start();
  EXPECT_THROW(p.start(), std::logic_error);
  ASSERT_TRUE(got.wait_for_count(10));
  p.stop();
  const auto after_stop = got.size();
  const auto m = p.metrics();
  EXPECT_TRUE(m.finished);
  EXPECT_FALSE(m.running);
  EXPECT_TRUE(m.healthy) << m.reason;  // a requested stop is not a failure
  p.stop();
  EXPECT_EQ(got.size(), after_stop);
}

TEST(VisionPipeline, StopFromTheCallbackDoesNotDeadlock) {
  contracts::ManualClock clock;
  std::atomic<int> seen{0};
  VisionPipeline* self = nullptr;
  auto source = std::make_unique<GeneratorSource>(
      [](std::int64_t) -> std::optional<cv::Mat> {
        return solid(16, 12, {0, 0, 0});
      },
      clock, "fake:camera", true);
  VisionPipeline p(std::move(source), std::make_unique<FakeFinder>(), clock,
                   [&](const FrameResult&) {
                     if (++seen == 3) self->stop();
                   });
  self = &p;
  p.start();
  ASSERT_TRUE(p.wait_for(20s));
  EXPECT_EQ(seen, 3);
}

TEST(VisionPipeline, DestructorStopsARunningPipeline) {
  contracts::ManualClock clock;
  Collected got;
  {
    auto source = std::make_unique<GeneratorSource>(
        [](std::int64_t) -> std::optional<cv::Mat> {
          return solid(16, 12, {0, 0, 0});
        },
        clock, "fake:camera", true);
    VisionPipeline p(std::move(source), std::make_unique<FakeFinder>(), clock, got.callback());
    p.start();
    ASSERT_TRUE(got.wait_for_count(3));
  }
  const auto n = got.size();
  EXPECT_GE(n, 3u);
}

TEST(VisionPipeline, RejectsMissingPartsAndBadOptions) {
  contracts::ManualClock clock;
  auto ok = [] { return [](const FrameResult&) {}; };
  EXPECT_THROW(VisionPipeline(nullptr, std::make_unique<FakeFinder>(), clock, ok()),
               std::invalid_argument);
  EXPECT_THROW(VisionPipeline(frames(clock, 1, false), nullptr, clock, ok()),
               std::invalid_argument);
  PipelineOptions bad;
  bad.queue_capacity = 0;
  EXPECT_THROW(
      VisionPipeline(frames(clock, 1, false), std::make_unique<FakeFinder>(), clock, ok(), bad),
      std::invalid_argument);
}

TEST(PipelineOptions, FromJsonReadsEveryKeyAndRejectsUnknownOnes) {
  const auto o = pipeline_options_from_json(nlohmann::json::parse(R"({
      "queue_capacity": 4, "policy": "drop_oldest", "resize_width": 320,
      "stall_timeout_s": 0.25, "timing_window": 30,
      "engine": {"window_frames": 5, "agree_frames": 3, "release_frames": 2},
      "recognizer": {"min_presence": 0.3}})"));
  EXPECT_EQ(o.queue_capacity, 4);
  EXPECT_EQ(o.policy, OverflowPolicy::kDropOldest);
  EXPECT_EQ(o.resize_width, 320);
  EXPECT_DOUBLE_EQ(o.stall_timeout_s, 0.25);
  EXPECT_EQ(o.timing_window, 30);
  EXPECT_EQ(o.engine.agree_frames, 3);
  EXPECT_DOUBLE_EQ(o.recognizer.min_presence, 0.3);
  EXPECT_FALSE(pipeline_options_from_json(nlohmann::json::parse(R"({"policy": "auto"})")).policy);
  auto message = [](const char* text) {
    try {
      pipeline_options_from_json(nlohmann::json::parse(text));
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("(accepted)");
  };
  EXPECT_NE(message(R"({"queue_size": 3})").find("'queue_size'"), std::string::npos);
  EXPECT_NE(message(R"({"policy": "newest"})").find("'policy'"), std::string::npos);
  EXPECT_NE(message(R"({"stall_timeout_s": 0})").find("'stall_timeout_s'"), std::string::npos);
}

}  // namespace
}  // namespace gbdcs::vision
