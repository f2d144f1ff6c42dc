// The worker's JSON messages against their schemas; recognition records; the landmark
// comparison behind `gbdcs eval landmarks`.
#include <gtest/gtest.h>

#include "gbdcs/contracts/codec.hpp"
#include "gbdcs/vision/vision_messages.hpp"
#include "pipeline_fakes.hpp"

namespace gbdcs::vision {
namespace {

using contracts::GestureType;
using nlohmann::json;
using testing::hand;

std::string joined(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += x + "\n";
  return s;
}

FrameResult sample_result(bool with_event) {
  FrameResult r;
  r.frame_id = 12;
  r.capture_utc = contracts::UtcTime{std::chrono::milliseconds{1'767'225'600'123}};
  r.source = "camera:0";
  r.width = 640;
  r.height = 480;
  r.latency = std::chrono::milliseconds(9);
  r.hands.push_back({hand(sim::PoseName::kFist, 0.9), GestureType::kFist, 0.8});
  r.hands.push_back({hand(sim::PoseName::kOpenPalm, 0.6, 0.2), GestureType::kNone, 0.3});
  if (with_event) {
    contracts::GestureEvent e;
    e.gesture = GestureType::kFist;
    e.confidence = 0.8;
    e.frame_id = 12;
    e.timestamp = r.capture_utc;
    r.gesture_event = e;
  }
  return r;
}

TEST(VisionMessages, FrameMessageMatchesItsSchema) {
  for (bool with_event : {true, false}) {
    const auto doc = frame_message(sample_result(with_event));
    EXPECT_TRUE(contracts::violations("vision_frame", doc).empty())
        << joined(contracts::violations("vision_frame", doc)) << doc.dump(1);
    EXPECT_EQ(doc["type"], "frame");
    EXPECT_EQ(doc["capture_time"], "2026-01-01T00:00:00.123Z");
    EXPECT_EQ(doc["hands"][0]["gesture"], "FIST");
    EXPECT_EQ(doc["hands"][0]["landmarks"].size(), 21u);
    EXPECT_EQ(doc["hands"][1]["handedness"], "Right");
    EXPECT_EQ(doc["gesture_event"].is_null(), !with_event);
    EXPECT_DOUBLE_EQ(doc["latency_ms"].get<double>(), 9);
  }
}

TEST(VisionMessages, TheFrameSchemaCatchesBrokenMessages) {
  auto doc = frame_message(sample_result(true));
  doc["hands"][0]["landmarks"].erase(20);
  EXPECT_FALSE(contracts::violations("vision_frame", doc).empty());

  doc = frame_message(sample_result(true));
  doc["gesture_event"]["gesture"] = "WAVE";
  EXPECT_FALSE(contracts::violations("vision_frame", doc).empty());

  doc = frame_message(sample_result(false));
  doc.erase("gesture_event");
  EXPECT_FALSE(contracts::violations("vision_frame", doc).empty());

  doc = frame_message(sample_result(false));
  doc["type"] = "heartbeat";
  EXPECT_FALSE(contracts::violations("vision_frame", doc).empty());
}

TEST(VisionMessages, HeartbeatMatchesItsSchema) {
  PipelineMetrics m;
  m.source = "camera:0";
  m.healthy = false;
  m.reason = "no frame from camera:0 for 0.61 s (limit 0.50 s)";
  m.fps = 29.5;
  m.frames_captured = 100;
  m.frames_done = 90;
  m.frames_dropped = 10;
  m.stages[static_cast<std::size_t>(Stage::kLandmarks)] = {6.5, 8.25, 9, 120};
  for (auto& q : m.queues) q = {1, 2, 2, 5};
  const auto doc =
      heartbeat_message(m, contracts::UtcTime{std::chrono::milliseconds{1'767'225'600'000}});
  EXPECT_TRUE(contracts::violations("vision_heartbeat", doc).empty())
      << joined(contracts::violations("vision_heartbeat", doc)) << doc.dump(1);
  EXPECT_EQ(doc["type"], "heartbeat");
  EXPECT_EQ(doc["healthy"], false);
  EXPECT_DOUBLE_EQ(doc["stages"]["landmarks_ms_p50"].get<double>(), 6.5);
  EXPECT_DOUBLE_EQ(doc["stages"]["landmarks_ms_p95"].get<double>(), 8.25);
  EXPECT_EQ(doc["queues"]["classify"]["dropped"], 5);
  EXPECT_EQ(doc["frames"]["dropped"], 10);

  auto broken = doc;
  broken["stages"].erase("capture_ms_p95");
  EXPECT_FALSE(contracts::violations("vision_heartbeat", broken).empty());
  broken = doc;
  broken["fps"] = -1;
  EXPECT_FALSE(contracts::violations("vision_heartbeat", broken).empty());
}

// Before a pipeline exists (its camera still being prepared) the worker still owes the server
// heartbeats it accepts: not healthy, with the reason, the queues at the capacity they will
// have. A default PipelineMetrics is not one (its queues' capacity is 0).
TEST(VisionMessages, HeartbeatBeforeStartMatchesItsSchema) {
  const contracts::UtcTime at{std::chrono::milliseconds{1'767'225'600'000}};
  EXPECT_FALSE(contracts::violations("vision_heartbeat", heartbeat_message(PipelineMetrics{}, at))
                   .empty());

  PipelineOptions options;
  options.queue_capacity = 3;
  const auto m = metrics_before_start(options, "recipe:demo.json?live=1", true,
                                      "preparing the camera: 4 of 150 frames");
  const auto doc = heartbeat_message(m, at);
  EXPECT_TRUE(contracts::violations("vision_heartbeat", doc).empty())
      << joined(contracts::violations("vision_heartbeat", doc)) << doc.dump(1);
  EXPECT_EQ(doc["healthy"], false);
  EXPECT_EQ(doc["running"], false);
  EXPECT_EQ(doc["reason"], "preparing the camera: 4 of 150 frames");
  EXPECT_EQ(doc["source"], "recipe:demo.json?live=1");
  for (const char* q : {"preprocess", "landmarks", "classify"}) {
    EXPECT_EQ(doc["queues"][q]["capacity"], 3) << q;
    EXPECT_EQ(doc["queues"][q]["depth"], 0) << q;
  }
  EXPECT_EQ(m.policy, OverflowPolicy::kDropOldest);  // auto, for a live source
  EXPECT_EQ(metrics_before_start(options, "video:a.mp4", false, "").policy, OverflowPolicy::kBlock);

  options.queue_capacity = 0;
  EXPECT_THROW(metrics_before_start(options, "camera:0", true, ""), std::invalid_argument);
}

TEST(RecognitionRecords, RoundTripAndReadTheReferenceFormat) {
  RecognizedImage ours;
  ours.image = "dir/a.jpg";
  ours.frame = 3;
  ours.width = 320;
  ours.height = 240;
  ours.hands.push_back({hand(sim::PoseName::kVictory, 0.9), GestureType::kVictory, 0.75});
  const auto back = recognized_from_json(json::array({to_json(ours)}));
  ASSERT_EQ(back.size(), 1u);
  EXPECT_EQ(back[0].image, "dir/a.jpg");
  EXPECT_EQ(back[0].frame, 3);
  EXPECT_EQ(back[0].hands.at(0).gesture, GestureType::kVictory);
  EXPECT_DOUBLE_EQ(back[0].hands[0].landmarks.points[8].x, ours.hands[0].landmarks.points[8].x);

  // The MediaPipe reference's shape: no frame, gesture or confidence; extra keys ("ms").
  auto ref = json::parse(R"([{"image": "/abs/a.jpg", "width": 320, "height": 240, "ms": 812.5,
                              "hands": []}])");
  json points = json::array();
  for (int i = 0; i < 21; ++i) points.push_back({0.5, 0.5, -0.01});
  ref[0]["hands"].push_back({{"handedness", "Left"}, {"score", 0.97}, {"landmarks", points}});
  const auto read = recognized_from_json(ref);
  EXPECT_EQ(read.at(0).frame, 0);
  EXPECT_EQ(read[0].hands.at(0).landmarks.handedness, contracts::Handedness::kLeft);
  EXPECT_EQ(read[0].hands[0].gesture, GestureType::kNone);

  ref[0]["hands"][0]["landmarks"].erase(3);
  try {
    recognized_from_json(ref);
    ADD_FAILURE() << "20 landmarks accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("entry 0 (/abs/a.jpg) hand 0"), std::string::npos)
        << e.what();
  }
}

RecognizedImage record(const std::string& image, std::vector<contracts::Landmarks> hands) {
  RecognizedImage r;
  r.image = image;
  r.width = 640;
  r.height = 480;
  for (auto& h : hands) r.hands.push_back({h, GestureType::kNone, 0});
  return r;
}

// The same hand moved right by `pct` % of its bounding-box diagonal.
contracts::Landmarks shifted(contracts::Landmarks h, double pct, int width, int height) {
  double x0 = 1, x1 = 0, y0 = 1, y1 = 0;
  for (const auto& p : h.points) {
    x0 = std::min(x0, p.x);
    x1 = std::max(x1, p.x);
    y0 = std::min(y0, p.y);
    y1 = std::max(y1, p.y);
  }
  const double diagonal_px = std::hypot((x1 - x0) * width, (y1 - y0) * height);
  for (auto& p : h.points) p.x += pct / 100 * diagonal_px / width;
  return h;
}

TEST(LandmarkComparison, DistanceIsAPercentageOfTheReferenceHandsDiagonal) {
  const auto ref = hand(sim::PoseName::kOpenPalm, 0.9);
  const auto [mean, max] = landmark_distance_pct(shifted(ref, 1.0, 640, 480), ref, 640, 480);
  EXPECT_NEAR(mean, 1.0, 1e-9);
  EXPECT_NEAR(max, 1.0, 1e-9);
  EXPECT_DOUBLE_EQ(landmark_distance_pct(ref, ref, 640, 480).first, 0);
  // One landmark off by 21 % of the diagonal: the mean is 1 %, the max 21 %.
  const auto moved = shifted(ref, 21.0, 640, 480);
  auto one_point = ref;
  one_point.points[8] = moved.points[8];
  const auto [one_mean, one_max] = landmark_distance_pct(one_point, ref, 640, 480);
  EXPECT_NEAR(one_mean, 1.0, 1e-9);
  EXPECT_NEAR(one_max, 21.0, 1e-9);
}

TEST(LandmarkComparison, MatchesImagesByBasenameAndHandsByPosition) {
  const auto left = hand(sim::PoseName::kOpenPalm, 0.9, 0.25);
  const auto right = hand(sim::PoseName::kFist, 0.9, 0.75);
  // Ours lists the two hands the other way round, each off by a known amount.
  const std::vector<RecognizedImage> ours = {
      record("ours/two.jpg", {shifted(right, 2.0, 640, 480), shifted(left, 1.0, 640, 480)}),
      record("ours/missed.jpg", {}), record("ours/extra.jpg", {left}),
      record("ours/only_ours.jpg", {})};
  const std::vector<RecognizedImage> ref = {
      record("/ref/two.jpg", {left, right}), record("/ref/missed.jpg", {right}),
      record("/ref/extra.jpg", {}), record("/ref/only_ref.jpg", {})};
  const auto c = compare_landmarks(ours, ref);
  ASSERT_EQ(c.images.size(), 3u);
  const auto& two = c.images[0];
  EXPECT_EQ(two.image, "two.jpg");
  ASSERT_EQ(two.matches.size(), 2u);
  for (const auto& m : two.matches) {
    EXPECT_EQ(m.ours, 1 - m.ref);  // crossed order, matched by position
    EXPECT_NEAR(m.mean_distance_pct, m.ref == 0 ? 1.0 : 2.0, 1e-9);
  }
  EXPECT_TRUE(two.detection_agrees);
  EXPECT_NEAR(*two.mean_distance_pct, 1.5, 1e-9);

  EXPECT_FALSE(c.images[1].detection_agrees);  // we missed a hand
  EXPECT_FALSE(c.images[1].mean_distance_pct);
  EXPECT_FALSE(c.images[2].detection_agrees);  // we found one that is not there
  EXPECT_EQ(c.hands_matched, 2u);
  EXPECT_EQ(c.hands_only_ref, 1u);
  EXPECT_EQ(c.hands_only_ours, 1u);
  EXPECT_EQ(c.images_detection_agree, 1u);
  EXPECT_EQ(c.only_in_ours, std::vector<std::string>{"only_ours.jpg"});
  EXPECT_EQ(c.only_in_ref, std::vector<std::string>{"only_ref.jpg"});
  EXPECT_NEAR(*c.mean_distance_pct, 1.5, 1e-9);
  EXPECT_NEAR(*c.max_distance_pct, 2.0, 1e-9);

  const auto doc = to_json(c);
  EXPECT_EQ(doc["images_compared"], 3);
  EXPECT_TRUE(doc["images"][1]["mean_distance_pct"].is_null());
}

TEST(LandmarkComparison, HandsFarApartAreNotAMatch) {
  const auto left = hand(sim::PoseName::kOpenPalm, 0.9, 0.2);
  const auto right = hand(sim::PoseName::kOpenPalm, 0.9, 0.8);
  const auto c = compare_landmarks({record("a.png", {left})}, {record("a.png", {right})});
  EXPECT_EQ(c.hands_matched, 0u);
  EXPECT_EQ(c.hands_only_ours, 1u);
  EXPECT_EQ(c.hands_only_ref, 1u);
  EXPECT_FALSE(c.mean_distance_pct);
}

}  // namespace
}  // namespace gbdcs::vision
