#include "gbdcs/adapters/airsim_rpc.hpp"

#include <cmath>
#include <numbers>
#include <sstream>

namespace gbdcs::adapters::airsim {
namespace {

const msgpack::object* field(const msgpack::object& map, const char* key) {
  if (map.type != msgpack::type::MAP) return nullptr;
  for (std::uint32_t i = 0; i < map.via.map.size; ++i) {
    const auto& kv = map.via.map.ptr[i];
    if (kv.key.type == msgpack::type::STR &&
        std::string_view(kv.key.via.str.ptr, kv.key.via.str.size) == key) {
      return &kv.val;
    }
  }
  return nullptr;
}

std::optional<double> number(const msgpack::object* o) {
  if (!o) return std::nullopt;
  switch (o->type) {
    case msgpack::type::FLOAT32:
    case msgpack::type::FLOAT64:
      return std::isfinite(o->via.f64) ? std::optional<double>(o->via.f64) : std::nullopt;
    case msgpack::type::POSITIVE_INTEGER:
      return static_cast<double>(o->via.u64);
    case msgpack::type::NEGATIVE_INTEGER:
      return static_cast<double>(o->via.i64);
    default:
      return std::nullopt;
  }
}

bool vector3(const msgpack::object* o, Vector3& out) {
  if (!o) return false;
  const auto x = number(field(*o, "x_val")), y = number(field(*o, "y_val")),
             z = number(field(*o, "z_val"));
  if (!x || !y || !z) return false;
  out = {*x, *y, *z};
  return true;
}

}  // namespace

void pack_yaw_mode(msgpack::packer<msgpack::sbuffer>& p, bool is_rate, double yaw_or_rate) {
  p.pack_map(2);
  p.pack(std::string("is_rate"));
  p.pack(is_rate);
  p.pack(std::string("yaw_or_rate"));
  p.pack_float(static_cast<float>(yaw_or_rate));
}

std::string describe(const msgpack::object& o) {
  if (o.type == msgpack::type::STR) return std::string(o.via.str.ptr, o.via.str.size);
  std::ostringstream out;
  out << o;
  return out.str().substr(0, 200);
}

std::unique_ptr<msgpack::unpacker> make_reply_unpacker() {
  return std::make_unique<msgpack::unpacker>(
      [](msgpack::type::object_type, std::size_t, void*) { return false; }, nullptr,
      MSGPACK_UNPACKER_INIT_BUFFER_SIZE,
      msgpack::unpack_limit(100000, 100000, 1 << 20, 1 << 22, 1 << 20, 64));
}

std::optional<Response> decode_response(msgpack::object_handle&& message, std::string& why) {
  const msgpack::object& o = message.get();
  if (o.type != msgpack::type::ARRAY || o.via.array.size != 4) {
    why = "not a 4-element array";
    return std::nullopt;
  }
  const auto* a = o.via.array.ptr;
  if (a[0].type != msgpack::type::POSITIVE_INTEGER || a[0].via.u64 != 1) {
    why = "type is not 1 (response)";
    return std::nullopt;
  }
  if (a[1].type != msgpack::type::POSITIVE_INTEGER || a[1].via.u64 > 0xffffffffu) {
    why = "msgid is not an unsigned 32-bit integer";
    return std::nullopt;
  }
  Response r;
  r.msgid = static_cast<std::uint32_t>(a[1].via.u64);
  r.ok = a[2].type == msgpack::type::NIL;
  if (!r.ok) r.error = describe(a[2]);
  // The result keeps pointing into the message's zone: hand the zone over with it.
  r.result = msgpack::object_handle(a[3], std::move(message.zone()));
  return r;
}

std::optional<MultirotorState> decode_multirotor_state(const msgpack::object& o, std::string& why) {
  if (o.type != msgpack::type::MAP) {
    why = "MultirotorState is not a map";
    return std::nullopt;
  }
  MultirotorState s;
  const auto* k = field(o, "kinematics_estimated");
  if (!k || k->type != msgpack::type::MAP) {
    why = "no kinematics_estimated map";
    return std::nullopt;
  }
  if (!vector3(field(*k, "position"), s.position_ned_m)) {
    why = "kinematics_estimated.position is not a Vector3r";
    return std::nullopt;
  }
  if (!vector3(field(*k, "linear_velocity"), s.velocity_ned_m_s)) {
    why = "kinematics_estimated.linear_velocity is not a Vector3r";
    return std::nullopt;
  }
  const auto* q = field(*k, "orientation");
  const auto w = q ? number(field(*q, "w_val")) : std::nullopt;
  const auto x = q ? number(field(*q, "x_val")) : std::nullopt;
  const auto y = q ? number(field(*q, "y_val")) : std::nullopt;
  const auto z = q ? number(field(*q, "z_val")) : std::nullopt;
  if (!w || !x || !y || !z) {
    why = "kinematics_estimated.orientation is not a Quaternionr";
    return std::nullopt;
  }
  s.orientation = {*w, *x, *y, *z};
  const auto landed = number(field(o, "landed_state"));
  if (!landed || (*landed != 0 && *landed != 1)) {
    why = "landed_state is not 0 or 1";
    return std::nullopt;
  }
  s.landed_state = static_cast<int>(*landed);
  if (const auto t = number(field(o, "timestamp")); t && *t >= 0) {
    s.timestamp_ns = static_cast<std::uint64_t>(*t);
  }
  if (const auto* c = field(o, "collision"); c) {
    if (const auto* h = field(*c, "has_collided"); h && h->type == msgpack::type::BOOLEAN) {
      s.has_collided = h->via.boolean;
    }
  }
  return s;
}

double yaw_deg_of(const Quaternion& q) {
  const double siny = 2.0 * (q.w * q.z + q.x * q.y);
  const double cosy = 1.0 - 2.0 * (q.y * q.y + q.z * q.z);
  return std::atan2(siny, cosy) * 180.0 / std::numbers::pi;
}

}  // namespace gbdcs::adapters::airsim
