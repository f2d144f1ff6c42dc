#include "gbdcs/server/metrics.hpp"

#include <sstream>

namespace gbdcs::server {

void Histogram::observe(double value) {
  std::lock_guard lock(mutex_);
  std::size_t i = 0;
  while (i < bounds_.size() && value > bounds_[i]) ++i;
  ++counts_[i];
  sum_ += value;
  ++total_;
}

std::string Histogram::render(const std::string& name, const std::string& help) const {
  std::lock_guard lock(mutex_);
  std::ostringstream out;
  out << "# HELP " << name << " " << help << "\n# TYPE " << name << " histogram\n";
  std::uint64_t cumulative = 0;
  for (std::size_t i = 0; i < bounds_.size(); ++i) {
    cumulative += counts_[i];
    out << name << "_bucket{le=\"" << bounds_[i] << "\"} " << cumulative << "\n";
  }
  out << name << "_bucket{le=\"+Inf\"} " << total_ << "\n"
      << name << "_sum " << sum_ << "\n"
      << name << "_count " << total_ << "\n";
  return out.str();
}

double Histogram::quantile(double q) const {
  std::lock_guard lock(mutex_);
  if (total_ == 0) return 0;
  const auto target = static_cast<std::uint64_t>(q * static_cast<double>(total_) + 0.5);
  std::uint64_t cumulative = 0;
  for (std::size_t i = 0; i < bounds_.size(); ++i) {
    cumulative += counts_[i];
    if (cumulative >= target) return bounds_[i];
  }
  return bounds_.empty() ? 0 : bounds_.back() * 2;
}

std::uint64_t Histogram::count() const {
  std::lock_guard lock(mutex_);
  return total_;
}

Metrics::Metrics()
    : request_ms({1, 2, 5, 10, 25, 50, 100, 250, 500, 1000, 2500}),
      vision_latency_ms({5, 10, 20, 30, 50, 75, 100, 150, 250, 500}),
      ws_delivery_ms({1, 2, 5, 10, 20, 50, 100, 250, 500, 1000}) {}

void Metrics::count_request(int status) {
  std::lock_guard lock(mutex_);
  ++requests_by_status_[status];
}

std::uint64_t Metrics::requests_with_status(int lo, int hi) const {
  std::lock_guard lock(mutex_);
  std::uint64_t n = 0;
  for (auto it = requests_by_status_.lower_bound(lo); it != requests_by_status_.end() && it->first <= hi;
       ++it) {
    n += it->second;
  }
  return n;
}

void Metrics::gauge(const std::string& name, const std::string& help,
                    std::function<double()> read) {
  std::lock_guard lock(mutex_);
  gauges_.emplace_back(name, help, std::move(read));
}

std::string Metrics::render() const {
  std::ostringstream out;
  auto counter = [&](const char* name, const char* help, std::uint64_t v) {
    out << "# HELP " << name << " " << help << "\n# TYPE " << name << " counter\n"
        << name << " " << v << "\n";
  };
  {
    std::lock_guard lock(mutex_);
    out << "# HELP gbdcs_http_requests_total HTTP requests by status\n"
        << "# TYPE gbdcs_http_requests_total counter\n";
    for (const auto& [status, n] : requests_by_status_) {
      out << "gbdcs_http_requests_total{status=\"" << status << "\"} " << n << "\n";
    }
    for (const auto& [name, help, read] : gauges_) {
      out << "# HELP " << name << " " << help << "\n# TYPE " << name << " gauge\n"
          << name << " " << read() << "\n";
    }
  }
  counter("gbdcs_vision_frames_total", "Frames received from the vision worker", vision_frames);
  counter("gbdcs_feed_pictures_total", "Camera pictures broadcast to /ws/live for the live feed",
          feed_pictures);
  counter("gbdcs_vision_worker_restarts_total", "Vision worker restarts", worker_restarts);
  counter("gbdcs_alerts_total", "Alerts raised", alerts);
  counter("gbdcs_commands_total", "Commands with an outcome", commands);
  counter("gbdcs_ws_rejected_total", "WebSocket upgrades refused", ws_rejected);
  out << request_ms.render("gbdcs_http_request_duration_ms", "HTTP request handling time, ms");
  out << vision_latency_ms.render("gbdcs_vision_latency_ms", "Capture to classified, ms");
  out << ws_delivery_ms.render("gbdcs_ws_delivery_ms", "Broadcast to written on the socket, ms");
  return out.str();
}

}  // namespace gbdcs::server
