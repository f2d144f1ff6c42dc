#include "gbdcs/control/drone_adapter.hpp"

namespace gbdcs::control {

std::string_view to_string(Result r) {
  switch (r) {
    case Result::kOk: return "OK";
    case Result::kNotConnected: return "NOT_CONNECTED";
    case Result::kRejected: return "REJECTED";
    case Result::kTimeout: return "TIMEOUT";
    case Result::kUnsupported: return "UNSUPPORTED";
    case Result::kError: return "ERROR";
  }
  return "ERROR";
}

Result execute(DroneAdapter& adapter, const contracts::DroneCommand& command) {
  using contracts::CommandType;
  switch (command.type) {
    case CommandType::kTakeoff: return adapter.takeoff();
    case CommandType::kLand: return adapter.land();
    case CommandType::kHover: return adapter.hover();
    case CommandType::kEmergencyStop: return adapter.emergency_stop();
    case CommandType::kMove:
      if (!command.payload) return Result::kRejected;
      return adapter.move(*command.payload);
  }
  return Result::kError;
}

}  // namespace gbdcs::control
