// FeedTap: every frame reaches the feed while the feed keeps up; a slow feed never holds up
// capture (the newest frame waits, older ones are skipped and counted); failures are counted.
#include "gbdcs/vision/feed_tap.hpp"

#include <gtest/gtest.h>

#include <condition_variable>
#include <mutex>
#include <vector>

#include "pipeline_fakes.hpp"

namespace gbdcs::vision {
namespace {

using namespace std::chrono_literals;
using testing::Gate;
using testing::solid;

std::unique_ptr<CaptureSource> counting_source(const contracts::Clock& clock, int frames) {
  return std::make_unique<GeneratorSource>(
      [frames](std::int64_t id) -> std::optional<cv::Mat> {
        if (id >= frames) return std::nullopt;
        return solid(8, 6, {static_cast<unsigned char>(id), 0, 0});
      },
      clock, "fake", true);
}

// What the feed received, awaited with a bounded wait.
class Received {
 public:
  void add(const Frame& f) {
    {
      std::lock_guard lock(mutex_);
      ids_.push_back(f.frame_id);
      data_.push_back(f.rgb.data);
    }
    cv_.notify_all();
  }
  bool wait_for_count(std::size_t n) {
    std::unique_lock lock(mutex_);
    return cv_.wait_for(lock, 20s, [&] { return ids_.size() >= n; });
  }
  std::vector<std::int64_t> ids() {
    std::lock_guard lock(mutex_);
    return ids_;
  }
  std::vector<const unsigned char*> data() {
    std::lock_guard lock(mutex_);
    return data_;
  }

 private:
  std::mutex mutex_;
  std::condition_variable cv_;
  std::vector<std::int64_t> ids_;
  std::vector<const unsigned char*> data_;
};

TEST(FeedTap, AFeedThatKeepsUpGetsEveryFrameWithThePipelinesPixels) {
  contracts::ManualClock clock;
  Received got;
  FeedTap tap(counting_source(clock, 5), [&](const Frame& f) { got.add(f); });
  EXPECT_TRUE(tap.live());
  EXPECT_EQ(tap.describe(), "fake");
  std::vector<const unsigned char*> pipeline_data;
  for (std::size_t i = 0; i < 5; ++i) {
    auto f = tap.next();
    ASSERT_TRUE(f);
    pipeline_data.push_back(f->rgb.data);
    ASSERT_TRUE(got.wait_for_count(i + 1)) << "frame " << i << " never reached the feed";
  }
  EXPECT_EQ(tap.next(), std::nullopt);  // the end of the inner source passes through
  EXPECT_EQ(got.ids(), (std::vector<std::int64_t>{0, 1, 2, 3, 4}));
  EXPECT_EQ(got.data(), pipeline_data);  // shared, not copied
  EXPECT_EQ(tap.stats().skipped, 0);
}

TEST(FeedTap, ASlowFeedNeverHoldsUpCaptureAndGetsTheNewestFrame) {
  contracts::ManualClock clock;
  Received got;
  Gate entered;
  Gate release;
  FeedTap tap(counting_source(clock, 10), [&](const Frame& f) {
    entered.open();
    if (f.frame_id == 0) {
      ASSERT_TRUE(release.wait());
    }
    got.add(f);
  });
  ASSERT_TRUE(tap.next());
  ASSERT_TRUE(entered.wait());  // the feed is busy with frame 0 until released
  // Capture goes on regardless: nine more frames, each replacing the last in the mailbox.
  for (int i = 1; i < 10; ++i) ASSERT_TRUE(tap.next()) << "frame " << i;
  release.open();
  ASSERT_TRUE(got.wait_for_count(2));
  EXPECT_EQ(got.ids(), (std::vector<std::int64_t>{0, 9}));
  const auto s = tap.stats();
  EXPECT_EQ(s.skipped, 8);  // frames 1..8
}

TEST(FeedTap, AFailingDeliveryIsCountedAndTheFeedGoesOn) {
  contracts::ManualClock clock;
  Received got;
  FeedTap tap(counting_source(clock, 3), [&](const Frame& f) {
    if (f.frame_id == 0) {
      got.add(f);
      throw std::runtime_error("encoder failed");
    }
    got.add(f);
  });
  ASSERT_TRUE(tap.next());
  ASSERT_TRUE(got.wait_for_count(1));
  ASSERT_TRUE(tap.next());
  ASSERT_TRUE(got.wait_for_count(2));
  EXPECT_EQ(got.ids(), (std::vector<std::int64_t>{0, 1}));
}

TEST(FeedTap, RefusesNullArguments) {
  contracts::ManualClock clock;
  EXPECT_THROW(FeedTap(nullptr, [](const Frame&) {}), std::invalid_argument);
  EXPECT_THROW(FeedTap(counting_source(clock, 1), nullptr), std::invalid_argument);
}

}  // namespace
}  // namespace gbdcs::vision
