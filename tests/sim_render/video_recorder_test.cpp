#include "gbdcs/sim/video_recorder.hpp"

#include <gtest/gtest.h>

#include <iostream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "gbdcs/sim/renderer.hpp"
#include "test_scene.hpp"

namespace gbdcs::sim {
namespace {

TEST(VideoRecorder, WritesAnMp4ThatReadsBackFrameByFrame) {
  auto model = test::load_test_scene();
  ASSERT_TRUE(model);
  auto data = test::make_state(model.get());
  Renderer renderer(model.get(), {.width = 320, .height = 240});
  const auto path = test::temp_path("run.mp4");
  constexpr int kFrames = 24;
  {
    VideoRecorder recorder(path, {320, 240}, {.fps = 12});
    std::cout << "VideoRecorder codec: " << recorder.codec() << "\n";
    RecordProperty("codec", recorder.codec());
    for (int i = 0; i < kFrames; ++i) {
      test::move_free_body(model.get(), data.get(), 0, 0.02, 0);
      recorder.write(renderer.render(data.get(), "chase"));
    }
    EXPECT_EQ(recorder.frames_written(), kFrames);
    recorder.close();
    recorder.close();  // idempotent
    EXPECT_THROW(recorder.write(cv::Mat(240, 320, CV_8UC3)), std::logic_error);
  }
  cv::VideoCapture capture(path.string(), cv::CAP_FFMPEG);
  ASSERT_TRUE(capture.isOpened());
  EXPECT_EQ(static_cast<int>(capture.get(cv::CAP_PROP_FRAME_COUNT)), kFrames);
  EXPECT_NEAR(capture.get(cv::CAP_PROP_FPS), 12.0, 0.01);
  int read = 0;
  cv::Mat frame;
  cv::Mat first;
  cv::Mat last;
  while (capture.read(frame)) {
    EXPECT_EQ(frame.size(), cv::Size(320, 240));
    if (read == 0) {
      first = frame.clone();
    }
    last = frame;
    ++read;
  }
  EXPECT_EQ(read, kFrames);
  // The drone moved left across the run, and the video shows it.
  const auto a = test::find_colour(first, 2);
  const auto b = test::find_colour(last, 2);
  ASSERT_GT(a.count, 20);
  ASSERT_GT(b.count, 20);
  EXPECT_LT(b.centroid.x, a.centroid.x - 30);
}

TEST(VideoRecorder, RejectsUnwritablePathsAndBadFrames) {
  EXPECT_THROW(VideoRecorder("/nonexistent-folder/run.mp4", {64, 48}), std::runtime_error);
  try {
    VideoRecorder recorder(::testing::TempDir(), {64, 48});
    FAIL() << "expected an error for a folder";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find(::testing::TempDir()), std::string::npos) << e.what();
  }
  EXPECT_THROW(VideoRecorder(test::temp_path("run.avi"), {64, 48}), std::invalid_argument);
  EXPECT_THROW(VideoRecorder(test::temp_path("odd.mp4"), {63, 48}), std::invalid_argument);
  EXPECT_THROW(VideoRecorder(test::temp_path("x.mp4"), {64, 48}, {.fps = 0}),
               std::invalid_argument);
  EXPECT_THROW(VideoRecorder(test::temp_path("x.mp4"), {64, 48}, {.codec = "h265"}),
               std::invalid_argument);
  VideoRecorder recorder(test::temp_path("sized.mp4"), {64, 48});
  EXPECT_THROW(recorder.write(cv::Mat(48, 63, CV_8UC3)), std::invalid_argument);
  EXPECT_THROW(recorder.write(cv::Mat(48, 64, CV_8UC1)), std::invalid_argument);
}

TEST(VideoRecorder, EachCodecCanBeAskedForByName) {
  for (const char* codec : {"mp4v", "avc1"}) {
    const auto path = test::temp_path(std::string("named_") + codec + ".mp4");
    try {
      VideoRecorder recorder(path, {64, 48}, {.fps = 10, .codec = codec});
      EXPECT_EQ(recorder.codec(), codec);
      for (int i = 0; i < 5; ++i) {
        recorder.write(cv::Mat(48, 64, CV_8UC3, cv::Scalar(40 * i, 80, 200)));
      }
    } catch (const std::runtime_error& e) {
      // Only H.264 may be missing (an FFmpeg build without libx264); mp4v must always work.
      EXPECT_STREQ(codec, "avc1") << e.what();
      continue;
    }
    cv::VideoCapture capture(path.string(), cv::CAP_FFMPEG);
    EXPECT_EQ(static_cast<int>(capture.get(cv::CAP_PROP_FRAME_COUNT)), 5) << codec;
  }
}

TEST(SavePng, WritesALosslessStill) {
  auto model = test::load_test_scene();
  ASSERT_TRUE(model);
  auto data = test::make_state(model.get());
  Renderer renderer(model.get(), {.width = 200, .height = 150});
  const cv::Mat image = renderer.render(data.get(), "onboard");
  const auto path = test::temp_path("still.png");
  save_png(path, image);
  const cv::Mat back = cv::imread(path.string(), cv::IMREAD_COLOR);
  ASSERT_EQ(back.size(), image.size());
  EXPECT_EQ(cv::norm(back, image, cv::NORM_INF), 0.0);
  EXPECT_THROW(save_png("/nonexistent-folder/still.png", image), std::runtime_error);
  EXPECT_THROW(save_png(test::temp_path("empty.png"), cv::Mat()), std::invalid_argument);
}

}  // namespace
}  // namespace gbdcs::sim
