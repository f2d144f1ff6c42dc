// `gbdcs fixture ...`: rendered and recorded hand-video fixtures (docs/FIXTURES.md).
#include <iostream>
#include <random>

#include "command_registry.hpp"
#include "commands.hpp"
#include "gbdcs/sim/hand_scene.hpp"
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

void add_fixture_commands(CLI::App& app) {
  auto* fixture = group_command(app, "fixture", "Hand-video fixtures: render, record, check");
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
