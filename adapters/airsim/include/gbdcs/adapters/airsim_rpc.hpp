// AirSim's wire format: msgpack-RPC over TCP (rpclib). Pure functions, no sockets.
//
// Request : [0, msgid, method, [params...]]      Response: [1, msgid, error, result]
//           (error nil on success; rpclib puts a string there otherwise)
// Structs : msgpack maps with AirSim's field names (MSGPACK_DEFINE_MAP in AirSim):
//           Vector3r {x_val, y_val, z_val}; Quaternionr {w_val, x_val, y_val, z_val};
//           YawMode {is_rate, yaw_or_rate}; KinematicsState {position, orientation,
//           linear_velocity, angular_velocity, linear_acceleration, angular_acceleration};
//           MultirotorState {collision, kinematics_estimated, gps_location, timestamp,
//           landed_state (0 landed, 1 flying), rc_data, ready, ready_message, can_arm}.
// Frames  : AirSim is NED (x north = forward at the start, y east = right, z down), yaw
//           clockwise seen from above.
#pragma once

#include <cstdint>
#include <memory>
#include <msgpack.hpp>
#include <optional>
#include <string>

namespace gbdcs::adapters::airsim {

struct Vector3 {
  double x = 0, y = 0, z = 0;
};
struct Quaternion {
  double w = 1, x = 0, y = 0, z = 0;
};

// The fields of a MultirotorState the adapter uses.
struct MultirotorState {
  Vector3 position_ned_m;
  Quaternion orientation;
  Vector3 velocity_ned_m_s;
  int landed_state = 0;  // 0 landed, 1 flying
  std::uint64_t timestamp_ns = 0;
  bool has_collided = false;
};

struct Response {
  std::uint32_t msgid = 0;
  bool ok = true;
  std::string error;             // when !ok: the server's error, as text
  msgpack::object_handle result;  // owns its zone
};

// [0, msgid, method, params] packed; `pack_params(packer)` writes the params array.
template <class PackParams>
std::string encode_request(std::uint32_t msgid, const std::string& method,
                           PackParams&& pack_params) {
  msgpack::sbuffer buffer;
  msgpack::packer<msgpack::sbuffer> p(buffer);
  p.pack_array(4);
  p.pack_uint8(0);
  p.pack_uint32(msgid);
  p.pack(method);
  pack_params(p);
  return std::string(buffer.data(), buffer.size());
}

// A YawMode map: {is_rate, yaw_or_rate}.
void pack_yaw_mode(msgpack::packer<msgpack::sbuffer>& p, bool is_rate, double yaw_or_rate);

// The unpacker for the server's byte stream: strings and binaries are copied out of its
// buffer, and one message is bounded (100000 array/map entries, 1 MiB strings, 4 MiB
// binaries, 64 levels deep); past a bound next() throws.
std::unique_ptr<msgpack::unpacker> make_reply_unpacker();

// A message from the server: a Response, or nullopt with `why` (not a response frame).
std::optional<Response> decode_response(msgpack::object_handle&& message, std::string& why);

// Reads a MultirotorState map; nullopt with `why` when a needed field is missing or mistyped.
std::optional<MultirotorState> decode_multirotor_state(const msgpack::object& o, std::string& why);

// Yaw (deg, clockwise from north, -180...180) of a NED attitude quaternion.
double yaw_deg_of(const Quaternion& q);

// The text of a msgpack value, for error messages ("nil", a string's content, ...).
std::string describe(const msgpack::object& o);

}  // namespace gbdcs::adapters::airsim
