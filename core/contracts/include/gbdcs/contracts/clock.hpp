// Clock: the only source of time for the core.
//
// Every timer in core/ reads an injected Clock. `SteadyClock` is the real one (the server);
// `ManualClock` is driven by tests and by the scenario runner, which steps it lockstep with
// the simulator, faster than real time and deterministically.
//
//   now()      monotonic time since the clock's epoch (never goes back)
//   utc_now()  wall-clock UTC, for timestamps in messages and logs
#pragma once

#include <chrono>
#include <cstdint>
#include <mutex>

namespace gbdcs::contracts {

using Duration = std::chrono::nanoseconds;
using UtcTime = std::chrono::time_point<std::chrono::system_clock, std::chrono::milliseconds>;

class Clock {
 public:
  virtual ~Clock() = default;
  virtual Duration now() const = 0;
  virtual UtcTime utc_now() const = 0;
};

// The real clock. The single place in core/ that reads the operating system's clocks.
class SteadyClock final : public Clock {
 public:
  SteadyClock();
  Duration now() const override;
  UtcTime utc_now() const override;

 private:
  std::chrono::steady_clock::time_point origin_;
};

// A clock that moves only when told to. Thread-safe.
class ManualClock final : public Clock {
 public:
  explicit ManualClock(UtcTime utc_origin = UtcTime{std::chrono::milliseconds{1'767'225'600'000}});
  Duration now() const override;
  UtcTime utc_now() const override;
  void advance(Duration step);
  void set(Duration since_origin);  // must not go back; throws std::invalid_argument if it would

 private:
  mutable std::mutex mutex_;
  Duration now_{0};
  UtcTime utc_origin_;
};

inline double to_seconds(Duration d) { return std::chrono::duration<double>(d).count(); }
inline Duration from_seconds(double s) {
  return std::chrono::duration_cast<Duration>(std::chrono::duration<double>(s));
}

}  // namespace gbdcs::contracts
