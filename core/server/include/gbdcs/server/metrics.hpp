// Metrics for GET /metrics (Prometheus text format 0.0.4): counters, gauges read on demand,
// and fixed-bucket histograms. Thread-safe; cheap enough for every request and message.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <string>
#include <vector>

namespace gbdcs::server {

class Histogram {
 public:
  explicit Histogram(std::vector<double> bounds) : bounds_(std::move(bounds)), counts_(bounds_.size() + 1) {}
  void observe(double value);
  // Prometheus lines for `name` (with _bucket/_sum/_count).
  std::string render(const std::string& name, const std::string& help) const;
  double quantile(double q) const;  // from the buckets (upper bound of the bucket)
  std::uint64_t count() const;

 private:
  std::vector<double> bounds_;
  mutable std::mutex mutex_;
  std::vector<std::uint64_t> counts_;
  double sum_ = 0;
  std::uint64_t total_ = 0;
};

class Metrics {
 public:
  Metrics();
  void count_request(int status);
  // Requests answered so far with a status in [lo, hi] (a 5xx count: 500, 599).
  std::uint64_t requests_with_status(int lo, int hi) const;
  Histogram request_ms;
  Histogram vision_latency_ms;
  Histogram ws_delivery_ms;
  std::atomic<std::uint64_t> vision_frames{0};
  std::atomic<std::uint64_t> feed_pictures{0};  // camera pictures broadcast for the live feed
  std::atomic<std::uint64_t> worker_restarts{0};
  std::atomic<std::uint64_t> alerts{0};
  std::atomic<std::uint64_t> commands{0};
  std::atomic<std::uint64_t> ws_rejected{0};
  // Gauges read at render time: name -> (help, value function).
  void gauge(const std::string& name, const std::string& help, std::function<double()> read);
  std::string render() const;

 private:
  mutable std::mutex mutex_;
  std::map<int, std::uint64_t> requests_by_status_;
  std::vector<std::tuple<std::string, std::string, std::function<double()>>> gauges_;
};

}  // namespace gbdcs::server
