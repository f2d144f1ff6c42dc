// `gbdcs fixture ...`: rendered and recorded hand-video fixtures (docs/FIXTURES.md).
#include <filesystem>
#include <iostream>
#include <random>

#include "command_registry.hpp"
#include "commands.hpp"
#include <opencv2/imgproc.hpp>

#include "fixture_support.hpp"
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
};

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
  sim::HandScene scene(o.width, o.height);
  auto r = scene.render(hand);
  cv::Mat out(r.bgr.size(), CV_8UC3, cv::Scalar(170, 180, 190));
  r.bgr.copyTo(out, r.mask);
  sim::save_png(o.output, out);
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
