#include "gbdcs/sim/twin_camera_source.hpp"

#include <gtest/gtest.h>

#include "test_scene.hpp"

namespace gbdcs::sim {
namespace {

TEST(TwinCameraSource, YieldsNumberedFramesUntilTheProducerEnds) {
  int calls = 0;
  TwinCameraSource source([&calls]() -> cv::Mat {
    ++calls;
    return calls <= 3 ? cv::Mat(4, 6, CV_8UC3, cv::Scalar(calls)) : cv::Mat();
  });
  for (std::int64_t id = 0; id < 3; ++id) {
    auto frame = source.next();
    ASSERT_TRUE(frame);
    EXPECT_EQ(frame->frame_id, id);
    EXPECT_EQ(frame->bgr.at<cv::Vec3b>(0, 0)[0], id + 1);
  }
  EXPECT_FALSE(source.next());
  EXPECT_FALSE(source.next());
  EXPECT_EQ(calls, 4);  // the end is not asked for twice
  EXPECT_TRUE(source.ended());
  EXPECT_EQ(source.describe(), "twin:onboard");
}

TEST(TwinCameraSource, StopsAtMaxFramesOrClose) {
  TwinCameraSource limited([] { return cv::Mat(2, 2, CV_8UC3); }, "twin:test", 2);
  EXPECT_TRUE(limited.next());
  EXPECT_TRUE(limited.next());
  EXPECT_FALSE(limited.next());

  TwinCameraSource closed([] { return cv::Mat(2, 2, CV_8UC3); });
  EXPECT_TRUE(closed.next());
  closed.close();
  EXPECT_FALSE(closed.next());
}

TEST(TwinCameraSource, GeneratorShapeChecksFrameIds) {
  TwinCameraSource source([] { return cv::Mat(2, 2, CV_8UC3); });
  EXPECT_TRUE(source.generate(0));
  EXPECT_TRUE(source.generate(1));
  EXPECT_THROW(source.generate(5), std::logic_error);
}

TEST(TwinCameraSource, RejectsBadProducersAndFrames) {
  EXPECT_THROW(TwinCameraSource(nullptr), std::invalid_argument);
  TwinCameraSource grey([] { return cv::Mat(2, 2, CV_8UC1); });
  EXPECT_THROW(grey.next(), std::runtime_error);
}

TEST(TwinCameraSource, StreamsTheOnboardCameraOfASteppingTwin) {
  auto model = test::load_test_scene();
  ASSERT_TRUE(model);
  auto data = test::make_state(model.get());
  int frames_left = 5;
  auto produce = make_render_producer(model.get(),
                                      [&]() -> const mjData* {
                                        if (frames_left-- == 0) {
                                          return nullptr;
                                        }
                                        test::move_free_body(model.get(), data.get(), 0, 0.05, 0);
                                        return data.get();
                                      },
                                      "onboard", {.width = 160, .height = 120});
  TwinCameraSource source(produce);
  cv::Mat previous;
  int count = 0;
  while (auto frame = source.next()) {
    ASSERT_EQ(frame->bgr.size(), cv::Size(160, 120));
    if (!previous.empty()) {
      EXPECT_GT(cv::norm(frame->bgr, previous, cv::NORM_L1), 0.0) << "frame " << count;
    }
    previous = frame->bgr;
    ++count;
  }
  EXPECT_EQ(count, 5);
}

}  // namespace
}  // namespace gbdcs::sim
