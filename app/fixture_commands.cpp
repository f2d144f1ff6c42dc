// `gbdcs fixture ...`: rendered and recorded hand-video fixtures (docs/FIXTURES.md).
#include <array>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <random>

#include "command_registry.hpp"
#include "commands.hpp"
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "fixture_support.hpp"
#include "gbdcs/gesture/hand_features.hpp"
#include "gbdcs/vision/hand_tracker.hpp"
#include "gbdcs/vision/vision_pipeline.hpp"
#include "gbdcs/sim/fixture_renderer.hpp"
#include "gbdcs/sim/hand_scene.hpp"
#include "gbdcs/sim/recipe.hpp"
#include "gbdcs/sim/video_recorder.hpp"

namespace gbdcs::app {
namespace {

struct StillOptions {
  std::string pose = "OPEN_PALM";
  std::string output;
  int width = 640;
  int height = 480;
  double distance_m = 0.6;
  std::uint32_t seed = 1;
  bool left = false;
  double yaw_deg = 0;
  double pitch_deg = 0;
  double roll_deg = 0;
  bool overlay = false;
  bool json = false;
};

// |tip - wrist| / |PIP - wrist| per finger (index ... pinky), in pixels: about 1.4 for a
// straight finger, 0.6 for one folded into a fist; what the recogniser's curl rules read.
std::array<double, 4> curl_ratios(const std::array<contracts::Point3, contracts::kLandmarkCount>& p,
                                  int w, int h) {
  auto d = [&](std::size_t a, std::size_t b) {
    return std::hypot((p[a].x - p[b].x) * w, (p[a].y - p[b].y) * h);
  };
  std::array<double, 4> out{};
  for (std::size_t f = 0; f < 4; ++f) {
    const std::size_t pip = contracts::kIndexMcp + 4 * f + 1;
    out[f] = d(pip + 2, contracts::kWrist) / std::max(1e-9, d(pip, contracts::kWrist));
  }
  return out;
}

int run_still(const StillOptions& o) {
  const auto name = sim::pose_from_string(o.pose);
  if (!name) {
    std::cerr << "gbdcs fixture still: unknown pose " << o.pose << "\n";
    return 2;
  }
  std::mt19937 rng(o.seed);
  sim::HandInstance hand;
  hand.pose = sim::pose_for(*name, rng);
  hand.distance_m = o.distance_m;
  hand.handedness = o.left ? contracts::Handedness::kLeft : contracts::Handedness::kRight;
  hand.yaw_deg = o.yaw_deg;
  hand.pitch_deg = o.pitch_deg;
  hand.roll_deg = o.roll_deg;
  if (const auto dir = std::filesystem::path(o.output).parent_path(); !dir.empty())
    std::filesystem::create_directories(dir);
  sim::HandScene scene(o.width, o.height);
  auto r = scene.render(hand);
  cv::Mat out(r.bgr.size(), CV_8UC3, cv::Scalar(170, 180, 190));  // the hand over a plain grey
  sim::composite_over(out, r);
  if (!o.overlay && !o.json) {
    sim::save_png(o.output, out);
    return 0;
  }
  // What our tracker and recogniser make of the still (tracking mode, settled over a few
  // passes as on a held pose in a video), against the sites' ground truth.
  static const contracts::SteadyClock clock;
  auto finder = vision::make_tracker_finder(vision::TrackerOptions{}, clock);
  cv::Mat rgb;
  cv::cvtColor(out, rgb, cv::COLOR_BGR2RGB);
  std::vector<contracts::Landmarks> hands;
  for (int pass = 0; pass < 4; ++pass) hands = finder->find(rgb);
  vision::HandClassifier classifier;
  classifier.set_frame_size(o.width, o.height);
  const auto results = classifier.classify(hands);
  const auto& truth = r.landmarks.points;
  contracts::Landmarks true_hand;
  true_hand.points = truth;
  true_hand.handedness = hand.handedness;
  true_hand.score = 1;
  const double aspect = static_cast<double>(o.width) / o.height;
  auto features = [&](const contracts::Landmarks& h) {
    const auto f = gesture::extract_features(h, aspect, 1.0);
    const auto flat = gesture::extract_features(h, aspect, 0.0);  // image plane only
    return nlohmann::json{{"finger_curl_deg", f.finger_curl_deg},
                          {"finger_curl_deg_image_plane", flat.finger_curl_deg},
                          {"thumb_bend_deg", f.thumb_bend_deg},
                          {"thumb_lateral", f.thumb_lateral}};
  };
  // The recogniser on the ground truth says whether the pose itself reads as intended.
  nlohmann::json doc = {{"pose", o.pose}, {"seed", o.seed},
                        {"hand_size_px", r.landmarks.size_px},
                        {"truth_gesture", contracts::to_string(classifier.recognize(true_hand).gesture)},
                        {"truth_features", features(true_hand)},
                        {"truth_curl_ratio", curl_ratios(truth, o.width, o.height)},
                        {"found", !results.empty()}};
  auto points = [](const std::array<contracts::Point3, contracts::kLandmarkCount>& ps) {
    nlohmann::json a = nlohmann::json::array();
    for (const auto& q : ps) a.push_back({q.x, q.y, q.z});
    return a;
  };
  doc["truth_landmarks"] = points(truth);
  if (!results.empty()) {
    const auto& tracked = results.front().landmarks.points;
    std::array<double, contracts::kLandmarkCount> err{};
    double sum = 0;
    for (std::size_t i = 0; i < err.size(); ++i) {
      err[i] = 100.0 *
               std::hypot((tracked[i].x - truth[i].x) * o.width, (tracked[i].y - truth[i].y) * o.height) /
               std::max(1.0, r.landmarks.size_px);
      sum += err[i];
    }
    doc["gesture"] = contracts::to_string(results.front().gesture);
    doc["tracked_curl_ratio"] = curl_ratios(tracked, o.width, o.height);
    doc["tracked_landmarks"] = points(tracked);
    doc["tracked_features"] = features(results.front().landmarks);
    doc["landmark_error_pct_mean"] = sum / static_cast<double>(err.size());
    doc["landmark_error_pct_by_point"] = err;
    if (o.overlay) {
      auto px = [&](const contracts::Point3& p) {
        return cv::Point(static_cast<int>(p.x * o.width), static_cast<int>(p.y * o.height));
      };
      for (std::size_t i = 0; i < err.size(); ++i) {
        cv::circle(out, px(truth[i]), 3, {0, 220, 0}, cv::FILLED);
        cv::circle(out, px(tracked[i]), 3, {0, 0, 255}, 1);
        cv::line(out, px(tracked[i]), px(truth[i]), {0, 0, 255}, 1);
      }
    }
  }
  sim::save_png(o.output, out);
  if (o.json) std::cout << doc.dump() << "\n";
  return 0;
}

struct RenderOptions {
  std::string recipe;
  std::string output;
  std::vector<std::int64_t> frames;
  bool overlay = false;
};

// Draws the ground truth (green) and what our tracker finds (red) on a frame.
void draw_overlay(cv::Mat& bgr, const sim::FrameLabel& label) {
  static const contracts::SteadyClock clock;
  static auto finder = vision::make_tracker_finder(vision::TrackerOptions{}, clock);
  cv::Mat rgb;
  cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  finder->reset();
  const auto hands = finder->find(rgb);
  auto px = [&](const contracts::Point3& p) {
    return cv::Point(static_cast<int>(p.x * bgr.cols), static_cast<int>(p.y * bgr.rows));
  };
  if (label.landmarks) {
    for (const auto& p : label.landmarks->points) cv::circle(bgr, px(p), 3, {0, 220, 0}, cv::FILLED);
  }
  for (const auto& h : hands) {
    for (std::size_t i = 0; i < h.points.size(); ++i) {
      cv::circle(bgr, px(h.points[i]), 3, {0, 0, 255}, 1);
      if (label.landmarks) cv::line(bgr, px(h.points[i]), px(label.landmarks->points[i]), {0, 0, 255}, 1);
    }
  }
}

int run_render(const RenderOptions& o) {
  if (!o.frames.empty()) {
    sim::FixtureRenderer renderer(sim::load_recipe(o.recipe));
    std::filesystem::create_directories(o.output);
    for (auto i : o.frames) {
      if (i < 0 || i >= renderer.frame_count()) {
        std::cerr << "gbdcs fixture render: --frame " << i << " is outside the recipe's 0 ... "
                  << renderer.frame_count() - 1 << "\n";
        return 2;
      }
      const auto path = std::filesystem::path(o.output) / ("frame_" + std::to_string(i) + ".png");
      auto frame = renderer.frame(i);
      if (o.overlay) draw_overlay(frame.bgr, frame.label);
      sim::save_png(path, frame.bgr);
      std::cout << path.string() << "\n";
    }
    return 0;
  }
  render_fixture(o.recipe, o.output, terminal_progress("render"));
  std::cout << o.output << "/video.mp4\n" << o.output << "/labels.json\n";
  return 0;
}

void add_fixture_commands(CLI::App& app) {
  auto* fixture = group_command(app, "fixture", "Hand-video fixtures: render, record, check");
  static RenderOptions r;
  auto* render = fixture->add_subcommand(
      "render",
      "Render a recipe (fixtures/*.json, docs/FIXTURES.md) through the MuJoCo hand: writes "
      "DIR/video.mp4 and DIR/labels.json (per frame the true gesture, landmarks, visibility; "
      "per segment the onset). The same recipe and seed give the same labels and frames");
  render->add_option("RECIPE", r.recipe, "Recipe JSON file")->required();
  render->add_option("-o,--output", r.output, "Output folder (created)")->required();
  render->add_option("--frame", r.frames,
                     "Only these frames, as DIR/frame_N.png (to look at a recipe quickly)");
  render->add_flag("--overlay", r.overlay,
                   "With --frame: draw the true landmarks (green) and our tracker's (red)");
  render->callback([] {
    try {
      g_exit_code = run_render(r);
    } catch (const std::exception& e) {
      std::cerr << "gbdcs fixture render: " << e.what() << "\n";
      g_exit_code = 2;
    }
  });

  static StillOptions s;
  auto* still = fixture->add_subcommand("still", "Render one pose of the MuJoCo hand to a PNG");
  still->add_option("--pose", s.pose, "Pose name (OPEN_PALM, FIST, ... CALL, OK_SIGN)");
  still->add_option("-o,--output", s.output, "PNG file")->required();
  still->add_option("--distance", s.distance_m, "Metres from the camera");
  still->add_option("--seed", s.seed, "Seed of the pose's natural variation");
  still->add_flag("--left", s.left, "A left hand");
  still->add_option("--yaw", s.yaw_deg, "Extra turn about the image vertical, degrees");
  still->add_option("--pitch", s.pitch_deg, "Extra tilt about the image horizontal, degrees");
  still->add_option("--roll", s.roll_deg, "Extra in-plane turn, degrees");
  still->add_flag("--overlay", s.overlay,
                  "Draw the true landmarks (green) and our tracker's (red) on the PNG");
  still->add_flag("--json", s.json,
                  "Print truth against tracking: the gesture read, curl ratios |tip-wrist| / "
                  "|PIP-wrist| per finger, landmark error (% of the hand's size)");
  still->callback([] {
    try {
      g_exit_code = run_still(s);
    } catch (const std::exception& e) {
      std::cerr << "gbdcs fixture still: " << e.what() << "\n";
      g_exit_code = 2;
    }
  });
}

const CommandRegistration kFixture{40, &add_fixture_commands};

}  // namespace
}  // namespace gbdcs::app
