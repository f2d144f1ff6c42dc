#include "gbdcs/contracts/clock.hpp"

#include <stdexcept>

namespace gbdcs::contracts {

SteadyClock::SteadyClock() : origin_(std::chrono::steady_clock::now()) {}

Duration SteadyClock::now() const {
  return std::chrono::duration_cast<Duration>(std::chrono::steady_clock::now() - origin_);
}

UtcTime SteadyClock::utc_now() const {
  return std::chrono::time_point_cast<std::chrono::milliseconds>(std::chrono::system_clock::now());
}

ManualClock::ManualClock(UtcTime utc_origin) : utc_origin_(utc_origin) {}

Duration ManualClock::now() const {
  std::lock_guard lock(mutex_);
  return now_;
}

UtcTime ManualClock::utc_now() const {
  std::lock_guard lock(mutex_);
  return utc_origin_ + std::chrono::duration_cast<std::chrono::milliseconds>(now_);
}

void ManualClock::advance(Duration step) {
  if (step < Duration::zero()) throw std::invalid_argument("ManualClock::advance: negative step");
  std::lock_guard lock(mutex_);
  now_ += step;
}

void ManualClock::set(Duration since_origin) {
  std::lock_guard lock(mutex_);
  if (since_origin < now_) throw std::invalid_argument("ManualClock::set: time must not go back");
  now_ = since_origin;
}

}  // namespace gbdcs::contracts
