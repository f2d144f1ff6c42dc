// The scenario's drones (twin, dummy) and landmark cameras (gesture timelines); the pixel
// cameras are in pixel_camera.cpp.
#include <mutex>
#include <stdexcept>

#include "gbdcs/adapters/dummy_adapter.hpp"
#include "gbdcs/sim/gesture_timeline.hpp"
#include "gbdcs/sim/twin_adapter.hpp"
#include "runner_parts.hpp"

namespace gbdcs::sim::detail {

std::shared_ptr<const TwinModel> shared_twin_model() {
  static std::mutex mutex;
  static std::shared_ptr<const TwinModel> model;
  std::lock_guard lock(mutex);
  if (!model) model = std::make_shared<const TwinModel>();
  return model;
}

// ---- drones -----------------------------------------------------------------------------

FaultSchedule faults_of(const Scenario& s, std::vector<Fault> base) {
  for (const auto& e : s.events) {
    Fault f;
    f.start_s = e.at_s;
    f.duration_s = e.duration_s;
    switch (e.type) {
      case EventType::kLinkLoss: f.type = FaultType::kLinkLoss; break;
      case EventType::kTelemetryDelay:
        f.type = FaultType::kTelemetryDelay;
        f.delay_ms = e.delay_ms;
        f.jitter_ms = e.jitter_ms;
        break;
      case EventType::kBatteryJump:
        f.type = FaultType::kBatteryJump;
        f.battery_pct = e.battery_pct;
        f.duration_s = kForever;
        break;
      case EventType::kWindGust:
        f.type = FaultType::kWindGust;
        f.force_n = e.force_n;
        break;
      case EventType::kMotorFault:
        f.type = FaultType::kMotorDegraded;
        f.motor = e.motor;
        f.thrust_factor = e.thrust_factor;
        break;
      default: continue;  // not a fault of the drone
    }
    base.push_back(f);
  }
  return FaultSchedule(std::move(base));
}

namespace {

class TwinDrone final : public ScenarioDrone {
 public:
  TwinDrone(const Scenario& s, const contracts::Clock& clock,
            std::shared_ptr<const TwinModel> model) {
    auto options = TwinAdapterOptions::from_json(s.drone.options);
    if (options.realtime) {
      throw std::invalid_argument("drone.options.realtime: scenarios run lockstep; remove it");
    }
    options.twin.faults = faults_of(s, options.twin.faults.faults());
    adapter_ = std::make_unique<TwinAdapter>(clock, std::move(model), options);
  }
  control::DroneAdapter& adapter() override { return *adapter_; }
  void on_event(const ScenarioEvent&, bool) override {}  // all in the fault schedule
  std::optional<int> collisions() const override { return adapter_->twin_status().collisions; }
  std::vector<double> pose_qpos() const override {
    std::vector<double> q;
    adapter_->inspect([&](const TwinSim& sim) {
      const int adr = sim.twin_model().free_joint_qpos_address();
      q.assign(sim.data()->qpos + adr, sim.data()->qpos + adr + 7);
    });
    return q;
  }
  std::string describe() const override { return "twin"; }

 private:
  std::unique_ptr<TwinAdapter> adapter_;
};

class DummyDrone final : public ScenarioDrone {
 public:
  DummyDrone(const Scenario& s, const contracts::Clock& clock) {
    for (const auto& e : s.events) {
      if (e.type == EventType::kTelemetryDelay || e.type == EventType::kWindGust ||
          e.type == EventType::kMotorFault) {
        throw std::invalid_argument("the dummy drone has no physics or radio model for a " +
                                    std::string(to_string(e.type)) +
                                    " event; fly the twin (\"drone\": \"twin\")");
      }
    }
    adapter_ = std::make_unique<adapters::DummyDroneAdapter>(
        clock, adapters::DummyOptions::from_json(s.drone.options));
  }
  control::DroneAdapter& adapter() override { return *adapter_; }
  void on_event(const ScenarioEvent& e, bool starting) override {
    if (e.type == EventType::kLinkLoss) adapter_->set_link_lost(starting);
    if (e.type == EventType::kBatteryJump && starting) adapter_->set_battery_pct(e.battery_pct);
  }
  std::optional<int> collisions() const override { return std::nullopt; }
  std::vector<double> pose_qpos() const override { return {}; }
  std::string describe() const override { return "dummy"; }

 private:
  std::unique_ptr<adapters::DummyDroneAdapter> adapter_;
};

// ---- cameras ----------------------------------------------------------------------------

class TimelineCamera final : public ScenarioCamera {
 public:
  explicit TimelineCamera(const CameraSpec& spec)
      : timeline_(GestureTimeline::from_json(spec.timeline)),
        frames_(timeline_.frame_count()),
        name_("timeline '" + timeline_.name() + "'") {}

  double fps() const override { return timeline_.fps(); }
  CameraFrame next() override {
    CameraFrame f;
    if (index_++ < frames_) {
      auto t = timeline_.next_frame();
      f.hand = std::move(t.hand);
      f.label = t.label;
    } else {
      f.label = "NO_HAND";
    }
    return f;
  }
  std::vector<LabelledSegment> segments() const override {
    std::vector<LabelledSegment> out;
    double start = 0;
    for (const auto& s : timeline_.segments()) {
      LabelledSegment l;
      l.start_s = start;
      l.end_s = start + s.duration_s;
      l.label = s.pose ? std::string(to_string(*s.pose)) : "NO_HAND";
      if (s.pose) l.gesture = gesture_of(*s.pose);
      out.push_back(l);
      start = l.end_s;
    }
    return out;
  }
  std::string describe() const override { return name_; }

 private:
  GestureTimeline timeline_;
  std::size_t frames_;
  std::size_t index_ = 0;
  std::string name_;
};

}  // namespace

std::unique_ptr<ScenarioDrone> make_scenario_drone(const Scenario& s, const contracts::Clock& clock,
                                                   std::shared_ptr<const TwinModel> model) {
  switch (s.drone.kind) {
    case DroneKind::kTwin: return std::make_unique<TwinDrone>(s, clock, std::move(model));
    case DroneKind::kDummy: return std::make_unique<DummyDrone>(s, clock);
    default: return make_emulator_drone(s, clock, std::move(model));
  }
}

std::unique_ptr<ScenarioCamera> open_scenario_camera(const CameraSpec& spec,
                                                     const CameraOptions& options) {
  if (spec.kind == CameraKind::kTimeline) return std::make_unique<TimelineCamera>(spec);
  return open_pixel_camera(spec, options);
}

}  // namespace gbdcs::sim::detail
