// Fakes for the pipeline tests: frames made in memory, a HandFinder that needs no models.
#pragma once

#include <gtest/gtest.h>

#include <chrono>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <opencv2/core.hpp>
#include <random>
#include <stdexcept>
#include <vector>

#include "gbdcs/contracts/clock.hpp"
#include "gbdcs/sim/hand_pose.hpp"
#include "gbdcs/vision/vision_pipeline.hpp"

namespace gbdcs::vision::testing {

// A gate threads wait on until the test opens it. Waits are bounded (real time) so that a
// broken pipeline fails the test instead of hanging it.
class Gate {
 public:
  void open() {
    {
      std::lock_guard lock(mutex_);
      open_ = true;
    }
    cv_.notify_all();
  }
  void close() {
    std::lock_guard lock(mutex_);
    open_ = false;
  }
  bool wait(std::chrono::milliseconds limit = std::chrono::seconds(20)) {
    std::unique_lock lock(mutex_);
    return cv_.wait_for(lock, limit, [&] { return open_; });
  }

 private:
  std::mutex mutex_;
  std::condition_variable cv_;
  bool open_ = false;
};

// Waits (real time, bounded) until `done()` holds; notify() after every change it reads.
class Waiter {
 public:
  // Takes the lock first, so a waiter between its check and its wait cannot miss this.
  void notify() {
    { std::lock_guard lock(mutex_); }
    cv_.notify_all();
  }
  template <class Pred>
  bool wait_until(Pred done, std::chrono::milliseconds limit = std::chrono::seconds(20)) {
    std::unique_lock lock(mutex_);
    return cv_.wait_for(lock, limit, done);
  }
  std::mutex& mutex() { return mutex_; }

 private:
  std::mutex mutex_;
  std::condition_variable cv_;
};

// A 4:3 frame of one colour (in the caller's channel order).
inline cv::Mat solid(int width, int height, cv::Vec3b colour) {
  return cv::Mat(height, width, CV_8UC3, cv::Scalar(colour[0], colour[1], colour[2]));
}

inline contracts::Landmarks hand(sim::PoseName pose, double score, double center_x = 0.5,
                                 double aspect_ratio = 4.0 / 3.0, unsigned seed = 7) {
  std::mt19937 rng(seed);
  sim::Placement placement;
  placement.center_x = center_x;
  placement.size = 0.4;
  placement.presence = score;
  placement.aspect_ratio = aspect_ratio;
  return sim::synthesize(sim::pose_for(pose, rng), placement);
}

// A HandFinder scripted per call: `hands_for(call_index, rgb)` says what it finds; optional
// hooks run before (to advance a ManualClock, wait on a gate, or throw).
class FakeFinder final : public HandFinder {
 public:
  using Script = std::function<std::vector<contracts::Landmarks>(int call, const cv::Mat& rgb)>;
  using Hook = std::function<void(int call, const cv::Mat& rgb)>;
  explicit FakeFinder(Script script = {}, Hook before = {})
      : script_(std::move(script)), before_(std::move(before)) {}
  std::vector<contracts::Landmarks> find(const cv::Mat& rgb) override {
    const int call = calls_++;
    if (before_) before_(call, rgb);
    return script_ ? script_(call, rgb) : std::vector<contracts::Landmarks>{};
  }

 private:
  Script script_;
  Hook before_;
  int calls_ = 0;
};

}  // namespace gbdcs::vision::testing
