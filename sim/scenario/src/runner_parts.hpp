// The runner's private pieces: the camera a scenario shows, the drone it flies, and the
// artifacts written for a run.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <opencv2/core/mat.hpp>
#include <optional>
#include <string>
#include <vector>

#include "gbdcs/contracts/clock.hpp"
#include "gbdcs/control/drone_adapter.hpp"
#include "gbdcs/sim/scenario.hpp"
#include "gbdcs/sim/faults.hpp"
#include "gbdcs/sim/scenario_criteria.hpp"
#include "gbdcs/sim/twin_model.hpp"

namespace gbdcs::sim::detail {

struct CameraFrame {
  std::optional<contracts::Landmarks> hand;  // what the vision stages found (nullopt: none)
  std::string label;                         // ground truth of the frame
  cv::Mat image;                             // the pixels, when the camera has them (BGR)
};

// A scenario's camera: frame i is shown at i / fps; after its last labelled segment it keeps
// running with no hand in view (the operator has put the hand down), so vision stays alive.
class ScenarioCamera {
 public:
  virtual ~ScenarioCamera() = default;
  virtual double fps() const = 0;
  virtual CameraFrame next() = 0;
  virtual std::vector<LabelledSegment> segments() const = 0;  // frames_shown left 0
  virtual std::string describe() const = 0;
};

// What a pixel camera needs besides its spec: where rendered recipes are cached and which
// hand models the vision stages load.
struct CameraOptions {
  std::string fixture_cache_dir;  // empty: sim::default_fixture_cache_dir()
  bool full_model = true;         // the models `gbdcs serve`'s vision worker loads by default
  std::string model_dir;          // empty: vision::default_model_dir()
};

std::unique_ptr<ScenarioCamera> open_scenario_camera(const CameraSpec& spec,
                                                     const CameraOptions& options);
// recipe and video + labels (pixel_camera.cpp).
std::unique_ptr<ScenarioCamera> open_pixel_camera(const CameraSpec& spec,
                                                  const CameraOptions& options);

// The drone of a scenario and the faults it can take.
class ScenarioDrone {
 public:
  virtual ~ScenarioDrone() = default;
  virtual control::DroneAdapter& adapter() = 0;
  // Runner-applied events (the dummy's link loss, battery): start at at_s, end after duration.
  virtual void on_event(const ScenarioEvent& event, bool starting) = 0;
  virtual std::optional<int> collisions() const = 0;
  // The free joint's qpos (x y z qw qx qy qz, MuJoCo frame) for the video; empty when the
  // drone has no physics (the runner places the model from telemetry instead).
  virtual std::vector<double> pose_qpos() const = 0;
  virtual std::string describe() const = 0;

  // Drones behind sockets (the emulators) keep lockstep with these; in-process ones need not.
  // advance(): after the core clock moved, step the drone's world to it and let its output
  // arrive; settle(): after the loop's tick, wait until nothing is in flight. False when the
  // link did not settle in time (settle_error() says why): the run stops with that error.
  virtual bool advance() { return true; }
  virtual bool settle() { return true; }
  virtual std::string settle_error() const { return {}; }
  // How many telemetry frames the core has taken in full (every inline observer ran): a frame
  // the adapter made but the core has not taken yet is still in flight for settle().
  virtual void count_frames_taken(std::function<std::uint64_t()> taken) { (void)taken; }
};

// The scenario's physical and radio faults as the twin's schedule, after `base`.
FaultSchedule faults_of(const Scenario& scenario, std::vector<Fault> base);

// tello-emulator, airsim-emulator, xfly-emulator (emulator_drone.cpp).
std::unique_ptr<ScenarioDrone> make_emulator_drone(const Scenario& scenario,
                                                   const contracts::Clock& clock,
                                                   std::shared_ptr<const TwinModel> model);

// Throws std::invalid_argument when the drone cannot take one of the scenario's events.
std::unique_ptr<ScenarioDrone> make_scenario_drone(const Scenario& scenario,
                                                   const contracts::Clock& clock,
                                                   std::shared_ptr<const TwinModel> model);

// The twin's model, loaded once per process and shared read-only.
std::shared_ptr<const TwinModel> shared_twin_model();

struct VideoSnapshot {
  double t_s = 0;
  std::vector<double> qpos;  // the free joint, or empty (placed from telemetry)
  std::optional<contracts::TelemetryFrame> telemetry;
  std::optional<contracts::Landmarks> hand;
  std::string label;
  std::vector<unsigned char> jpeg;  // the camera's frame, when it has pixels
  std::string last_command;
  std::string last_alert;
  bool vision_down = false;
};

struct LoggedEvent {
  double t_s = 0;
  std::string description;
};

// events.jsonl, trajectory.png and video.mp4 into `dir`; returns the files written.
std::vector<std::string> write_artifacts(const std::string& dir, const Scenario& scenario,
                                         const RunRecord& record,
                                         const std::vector<LoggedEvent>& events,
                                         const std::vector<VideoSnapshot>& video,
                                         double video_fps, const TwinModel& model);

}  // namespace gbdcs::sim::detail
