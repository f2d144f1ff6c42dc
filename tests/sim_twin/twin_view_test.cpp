// TwinAdapter's drone view: the chase camera rendered (OSMesa) on the adapter's own thread and
// pushed to the sink as JPEG; bad options are refused with the reason; stop_view() means no
// more pictures.
#include <gtest/gtest.h>

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <opencv2/imgcodecs.hpp>
#include <vector>

#include "twin_test_support.hpp"

namespace gbdcs::sim {
namespace {

using control::Result;
using testing::TwinRig;

struct Pictures {
  std::mutex mutex;
  std::condition_variable cv;
  std::vector<control::DroneView> got;

  control::ViewSink sink() {
    return [this](const control::DroneView& v) {
      {
        std::lock_guard lock(mutex);
        got.push_back(v);
      }
      cv.notify_all();
    };
  }
  bool wait_for(std::size_t n) {
    std::unique_lock lock(mutex);
    // Generous: a loaded 2-core machine renders slowly; the condition, not the time, decides.
    return cv.wait_for(lock, std::chrono::seconds(60), [&] { return got.size() >= n; });
  }
};

TEST(TwinView, ChaseCameraPicturesAreJpegOfTheAskedSize) {
  TwinRig rig;
  ASSERT_EQ(rig.twin.connect(), Result::kOk);
  Pictures pictures;
  control::ViewOptions o;
  o.width = 160;
  o.height = 120;
  o.fps = 20;
  ASSERT_EQ(rig.twin.start_view(o, pictures.sink()), Result::kOk) << rig.twin.last_error();
  ASSERT_TRUE(pictures.wait_for(3)) << rig.twin.last_error();
  rig.twin.stop_view();
  std::lock_guard lock(pictures.mutex);
  for (std::size_t i = 0; i < pictures.got.size(); ++i) {
    const auto& v = pictures.got[i];
    EXPECT_EQ(v.frame_id, static_cast<std::int64_t>(i));
    EXPECT_EQ(v.camera, "chase");
    EXPECT_EQ(v.width, 160);
    EXPECT_EQ(v.height, 120);
    const std::vector<unsigned char> bytes(v.jpeg.begin(), v.jpeg.end());
    const cv::Mat decoded = cv::imdecode(bytes, cv::IMREAD_COLOR);
    ASSERT_FALSE(decoded.empty()) << "picture " << i << " is not a JPEG";
    EXPECT_EQ(decoded.cols, 160);
    EXPECT_EQ(decoded.rows, 120);
    // Not a blank image: the room and the drone give the picture some contrast.
    cv::Scalar mean, stddev;
    cv::meanStdDev(decoded, mean, stddev);
    EXPECT_GT(stddev[0] + stddev[1] + stddev[2], 5.0);
  }
}

TEST(TwinView, StopsAndStartsAgainAndDisconnectEndsIt) {
  TwinRig rig;
  ASSERT_EQ(rig.twin.connect(), Result::kOk);
  Pictures pictures;
  control::ViewOptions o;
  o.width = 64;
  o.height = 48;
  o.fps = 30;
  ASSERT_EQ(rig.twin.start_view(o, pictures.sink()), Result::kOk);
  ASSERT_TRUE(pictures.wait_for(1));
  rig.twin.stop_view();  // returns once the sink is no longer called
  std::size_t after_stop;
  {
    std::lock_guard lock(pictures.mutex);
    after_stop = pictures.got.size();
  }
  // Started again, then ended by disconnect().
  ASSERT_EQ(rig.twin.start_view(o, pictures.sink()), Result::kOk);
  ASSERT_TRUE(pictures.wait_for(after_stop + 1));
  EXPECT_EQ(rig.twin.disconnect(), Result::kOk);
  std::lock_guard lock(pictures.mutex);
  EXPECT_EQ(pictures.got[after_stop].frame_id, 0);  // a new view counts from 0
}

TEST(TwinView, BadOptionsAreRefusedWithTheReason) {
  TwinRig rig;
  Pictures pictures;
  control::ViewOptions o;
  o.fps = 0;
  EXPECT_EQ(rig.twin.start_view(o, pictures.sink()), Result::kRejected);
  EXPECT_NE(rig.twin.last_error().find("fps must be in (0, 30]"), std::string::npos)
      << rig.twin.last_error();
  o.fps = 5;
  o.width = 100000;
  EXPECT_EQ(rig.twin.start_view(o, pictures.sink()), Result::kRejected);
  o.width = 320;
  EXPECT_EQ(rig.twin.start_view(o, nullptr), Result::kRejected);
}

}  // namespace
}  // namespace gbdcs::sim
