#include "gbdcs/sim/renderer.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <iostream>
#include <opencv2/imgproc.hpp>
#include <thread>
#include <vector>

#include "test_scene.hpp"

namespace gbdcs::sim {
namespace {

using test::find_colour;
using test::grey_stddev;

constexpr int kRed = 2;
constexpr int kBlue = 0;

TEST(Renderer, RendersBothCamerasAtTheRequestedSizeAndNotUniform) {
  auto model = test::load_test_scene();
  ASSERT_TRUE(model);
  auto data = test::make_state(model.get());
  Renderer renderer(model.get(), {.width = 320, .height = 240});
  for (const char* camera : {"chase", "onboard"}) {
    const cv::Mat image = renderer.render(data.get(), camera);
    EXPECT_EQ(image.type(), CV_8UC3) << camera;
    EXPECT_EQ(image.cols, 320) << camera;
    EXPECT_EQ(image.rows, 240) << camera;
    EXPECT_GT(grey_stddev(image), 10.0) << camera;
  }
  EXPECT_EQ(renderer.camera_names(), (std::vector<std::string>{"chase", "onboard"}));
}

TEST(Renderer, TheDroneMovesInTheChaseImageWhenItsBodyMoves) {
  auto model = test::load_test_scene();
  ASSERT_TRUE(model);
  auto data = test::make_state(model.get());
  Renderer renderer(model.get());
  const auto before = find_colour(renderer.render(data.get(), "chase"), kRed);
  ASSERT_GT(before.count, 100) << "the red drone is not in the chase view";
  // The chase camera looks along +x; world +y is image left, world +z is image up.
  test::move_free_body(model.get(), data.get(), 0, 0.4, 0);
  const auto left = find_colour(renderer.render(data.get(), "chase"), kRed);
  ASSERT_GT(left.count, 100);
  EXPECT_LT(left.centroid.x, before.centroid.x - 40);
  EXPECT_NEAR(left.centroid.y, before.centroid.y, 10);
  test::move_free_body(model.get(), data.get(), 0, 0, 0.3);
  const auto up = find_colour(renderer.render(data.get(), "chase"), kRed);
  EXPECT_LT(up.centroid.y, left.centroid.y - 20);
  test::expect_no_warnings(data.get());
}

TEST(Renderer, TheOnboardViewShiftsWhenTheDroneMoves) {
  auto model = test::load_test_scene();
  ASSERT_TRUE(model);
  auto data = test::make_state(model.get());
  Renderer renderer(model.get());
  const auto before = find_colour(renderer.render(data.get(), "onboard"), kBlue);
  ASSERT_GT(before.count, 100) << "the blue pillar is not in the on-board view";
  test::move_free_body(model.get(), data.get(), 0, 0.3, 0);  // drone left: the scene goes right
  const auto after = find_colour(renderer.render(data.get(), "onboard"), kBlue);
  EXPECT_GT(after.centroid.x, before.centroid.x + 20);
}

TEST(Renderer, OddSizesAreReadBackRowByRow) {
  // A 3-byte pixel row of odd width is not 4-byte aligned: a wrong pack alignment would shear
  // the image, moving the drone's centroid away from where the even-sized render puts it.
  auto model = test::load_test_scene();
  ASSERT_TRUE(model);
  auto data = test::make_state(model.get());
  Renderer even(model.get(), {.width = 640, .height = 480});
  Renderer odd(model.get(), {.width = 321, .height = 241});
  const cv::Mat odd_image = odd.render(data.get(), "chase");
  ASSERT_EQ(odd_image.size(), cv::Size(321, 241));
  const auto a = find_colour(even.render(data.get(), "chase"), kRed);
  const auto b = find_colour(odd_image, kRed);
  ASSERT_GT(b.count, 20);
  EXPECT_NEAR(b.centroid.x / 321, a.centroid.x / 640, 0.02);
  EXPECT_NEAR(b.centroid.y / 241, a.centroid.y / 480, 0.02);
}

TEST(Renderer, UnknownCameraListsTheCameras) {
  auto model = test::load_test_scene();
  ASSERT_TRUE(model);
  auto data = test::make_state(model.get());
  Renderer renderer(model.get(), {.width = 64, .height = 48});
  try {
    renderer.render(data.get(), "belly");
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'belly'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("chase, onboard"), std::string::npos) << e.what();
  }
  EXPECT_THROW(renderer.render(nullptr, "chase"), std::invalid_argument);
}

TEST(Renderer, RejectsBadConstruction) {
  EXPECT_THROW(Renderer(nullptr), std::invalid_argument);
  auto model = test::load_test_scene();
  ASSERT_TRUE(model);
  EXPECT_THROW(Renderer(model.get(), {.width = 0, .height = 480}), std::invalid_argument);
  EXPECT_THROW(Renderer(model.get(), {.width = 640, .height = 9000}), std::invalid_argument);
}

TEST(Renderer, LeavesTheStateUntouched) {
  auto model = test::load_test_scene();
  ASSERT_TRUE(model);
  auto data = test::make_state(model.get());
  const std::vector<unsigned char> before(
      static_cast<unsigned char*>(data->buffer),
      static_cast<unsigned char*>(data->buffer) + data->nbuffer);
  Renderer renderer(model.get(), {.width = 160, .height = 120});
  renderer.render(data.get(), "chase");
  renderer.render(data.get(), "onboard");
  EXPECT_EQ(std::memcmp(before.data(), data->buffer, before.size()), 0);
}

TEST(Renderer, IsBoundToItsThread) {
  auto model = test::load_test_scene();
  ASSERT_TRUE(model);
  auto data = test::make_state(model.get());
  Renderer here(model.get(), {.width = 64, .height = 48});
  bool threw = false;
  std::thread([&] {
    try {
      here.render(data.get(), "chase");
    } catch (const std::logic_error&) {
      threw = true;
    }
  }).join();
  EXPECT_TRUE(threw);

  // A Renderer made, used and destroyed on another thread works there.
  cv::Mat there_image;
  std::thread([&] {
    Renderer there(model.get(), {.width = 64, .height = 48});
    there_image = there.render(data.get(), "chase");
  }).join();
  EXPECT_EQ(there_image.size(), cv::Size(64, 48));
  EXPECT_GT(grey_stddev(there_image), 5.0);
}

TEST(Renderer, MultisamplingSmoothsEdges) {
  auto model = test::load_test_scene();
  ASSERT_TRUE(model);
  auto data = test::make_state(model.get());
  Renderer sharp(model.get(), {.width = 320, .height = 240});
  Renderer smooth(model.get(), {.width = 320, .height = 240, .multisamples = 4});
  const cv::Mat a = sharp.render(data.get(), "chase");
  const cv::Mat b = smooth.render(data.get(), "chase");
  EXPECT_GT(cv::norm(a, b, cv::NORM_L1), 0.0);
  // Same picture, only the edges differ.
  EXPECT_NEAR(test::find_colour(a, kRed).centroid.x, test::find_colour(b, kRed).centroid.x, 1.5);
}

TEST(Renderer, ShadowsAndReflectionsChangeTheImage) {
  auto model = test::load_test_scene();
  ASSERT_TRUE(model);
  auto data = test::make_state(model.get());
  Renderer plain(model.get(), {.width = 320, .height = 240});
  Renderer shaded(model.get(), {.width = 320, .height = 240, .shadows = true, .reflections = true});
  const cv::Mat a = plain.render(data.get(), "chase");
  const cv::Mat b = shaded.render(data.get(), "chase");
  EXPECT_GT(cv::norm(a, b, cv::NORM_L1), 0.0);
}

TEST(Renderer, OptionsFromJson) {
  const auto options = RendererOptions::from_json({{"width", 320}, {"shadows", true}});
  EXPECT_EQ(options.width, 320);
  EXPECT_EQ(options.height, 480);
  EXPECT_TRUE(options.shadows);
  EXPECT_FALSE(options.reflections);
  EXPECT_THROW(RendererOptions::from_json({{"widht", 320}}), std::invalid_argument);
  EXPECT_THROW(RendererOptions::from_json({{"shadows", 1}}), std::invalid_argument);
  EXPECT_THROW(RendererOptions::from_json({{"width", -3}}), std::invalid_argument);
  EXPECT_THROW(RendererOptions::from_json({{"multisamples", 32}}), std::invalid_argument);
  EXPECT_EQ(RendererOptions::from_json({{"multisamples", 4}}).multisamples, 4);
}

TEST(Renderer, QuadrotorModelFromBothCameras) {
  const auto path = test::quadrotor_model_path();
  if (path.empty()) {
    GTEST_SKIP() << "sim/models/quadrotor.xml does not exist yet";
  }
  auto model = test::load_model(path);
  ASSERT_TRUE(model);
  auto data = test::make_state(model.get());
  Renderer renderer(model.get());
  for (const char* camera : {"chase", "onboard"}) {
    const cv::Mat before = renderer.render(data.get(), camera);
    EXPECT_EQ(before.size(), cv::Size(640, 480)) << camera;
    EXPECT_GT(grey_stddev(before), 10.0) << camera;
  }
  const cv::Mat chase_before = renderer.render(data.get(), "chase");
  const cv::Mat onboard_before = renderer.render(data.get(), "onboard");
  test::move_free_body(model.get(), data.get(), 0.0, 0.5, 0.4);
  for (const auto& [camera, before] :
       {std::pair{"chase", chase_before}, std::pair{"onboard", onboard_before}}) {
    cv::Mat diff;
    cv::absdiff(renderer.render(data.get(), camera), before, diff);
    cv::cvtColor(diff, diff, cv::COLOR_BGR2GRAY);
    const double changed = cv::countNonZero(diff > 30) / static_cast<double>(diff.total());
    EXPECT_GT(changed, 0.002) << camera << ": the image did not change when the drone moved";
  }
  test::expect_no_warnings(data.get());
}

TEST(Renderer, QuadrotorYawMovesOnlyTheDronesPixelsInTheChaseView) {
  // The chase camera tracks the drone's centre of mass with world-aligned axes, so a yaw in
  // place changes the drone's pixels and nothing else.
  const auto path = test::quadrotor_model_path();
  if (path.empty()) {
    GTEST_SKIP() << "sim/models/quadrotor.xml does not exist yet";
  }
  auto model = test::load_model(path);
  ASSERT_TRUE(model);
  auto data = test::make_state(model.get());
  Renderer renderer(model.get());
  const cv::Mat before = renderer.render(data.get(), "chase");
  test::set_free_body_yaw(model.get(), data.get(), 45.0);
  const cv::Mat after = renderer.render(data.get(), "chase");
  cv::Mat diff;
  cv::absdiff(after, before, diff);
  cv::cvtColor(diff, diff, cv::COLOR_BGR2GRAY);
  const cv::Mat changed = diff > 30;
  ASSERT_GT(cv::countNonZero(changed), 30) << "the drone's pixels did not change";
  const cv::Rect box = cv::boundingRect(changed);
  EXPECT_LT(box.width, 640 / 4) << box;
  EXPECT_LT(box.height, 480 / 4) << box;
  const cv::Point centre = (box.tl() + box.br()) / 2;
  EXPECT_NEAR(centre.x, 320, 40) << "the drone is not where the chase camera looks";
  EXPECT_NEAR(centre.y, 240, 40);
}

TEST(Renderer, Timing640x480) {
  const auto path = test::quadrotor_model_path();
  auto model = path.empty() ? test::load_test_scene() : test::load_model(path);
  ASSERT_TRUE(model);
  auto data = test::make_state(model.get());
  Renderer renderer(model.get());
  for (const char* camera : {"chase", "onboard"}) {
    const RenderTiming timing = measure_render(renderer, data.get(), camera, 30);
    std::cout << "render 640x480 " << camera << " (" << (path.empty() ? "test scene" : "quadrotor")
              << "): p50 " << timing.p50_ms << " ms, p90 " << timing.p90_ms << " ms, max "
              << timing.max_ms << " ms, CPU " << timing.cpu_ms_mean << " ms/frame\n";
    RecordProperty(std::string("render_640x480_ms_p50_") + camera, std::to_string(timing.p50_ms));
    EXPECT_LT(timing.p50_ms, 1000.0) << "a pathological render time";
  }
}

}  // namespace
}  // namespace gbdcs::sim
