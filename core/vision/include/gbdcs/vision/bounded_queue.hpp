// BoundedQueue: the pipe between two pipeline stages. Many producers, one consumer (it is
// safe with several consumers too, but order is then per consumer only).
//
// Inputs   push(item) from any thread.
// Outputs  pop() in FIFO order (per producer; across producers, in the order pushes
//          completed).
// Policy when full
//   kDropOldest  push never waits: the oldest queued item is discarded and counted in
//                dropped(). For live sources, where a stale frame is worth less than a new
//                one and the camera must never be stalled.
//   kBlock       push waits for room. For offline sources, so no frame is ever lost.
// Shutdown
//   close()      no more pushes (push returns false and discards the item); pop() still
//                returns what is queued, then nullopt. Wakes every waiting thread.
//   discard()    empties the queue (for a stop that must not wait for the backlog).
// Counters     depth() now, max_depth() high-water mark, pushed(), dropped(); all thread-safe.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string_view>
#include <utility>

namespace gbdcs::vision {

enum class OverflowPolicy { kDropOldest, kBlock };

inline std::string_view to_string(OverflowPolicy p) {
  return p == OverflowPolicy::kDropOldest ? "drop_oldest" : "block";
}

template <class T>
class BoundedQueue {
 public:
  // Throws std::invalid_argument for a capacity of 0.
  BoundedQueue(std::size_t capacity, OverflowPolicy policy) : capacity_(capacity), policy_(policy) {
    if (capacity == 0) throw std::invalid_argument("BoundedQueue: capacity must be at least 1");
  }
  BoundedQueue(const BoundedQueue&) = delete;
  BoundedQueue& operator=(const BoundedQueue&) = delete;

  // False when the queue is closed; the item is then discarded.
  bool push(T item) {
    std::unique_lock lock(mutex_);
    if (policy_ == OverflowPolicy::kBlock) {
      not_full_.wait(lock, [&] { return closed_ || items_.size() < capacity_; });
    }
    if (closed_) return false;
    if (items_.size() >= capacity_) {
      items_.pop_front();
      ++dropped_;
    }
    items_.push_back(std::move(item));
    ++pushed_;
    if (items_.size() > max_depth_) max_depth_ = items_.size();
    lock.unlock();
    not_empty_.notify_one();
    return true;
  }

  // Waits for an item; nullopt once the queue is closed and empty.
  std::optional<T> pop() {
    std::unique_lock lock(mutex_);
    not_empty_.wait(lock, [&] { return closed_ || !items_.empty(); });
    return take(lock);
  }

  // Never waits; nullopt when empty.
  std::optional<T> try_pop() {
    std::unique_lock lock(mutex_);
    return take(lock);
  }

  void close() {
    {
      std::lock_guard lock(mutex_);
      closed_ = true;
    }
    not_empty_.notify_all();
    not_full_.notify_all();
  }

  // Returns how many items were thrown away.
  std::size_t discard() {
    std::size_t n = 0;
    {
      std::lock_guard lock(mutex_);
      n = items_.size();
      items_.clear();
    }
    not_full_.notify_all();
    return n;
  }

  bool closed() const {
    std::lock_guard lock(mutex_);
    return closed_;
  }
  std::size_t depth() const {
    std::lock_guard lock(mutex_);
    return items_.size();
  }
  std::size_t max_depth() const {
    std::lock_guard lock(mutex_);
    return max_depth_;
  }
  std::int64_t pushed() const {
    std::lock_guard lock(mutex_);
    return pushed_;
  }
  std::int64_t dropped() const {
    std::lock_guard lock(mutex_);
    return dropped_;
  }
  std::size_t capacity() const { return capacity_; }
  OverflowPolicy policy() const { return policy_; }

 private:
  std::optional<T> take(std::unique_lock<std::mutex>& lock) {
    if (items_.empty()) return std::nullopt;
    std::optional<T> item(std::move(items_.front()));
    items_.pop_front();
    lock.unlock();
    not_full_.notify_one();
    return item;
  }

  const std::size_t capacity_;
  const OverflowPolicy policy_;
  mutable std::mutex mutex_;
  std::condition_variable not_empty_;
  std::condition_variable not_full_;
  std::deque<T> items_;
  bool closed_ = false;
  std::size_t max_depth_ = 0;
  std::int64_t pushed_ = 0;
  std::int64_t dropped_ = 0;
};

}  // namespace gbdcs::vision
