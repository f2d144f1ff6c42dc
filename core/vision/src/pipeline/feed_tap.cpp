// FeedTap: a one-slot mailbox between the capture thread and the feed thread.
#include "gbdcs/vision/feed_tap.hpp"

#include <stdexcept>

namespace gbdcs::vision {

FeedTap::FeedTap(std::unique_ptr<CaptureSource> inner, Deliver deliver)
    : inner_(std::move(inner)), deliver_(std::move(deliver)) {
  if (!inner_) throw std::invalid_argument("FeedTap: no capture source");
  if (!deliver_) throw std::invalid_argument("FeedTap: no deliver function");
  thread_ = std::thread([this] { run(); });
}

FeedTap::~FeedTap() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

std::optional<Frame> FeedTap::next() {
  auto frame = inner_->next();
  if (frame && !frame->rgb.empty()) {
    {
      std::lock_guard lock(mutex_);
      if (mailbox_) ++stats_.skipped;
      mailbox_ = *frame;  // shares the pixels
    }
    wake_.notify_one();
  }
  return frame;
}

FeedStats FeedTap::stats() const {
  std::lock_guard lock(mutex_);
  return stats_;
}

void FeedTap::run() {
  std::unique_lock lock(mutex_);
  while (true) {
    wake_.wait(lock, [&] { return stopping_ || mailbox_.has_value(); });
    if (stopping_) return;
    Frame frame = std::move(*mailbox_);
    mailbox_.reset();
    lock.unlock();
    bool ok = true;
    try {
      deliver_(frame);
    } catch (...) {
      ok = false;
    }
    lock.lock();
    ++(ok ? stats_.delivered : stats_.failed);
  }
}

}  // namespace gbdcs::vision
