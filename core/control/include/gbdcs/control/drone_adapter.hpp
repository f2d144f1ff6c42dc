// DroneAdapter: the one interface every drone speaks (dummy, twin, tello, airsim, xfly).
//
// Inputs : connect/disconnect, takeoff, land, hover, move(MotionPayload), emergency_stop.
// Outputs: Result of each call (typed, never an exception across this boundary);
//          TelemetryFrames pushed to the sink set with set_telemetry_sink(), at >= 5 Hz
//          while connected; state() the current FlightState.
// Threading: calls may come from any thread; an adapter serialises them itself. The sink
//          may be called from the adapter's own thread or from poll().
// View (optional capability): start_view() asks the drone for a live picture (the twin's
//          chase camera; a real drone's video where an adapter can decode it): JPEG images
//          of about options.width x options.height at about options.fps, pushed to the sink
//          from the adapter's own thread until stop_view() (which returns once the sink is no
//          longer called) or disconnect. Default: kUnsupported, no picture.
// poll(): adapters driven by a host loop (the dummy, the twin in lockstep) advance their
//          simulation to the injected clock's now and emit telemetry there; adapters with
//          their own I/O threads may leave it empty.
#pragma once

#include <cstdint>
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

struct ViewOptions {
  int width = 320;
  int height = 240;
  double fps = 5;
  int jpeg_quality = 70;  // 1...100
};
struct DroneView {
  std::string jpeg;    // the encoded image (bytes)
  int width = 0;       // px
  int height = 0;      // px
  std::string camera;  // e.g. "chase"
  std::int64_t frame_id = 0;
};
using ViewSink = std::function<void(const DroneView&)>;

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

  virtual Result start_view(const ViewOptions& /*options*/, ViewSink /*sink*/) {
    return Result::kUnsupported;
  }
  virtual void stop_view() {}
};

// Sends one command to the adapter (MOVE without payload is kRejected).
Result execute(DroneAdapter& adapter, const contracts::DroneCommand& command);

// Creates adapters by name; the app fills it from adapters/registry so core never names one.
using AdapterFactory = std::function<std::unique_ptr<DroneAdapter>(std::string_view name)>;

}  // namespace gbdcs::control
