// The messages every part of GBDCS exchanges. Defined once; their JSON form is checked
// against the schemas in core/contracts/schemas/ (see codec.hpp). Units are in the names.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "gbdcs/contracts/clock.hpp"

namespace gbdcs::contracts {

// ---- gestures -------------------------------------------------------------------------
enum class GestureType {
  kNone,
  kOpenPalm,
  kFist,
  kThumbUp,
  kThumbDown,
  kPointLeft,
  kPointRight,
  kPointUp,
  kVictory,
  kILoveYou,
};
inline constexpr std::array<GestureType, 10> kAllGestures = {
    GestureType::kNone,      GestureType::kOpenPalm,  GestureType::kFist,
    GestureType::kThumbUp,   GestureType::kThumbDown, GestureType::kPointLeft,
    GestureType::kPointRight, GestureType::kPointUp,  GestureType::kVictory,
    GestureType::kILoveYou};
std::string_view to_string(GestureType g);                   // "OPEN_PALM", ...
std::optional<GestureType> gesture_from_string(std::string_view s);

enum class Handedness { kLeft, kRight };
std::string_view to_string(Handedness h);  // "Left" / "Right", as MediaPipe labels them
std::optional<Handedness> handedness_from_string(std::string_view s);

// A landmark in normalised image coordinates: x right, y down, both in [0, 1] over the
// frame; z is depth relative to the wrist in roughly the same scale as x.
struct Point3 {
  double x = 0;
  double y = 0;
  double z = 0;
};

inline constexpr std::size_t kLandmarkCount = 21;
// MediaPipe Hands landmark order.
enum LandmarkIndex : std::size_t {
  kWrist = 0,
  kThumbCmc, kThumbMcp, kThumbIp, kThumbTip,
  kIndexMcp, kIndexPip, kIndexDip, kIndexTip,
  kMiddleMcp, kMiddlePip, kMiddleDip, kMiddleTip,
  kRingMcp, kRingPip, kRingDip, kRingTip,
  kPinkyMcp, kPinkyPip, kPinkyDip, kPinkyTip,
};

struct Landmarks {
  std::array<Point3, kLandmarkCount> points{};
  Handedness handedness = Handedness::kRight;
  double score = 0;  // hand presence in [0, 1]
};

struct GestureEvent {
  GestureType gesture = GestureType::kNone;
  double confidence = 0;  // [0, 1]
  Handedness handedness = Handedness::kRight;
  std::int64_t frame_id = 0;
  UtcTime timestamp{};
  bool repeat = false;  // true when the gesture is still held (a refresh), false at onset
};

// ---- commands -------------------------------------------------------------------------
enum class CommandType { kTakeoff, kLand, kHover, kMove, kEmergencyStop };
std::string_view to_string(CommandType t);  // "TAKEOFF", ...
std::optional<CommandType> command_type_from_string(std::string_view s);

// Who asked. Priority comes from this (and EMERGENCY_STOP beats everything).
enum class CommandSource { kGesture, kKeyboard, kApi, kFailsafe, kScenario };
std::string_view to_string(CommandSource s);  // "gesture", ...
std::optional<CommandSource> command_source_from_string(std::string_view s);

// Body frame: x forward, y right, z up; yaw rate positive clockwise seen from above.
struct MotionPayload {
  double vx_m_s = 0;
  double vy_m_s = 0;
  double vz_m_s = 0;
  double yaw_rate_deg_s = 0;
  double duration_s = 0;  // 0 = until the next command
};

struct DroneCommand {
  CommandType type = CommandType::kHover;
  CommandSource source = CommandSource::kGesture;
  std::string source_id;  // e.g. the gesture name, the key, "LINK_LOSS"
  std::optional<MotionPayload> payload;
  std::int64_t id = 0;
  UtcTime issued_at{};
};

// ---- telemetry ------------------------------------------------------------------------
enum class FlightState { kInit, kReady, kFlying, kLanding, kFault };
std::string_view to_string(FlightState s);  // "INIT", ...
std::optional<FlightState> flight_state_from_string(std::string_view s);

enum class LinkState { kOk, kDegraded, kLost };
std::string_view to_string(LinkState s);  // "OK", "DEGRADED", "LOST"
std::optional<LinkState> link_state_from_string(std::string_view s);

struct TelemetryFrame {
  UtcTime timestamp{};
  double altitude_m = 0;
  double speed_m_s = 0;
  double vx_m_s = 0;  // body frame, as in MotionPayload
  double vy_m_s = 0;
  double vz_m_s = 0;
  double x_m = 0;  // displacement from the session origin, x north/forward-at-start
  double y_m = 0;
  double heading_deg = 0;  // [0, 360)
  double battery_pct = 100;
  FlightState flight_state = FlightState::kInit;
  LinkState link = LinkState::kOk;
};

// ---- alerts ---------------------------------------------------------------------------
enum class Severity { kInfo, kWarning, kCritical };
std::string_view to_string(Severity s);  // "INFO", "WARNING", "CRITICAL"
std::optional<Severity> severity_from_string(std::string_view s);

struct Alert {
  Severity severity = Severity::kInfo;
  std::string code;        // LINK_LOSS, IDLE_HOVER, BATTERY_LOW, ... (docs/ALERTS.md)
  std::string cause;       // what happened, for a person
  std::string suggestion;  // what to do about it
  UtcTime timestamp{};
  std::int64_t id = 0;
};

}  // namespace gbdcs::contracts
