// Kinematic hand landmark synthesizer: a hand pose in, the 21 MediaPipe landmarks out.
//
// Inputs
//   HandPose   joint flexion per finger (MCP, PIP, DIP), thumb (CMC abduction + flexion,
//              MCP, IP), finger spread, and the hand's attitude (see HandOrientation). Angles
//              in degrees; positive flexion curls toward the palm.
//   Placement  where the hand is in the image: palm centre (normalised), size (hand length,
//              wrist to extended middle fingertip, as a fraction of the frame height), extra
//              in-plane roll and out-of-plane yaw/pitch (deg, |yaw|, |pitch| <= 40),
//              handedness (Left = the mirror image), frame aspect ratio, presence score.
// Outputs
//   contracts::Landmarks in normalised image coordinates, x right, y down (x scaled by the
//   frame width, y by its height), z depth relative to the wrist in the scale of x, larger =
//   farther from the camera. Weak-perspective (orthographic) projection.
// Pose library
//   pose_for(name, rng) draws a natural variant (a few degrees of joint noise) of each pose of
//   the gesture vocabulary and of the non-deliberate poses that must read as NONE. Direction
//   poses are aimed in the image: POINT_LEFT index toward -x, POINT_RIGHT +x, POINT_UP -y,
//   THUMB_UP thumb toward -y, THUMB_DOWN +y, for either handedness.
// Determinism
//   Everything is a pure function of its inputs and the generator's state; the random draws
//   use the raw mt19937 stream (not std distributions) so a seed gives the same hands on every
//   standard library.
#pragma once

#include <array>
#include <optional>
#include <random>
#include <string_view>

#include "gbdcs/contracts/messages.hpp"

namespace gbdcs::sim {

// Bones of an adult hand (mm): metacarpal layout plus phalanges, in the palm frame below.
inline constexpr double kHandLengthMm = 183.0;  // wrist to extended middle fingertip

struct FingerPose {
  double mcp_deg = 0;  // negative = hyperextension
  double pip_deg = 0;
  double dip_deg = 0;
};

struct ThumbPose {
  double cmc_abduction_deg = 35;  // away from the index metacarpal, in the palm plane
  double cmc_flexion_deg = 10;    // toward the palm (opposition)
  double mcp_deg = 5;
  double ip_deg = 5;
};

// The hand's attitude before the Placement adds its own. The palm frame (x toward the thumb
// for a right hand, y from the wrist toward the middle knuckle, z out of the palm) is first
// turned to face the camera with the fingers up, then by yaw (about the image vertical),
// pitch (about the image horizontal), roll (in-plane); a Left hand is mirrored here, about
// the image vertical; finally the whole hand is turned in-plane by aim_deg (0 = as is,
// 90 = what pointed up points right, -90 = left, 180 = down). Mirroring before the aim is
// what keeps a pointing hand pointing the same way whichever hand it is.
struct HandOrientation {
  double yaw_deg = 0;
  double pitch_deg = 0;
  double roll_deg = 0;
  double aim_deg = 0;
};

inline constexpr std::size_t kFingerCount = 4;  // index, middle, ring, pinky

struct HandPose {
  ThumbPose thumb;
  std::array<FingerPose, kFingerCount> fingers{};
  double spread_deg = 10;  // fan of the fingers: 0 together, ~20 wide open
  HandOrientation orientation;
};

struct Placement {
  double center_x = 0.5;  // palm centre, normalised image coordinates
  double center_y = 0.5;
  double size = 0.35;      // hand length / frame height
  double roll_deg = 0;     // in-plane, clockwise on the image
  double yaw_deg = 0;      // about the image vertical, |yaw| <= 40
  double pitch_deg = 0;    // about the image horizontal, |pitch| <= 40
  contracts::Handedness handedness = contracts::Handedness::kRight;
  double aspect_ratio = 4.0 / 3.0;  // frame width / height
  double presence = 0.95;           // copied to Landmarks::score
};

// The 21 landmarks of a right hand in the palm frame (mm, wrist at the origin), orientation
// not applied. For renderers that need the skeleton itself.
std::array<contracts::Point3, contracts::kLandmarkCount> hand_points_mm(const HandPose& pose);

// The same pose as the joint angles of an articulated hand (sim/models/hand.xml) built on the
// knuckle positions and bone lengths of hand_points_mm(): per finger the in-plane abduction
// (+ toward the thumb) then MCP/PIP/DIP flexion; the thumb's metacarpal turned in the palm
// plane by thumb_abduction_deg (+ toward the thumb side, from the palm's y axis), tilted
// toward the palm by thumb_flexion_deg, then twisted about itself by thumb_twist_deg (right-
// handed about the metacarpal) so that its MCP and IP joints bend in the plane they bend in
// hand_points_mm(). Degrees. Placing hinges this way reproduces hand_points_mm() exactly.
struct HandJointAngles {
  std::array<double, kFingerCount> finger_abduction_deg{};
  double thumb_abduction_deg = 0;
  double thumb_flexion_deg = 0;
  double thumb_twist_deg = 0;
};
HandJointAngles joint_angles(const HandPose& pose);

// Throws std::invalid_argument for a Placement outside its stated ranges (size <= 0,
// |yaw| or |pitch| > 40, aspect_ratio <= 0, presence outside [0, 1], non-finite values).
contracts::Landmarks synthesize(const HandPose& pose, const Placement& placement);

// Adds Gaussian jitter, like a landmark model's: sigma is a fraction of the hand length in
// the image, doubled for z (depth is the least certain coordinate).
void add_landmark_noise(contracts::Landmarks& hand, double sigma_fraction, double size,
                        std::mt19937& rng);

// Joint-wise interpolation, t in [0, 1] (clamped); aim and roll take the short way round.
HandPose blend(const HandPose& from, const HandPose& to, double t);

// ---- pose library -----------------------------------------------------------------------
enum class PoseName {
  kOpenPalm,
  kFist,
  kThumbUp,
  kThumbDown,
  kPointLeft,
  kPointRight,
  kPointUp,
  kVictory,
  kILoveYou,
  // non-deliberate: must be recognised as NONE
  kFourFingers,  // thumb folded across the palm, four fingers extended
  kCall,         // thumb + pinky
  kRock,         // index + pinky, thumb holding the others
  kOkSign,
  kPinch,
  kHalfClosed,
  kRelaxed,  // fingers slightly curled
};
inline constexpr std::array<PoseName, 16> kAllPoses = {
    PoseName::kOpenPalm,   PoseName::kFist,      PoseName::kThumbUp,  PoseName::kThumbDown,
    PoseName::kPointLeft,  PoseName::kPointRight, PoseName::kPointUp, PoseName::kVictory,
    PoseName::kILoveYou,   PoseName::kFourFingers, PoseName::kCall,   PoseName::kRock,
    PoseName::kOkSign,     PoseName::kPinch,     PoseName::kHalfClosed, PoseName::kRelaxed};

std::string_view to_string(PoseName p);  // "OPEN_PALM", "FOUR_FINGERS", "CALL", ...
std::optional<PoseName> pose_from_string(std::string_view s);
// The gesture a pose means; nullopt for the non-deliberate poses (they must read as NONE).
std::optional<contracts::GestureType> gesture_of(PoseName p);
// Whether the pose is defined by a direction in the image (POINT_*, THUMB_*).
bool is_direction_pose(PoseName p);

// A natural variant of the pose: a few degrees of joint noise, a slightly different attitude.
HandPose pose_for(PoseName name, std::mt19937& rng);

// Deterministic draws from the raw mt19937 stream (same on every standard library).
double uniform(std::mt19937& rng, double lo, double hi);
double gaussian(std::mt19937& rng, double sigma);  // clipped at 2.5 sigma

}  // namespace gbdcs::sim
