// EventListeners that come with the core.
//
// StorageListener  writes every gesture, command (with outcome), alert and telemetry frame of
//                  one session to the StorageManager. A failed write is counted and passed to
//                  the error handler (the console/log), never silently dropped.
// ConsoleListener  prints one line per event to a stream (the `fly` subcommand, logs).
#pragma once

#include <cstdint>
#include <functional>
#include <iosfwd>
#include <mutex>

#include "gbdcs/runtime/control_loop.hpp"
#include "gbdcs/storage/storage_manager.hpp"

namespace gbdcs::runtime {

class StorageListener final : public EventListener {
 public:
  using ErrorHandler = std::function<void(const std::string&)>;
  StorageListener(storage::StorageManager& storage, std::int64_t session_id,
                  ErrorHandler on_error = {});
  void on_gesture(const contracts::GestureEvent& event) override;
  void on_command(const contracts::DroneCommand& command, const std::string& outcome) override;
  void on_alert(const contracts::Alert& alert) override;
  void on_telemetry(const contracts::TelemetryFrame& frame) override;
  std::uint64_t failures() const;

 private:
  void check(const storage::WriteResult& result, const char* what);
  storage::StorageManager& storage_;
  std::int64_t session_id_;
  ErrorHandler on_error_;
  mutable std::mutex mutex_;
  std::uint64_t failures_ = 0;
};

struct ConsoleOptions {
  bool gestures = true;
  bool commands = true;
  bool alerts = true;
  bool telemetry = true;
  bool json = false;  // one JSON document per line instead of text
};

class ConsoleListener final : public EventListener {
 public:
  ConsoleListener(std::ostream& out, ConsoleOptions options = {});
  void on_gesture(const contracts::GestureEvent& event) override;
  void on_command(const contracts::DroneCommand& command, const std::string& outcome) override;
  void on_alert(const contracts::Alert& alert) override;
  void on_telemetry(const contracts::TelemetryFrame& frame) override;

 private:
  void write(const std::string& line);
  std::ostream& out_;
  ConsoleOptions options_;
  std::mutex mutex_;
};

}  // namespace gbdcs::runtime
