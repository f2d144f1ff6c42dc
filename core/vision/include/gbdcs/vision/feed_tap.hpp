// FeedTap: the live feed's picture at the camera's rate, whatever tracking manages.
//
// A CaptureSource decorator. Every frame the inner source delivers goes on to the pipeline
// unchanged and, at the same time, to the feed: the newest captured frame waits in a one-slot
// mailbox that a feed thread empties by calling `deliver(frame)` (the worker downscales and
// JPEG-encodes it there and sends a `picture` message). Capture never waits for the feed:
// a frame replaced in the mailbox before the feed thread took it is skipped (counted).
// The pixels are shared with the pipeline (cv::Mat reference counting); neither side writes
// into them (the pipeline's stages make new matrices).
//
//   Inputs   inner CaptureSource (owned); deliver(const Frame&), called on the feed thread,
//            one call at a time; an exception from it is counted and the feed goes on.
//   Outputs  next(), live(), describe() of the inner source; stats(): delivered, skipped,
//            failed.
//   Threads  one feed thread, started by the constructor, joined by the destructor (after the
//            call in progress returns).
#pragma once

#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "gbdcs/vision/capture.hpp"

namespace gbdcs::vision {

struct FeedStats {
  std::int64_t delivered = 0;  // deliver() returned
  std::int64_t skipped = 0;    // replaced in the mailbox before the feed took them
  std::int64_t failed = 0;     // deliver() threw
};

class FeedTap final : public CaptureSource {
 public:
  using Deliver = std::function<void(const Frame&)>;
  // Throws std::invalid_argument for a null source or deliver.
  FeedTap(std::unique_ptr<CaptureSource> inner, Deliver deliver);
  ~FeedTap() override;
  FeedTap(const FeedTap&) = delete;
  FeedTap& operator=(const FeedTap&) = delete;

  std::optional<Frame> next() override;
  bool live() const override { return inner_->live(); }
  std::string describe() const override { return inner_->describe(); }
  FeedStats stats() const;

 private:
  void run();

  std::unique_ptr<CaptureSource> inner_;
  Deliver deliver_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::optional<Frame> mailbox_;
  bool stopping_ = false;
  FeedStats stats_;
  std::thread thread_;
};

}  // namespace gbdcs::vision
