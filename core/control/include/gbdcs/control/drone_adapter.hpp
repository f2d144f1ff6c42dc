// DroneAdapter: the one interface every drone speaks (dummy, twin, tello, airsim, xfly).
//
// Inputs : connect/disconnect, takeoff, land, hover, move(MotionPayload), emergency_stop.
// Outputs: Result of each call (typed, never an exception across this boundary);
//          TelemetryFrames pushed to the sink set with set_telemetry_sink(), at >= 5 Hz
//          while connected; state() the current FlightState.
// Threading: calls may come from any thread; an adapter serialises them itself. The sink
//          may be called from the adapter's own thread or from poll().
// poll(): adapters driven by a host loop (the dummy, the twin in lockstep) advance their
//          simulation to the injected clock's now and emit telemetry there; adapters with
//          their own I/O threads may leave it empty.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <string_view>

#include "gbdcs/contracts/messages.hpp"

namespace gbdcs::control {

enum class Result {
  kOk,
  kNotConnected,  // connect() first, or the link is down
  kRejected,      // the drone refused in its current state (e.g. land while on the ground)
  kTimeout,       // no reply in time
  kUnsupported,   // this drone cannot do that
  kError,         // anything else; last_error() says what
};
std::string_view to_string(Result r);

using TelemetrySink = std::function<void(const contracts::TelemetryFrame&)>;

class DroneAdapter {
 public:
  virtual ~DroneAdapter() = default;
  virtual std::string_view name() const = 0;

  virtual Result connect() = 0;
  virtual Result disconnect() = 0;
  virtual Result takeoff() = 0;
  virtual Result land() = 0;
  virtual Result hover() = 0;
  virtual Result move(const contracts::MotionPayload& motion) = 0;
  virtual Result emergency_stop() = 0;

  virtual contracts::FlightState state() const = 0;
  virtual void set_telemetry_sink(TelemetrySink sink) = 0;
  virtual void poll() {}
  virtual std::string last_error() const { return {}; }
};

// Sends one command to the adapter (MOVE without payload is kRejected).
Result execute(DroneAdapter& adapter, const contracts::DroneCommand& command);

// Creates adapters by name; the app fills it from adapters/registry so core never names one.
using AdapterFactory = std::function<std::unique_ptr<DroneAdapter>(std::string_view name)>;

}  // namespace gbdcs::control
