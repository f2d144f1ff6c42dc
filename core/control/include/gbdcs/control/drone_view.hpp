// DroneViewSource: an optional capability of a DroneAdapter: a live picture of or from the
// drone (the twin's chase camera; a real drone's video where an adapter can decode it). An
// adapter that has one also derives from DroneViewSource; the server asks with dynamic_cast,
// so drones without a camera need nothing.
//
// start_view(options, sink): JPEG images of about options.width x options.height at about
//          options.fps, pushed to the sink from the adapter's own thread until stop_view()
//          (which returns once the sink is no longer called) or the adapter's disconnect().
//          kRejected with last_error() for options it cannot honour.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include "gbdcs/control/drone_adapter.hpp"

namespace gbdcs::control {

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

class DroneViewSource {
 public:
  virtual ~DroneViewSource() = default;
  virtual Result start_view(const ViewOptions& options, ViewSink sink) = 0;
  virtual void stop_view() = 0;
};

}  // namespace gbdcs::control
