// The msgpack-RPC stream from AirSim, as AirSimAdapter reads it: bytes fed to the reply
// unpacker in pieces (TCP splits frames anywhere), every message through decode_response and
// every result through decode_multirotor_state and describe.
//
// Input: byte 0 sets the piece size (1...256 bytes), the rest is the stream.
// Checks: the unpacker throws only std::exception (the adapter drops the connection); the
// decoders return a value or nullopt with a reason; a decoded state yields a finite yaw.
#include <algorithm>
#include <cmath>
#include <cstring>

#include "fuzz_harness.hpp"
#include "gbdcs/adapters/airsim_rpc.hpp"

namespace gbdcs::fuzz {
namespace {

constexpr std::string_view kName = "airsim_rpc";

void state_of(const msgpack::object& o) {
  std::string why;
  const auto s = adapters::airsim::decode_multirotor_state(o, why);
  if (!s) {
    require(!why.empty(), kName, "a state rejected without a reason");
    return;
  }
  const auto& q = s->orientation;
  if (std::isfinite(q.w) && std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z) &&
      std::abs(q.w) < 1e100 && std::abs(q.x) < 1e100 && std::abs(q.y) < 1e100 &&
      std::abs(q.z) < 1e100) {
    require(std::isfinite(adapters::airsim::yaw_deg_of(q)), kName, "yaw of a finite quaternion is not finite");
  }
}

void message(msgpack::object_handle&& handle) {
  (void)adapters::airsim::describe(handle.get());
  state_of(handle.get());  // a bare state map, for the decoder's sake
  std::string why;
  auto response = adapters::airsim::decode_response(std::move(handle), why);
  if (!response) {
    require(!why.empty(), kName, "a message rejected without a reason");
    return;
  }
  (void)adapters::airsim::describe(response->result.get());
  if (response->ok) state_of(response->result.get());
}

}  // namespace

void airsim_rpc(Bytes input) {
  if (input.empty()) return;
  const std::size_t piece = 1 + input[0];
  input = input.subspan(1);
  auto unpacker = adapters::airsim::make_reply_unpacker();
  try {
    while (!input.empty()) {
      const auto n = std::min(piece, input.size());
      unpacker->reserve_buffer(n);
      std::memcpy(unpacker->buffer(), input.data(), n);
      unpacker->buffer_consumed(n);
      input = input.subspan(n);
      msgpack::object_handle handle;
      while (unpacker->next(handle)) message(std::move(handle));
    }
  } catch (const std::exception&) {
    // Undecodable msgpack or a bound exceeded: the adapter drops the connection.
  }
}

}  // namespace gbdcs::fuzz

GBDCS_FUZZ_ENTRY(airsim_rpc)
