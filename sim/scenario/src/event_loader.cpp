// The scenario loader's events part: events[i] of a scenario file, and their names.
#include <algorithm>
#include <cmath>
#include <sstream>

#include "gbdcs/contracts/codec.hpp"
#include "gbdcs/control/keyboard_input.hpp"
#include "json_fields.hpp"
#include "loader_parts.hpp"

namespace gbdcs::sim {

namespace {

constexpr std::array<std::pair<EventType, std::string_view>, 9> kEvents{{
    {EventType::kLinkLoss, "link_loss"},
    {EventType::kTelemetryDelay, "telemetry_delay"},
    {EventType::kBatteryJump, "battery_jump"},
    {EventType::kWindGust, "wind_gust"},
    {EventType::kMotorFault, "motor_fault"},
    {EventType::kVisionCrash, "vision_crash"},
    {EventType::kVisionUnhealthy, "vision_unhealthy"},
    {EventType::kEmergencyStop, "emergency_stop"},
    {EventType::kKey, "key"},
}};

}  // namespace

namespace detail {

ScenarioEvent read_event(const nlohmann::json& v, const std::string& origin,
                         const std::string& path, double timeout_s) {
  Fields g(v, origin, path);
  ScenarioEvent e;
  const auto type = g.string("type");
  auto t = find_in(kEvents, type);
  if (!t) g.fail("type", "unknown event '" + type + "'; use one of: " + join(names_of(kEvents)));
  e.type = *t;
  e.at_s = g.number("at_s", 0, timeout_s);
  auto duration = [&](bool required) {
    if (required) {
      e.duration_s = g.number("duration_s", 0.001, 3600);
    } else {
      e.duration_s = g.opt_number("duration_s", 0.001, 3600).value_or(kForever);
    }
  };
  switch (e.type) {
    case EventType::kLinkLoss:
      duration(true);
      break;
    case EventType::kTelemetryDelay:
      duration(true);
      e.delay_ms = g.number("delay_ms", 0, 60000);
      e.jitter_ms = g.opt_number("jitter_ms", 0, 60000).value_or(0);
      break;
    case EventType::kBatteryJump:
      e.battery_pct = g.number("battery_pct", 0, 100);
      break;
    case EventType::kWindGust: {
      duration(true);
      const auto& force = g.get("force_n");
      if (!force.is_array() || force.size() != 3 ||
          !std::all_of(force.begin(), force.end(), [](const auto& x) { return x.is_number(); })) {
        g.fail("force_n", "must be [x, y, z] in newtons (x forward, y right, z up)");
      }
      for (int i = 0; i < 3; ++i) {
        e.force_n[static_cast<std::size_t>(i)] = force[static_cast<std::size_t>(i)].get<double>();
        if (std::abs(e.force_n[static_cast<std::size_t>(i)]) > 5) {
          g.fail("force_n", "a component above 5 N would throw an 80 g drone across the room; "
                            "use at most 5");
        }
      }
      break;
    }
    case EventType::kMotorFault:
      duration(false);
      e.motor = g.opt_int("motor", 0, 3).value_or(0);
      e.thrust_factor = g.number("thrust_factor", 0, 1);
      break;
    case EventType::kVisionCrash: {
      duration(false);
      const auto detect = g.opt_string("detect").value_or("exit");
      if (detect != "exit" && detect != "silence") {
        g.fail("detect", "use \"exit\" (the supervisor sees the worker die) or \"silence\" "
                         "(the worker hangs; only the missing frames tell)");
      }
      e.detected_at_exit = detect == "exit";
      break;
    }
    case EventType::kVisionUnhealthy:
      duration(false);
      e.reason = g.opt_string("reason").value_or("the camera reports a fault");
      break;
    case EventType::kEmergencyStop: {
      const auto source = g.opt_string("source").value_or("api");
      if (source != "api" && source != "keyboard") {
        g.fail("source", "use \"api\" (the dashboard's button) or \"keyboard\" (Space)");
      }
      e.source = source == "api" ? contracts::CommandSource::kApi
                                 : contracts::CommandSource::kKeyboard;
      break;
    }
    case EventType::kKey:
      e.key = g.string("key");
      if (!control::KeyboardInput{}.command_for(e.key)) {
        g.fail("key", "'" + e.key + "' means nothing to the keyboard input; use w a s d q e r f "
                      "t l h, an arrow key name or \" \" (docs/SAFETY.md)");
      }
      break;
  }
  g.finish("a " + type + " event");
  return e;
}

}  // namespace detail

std::string_view to_string(EventType t) { return detail::name_in(kEvents, t); }
std::optional<EventType> event_type_from_string(std::string_view s) {
  return detail::find_in(kEvents, s);
}

std::string ScenarioEvent::describe() const {
  std::ostringstream s;
  s << sim::to_string(type);
  switch (type) {
    case EventType::kTelemetryDelay: s << " " << delay_ms << " ms"; break;
    case EventType::kBatteryJump: s << " to " << battery_pct << " %"; break;
    case EventType::kWindGust:
      s << " [" << force_n[0] << ", " << force_n[1] << ", " << force_n[2] << "] N";
      break;
    case EventType::kMotorFault: s << " motor " << motor << " x" << thrust_factor; break;
    case EventType::kVisionCrash: s << (detected_at_exit ? " (exit)" : " (silent)"); break;
    case EventType::kVisionUnhealthy: s << " (" << reason << ")"; break;
    case EventType::kEmergencyStop: s << " from " << contracts::to_string(source); break;
    case EventType::kKey: s << " '" << key << "'"; break;
    default: break;
  }
  if (duration_s != kForever &&
      (type == EventType::kLinkLoss || type == EventType::kTelemetryDelay ||
       type == EventType::kWindGust || type == EventType::kMotorFault ||
       type == EventType::kVisionCrash || type == EventType::kVisionUnhealthy)) {
    s << " for " << duration_s << " s";
  }
  return s.str();
}

}  // namespace gbdcs::sim
