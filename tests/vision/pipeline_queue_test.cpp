// BoundedQueue: order, the two overflow policies, close and discard, many producers.
#include <gtest/gtest.h>

#include <atomic>
#include <thread>
#include <vector>

#include "gbdcs/vision/bounded_queue.hpp"

namespace gbdcs::vision {
namespace {

TEST(BoundedQueue, IsFifo) {
  BoundedQueue<int> q(4, OverflowPolicy::kBlock);
  for (int i = 0; i < 4; ++i) EXPECT_TRUE(q.push(i));
  EXPECT_EQ(q.depth(), 4u);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(q.pop(), i);
  EXPECT_EQ(q.try_pop(), std::nullopt);
  EXPECT_EQ(q.pushed(), 4);
  EXPECT_EQ(q.max_depth(), 4u);
}

TEST(BoundedQueue, RejectsZeroCapacity) {
  EXPECT_THROW(BoundedQueue<int>(0, OverflowPolicy::kBlock), std::invalid_argument);
}

TEST(BoundedQueue, DropOldestKeepsTheNewestAndCountsTheRest) {
  BoundedQueue<int> q(3, OverflowPolicy::kDropOldest);
  for (int i = 0; i < 10; ++i) EXPECT_TRUE(q.push(i));  // never waits
  EXPECT_EQ(q.depth(), 3u);
  EXPECT_EQ(q.dropped(), 7);
  EXPECT_EQ(q.pop(), 7);
  EXPECT_EQ(q.pop(), 8);
  EXPECT_EQ(q.pop(), 9);
}

TEST(BoundedQueue, BlockPolicyHoldsTheProducerUntilThereIsRoom) {
  BoundedQueue<int> q(2, OverflowPolicy::kBlock);
  std::thread producer([&] {
    for (int i = 0; i < 3; ++i) q.push(i);
  });
  while (q.pushed() < 2) std::this_thread::yield();
  // A correct queue can never reach 3 before a pop; a queue that does not block would at once.
  std::this_thread::sleep_for(std::chrono::milliseconds(30));
  EXPECT_EQ(q.pushed(), 2);
  EXPECT_EQ(q.pop(), 0);
  producer.join();
  EXPECT_EQ(q.pushed(), 3);
  EXPECT_EQ(q.dropped(), 0);
  EXPECT_EQ(q.pop(), 1);
  EXPECT_EQ(q.pop(), 2);
}

TEST(BoundedQueue, CloseLetsTheConsumerDrainThenEnds) {
  BoundedQueue<int> q(4, OverflowPolicy::kBlock);
  q.push(1);
  q.push(2);
  q.close();
  EXPECT_FALSE(q.push(3));
  EXPECT_EQ(q.pop(), 1);
  EXPECT_EQ(q.pop(), 2);
  EXPECT_EQ(q.pop(), std::nullopt);
  EXPECT_TRUE(q.closed());
}

TEST(BoundedQueue, CloseWakesABlockedConsumerAndABlockedProducer) {
  BoundedQueue<int> empty(1, OverflowPolicy::kBlock);
  std::optional<int> popped = 42;
  std::thread consumer([&] { popped = empty.pop(); });

  BoundedQueue<int> full(1, OverflowPolicy::kBlock);
  full.push(0);
  std::atomic<int> push_result{-1};
  std::thread producer([&] { push_result = full.push(1) ? 1 : 0; });

  empty.close();
  full.close();
  consumer.join();
  producer.join();
  EXPECT_EQ(popped, std::nullopt);
  EXPECT_EQ(push_result, 0);
}

TEST(BoundedQueue, DiscardEmptiesAndFreesABlockedProducer) {
  BoundedQueue<int> q(1, OverflowPolicy::kBlock);
  q.push(0);
  std::thread producer([&] { q.push(1); });
  while (q.depth() != 1) std::this_thread::yield();
  EXPECT_GE(q.discard(), 1u);
  producer.join();
  EXPECT_EQ(q.pop(), 1);
  EXPECT_EQ(q.dropped(), 0);  // discard is not a policy drop
}

TEST(BoundedQueue, ManyProducersOneConsumerLoseNothingAndKeepEachProducersOrder) {
  constexpr int kProducers = 4;
  constexpr int kEach = 2000;
  BoundedQueue<std::pair<int, int>> q(8, OverflowPolicy::kBlock);
  std::vector<std::thread> producers;
  for (int p = 0; p < kProducers; ++p) {
    producers.emplace_back([&q, p] {
      for (int i = 0; i < kEach; ++i) q.push({p, i});
    });
  }
  std::vector<int> next(kProducers, 0);
  for (int n = 0; n < kProducers * kEach; ++n) {
    auto item = q.pop();
    ASSERT_TRUE(item);
    ASSERT_EQ(item->second, next[static_cast<std::size_t>(item->first)])
        << "producer " << item->first;
    ++next[static_cast<std::size_t>(item->first)];
  }
  for (auto& t : producers) t.join();
  EXPECT_EQ(q.try_pop(), std::nullopt);
  EXPECT_EQ(q.dropped(), 0);
  EXPECT_LE(q.max_depth(), 8u);
}

}  // namespace
}  // namespace gbdcs::vision
