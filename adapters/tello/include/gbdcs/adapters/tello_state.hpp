// The Tello's state stream (UDP 8890): one text datagram of `key:value;` pairs, 10 per second.
//
// Input : a datagram, e.g. SDK 2.0 "mid:-1;x:0;y:0;z:0;mpry:0,0,0;pitch:0;roll:0;yaw:12;vgx:0;
//         vgy:0;vgz:0;templ:60;temph:63;tof:10;h:0;bat:87;baro:12.34;time:0;agx:0.00;agy:0.00;
//         agz:-998.00;\r\n" or the shorter SDK 1.3 set (no mid/x/y/z/mpry).
// Parse : generic pairs, no fixed pattern (the official text has typos and firmwares differ):
//         pieces split on ';', each `key:value` with a non-empty key of [A-Za-z0-9_] and a
//         printable value; trailing "\r\n" and empty pieces ignored; unknown keys kept.
//         Required for a usable state: h, bat, yaw (numbers). Anything else is malformed: the
//         caller drops the datagram and counts it.
// Units : pitch/roll/yaw deg (yaw clockwise seen from above, -180...180); vgx/vgy/vgz the
//         drone's speed units (dm/s on the firmwares we know: TelloOptions::velocity_unit_m_s),
//         vgz positive DOWN; templ/temph deg C; tof/h cm (h from the take-off point); bat %;
//         baro m; time s (motors on); agx/agy/agz 0.001 g.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <string_view>

namespace gbdcs::adapters {

// The raw pairs, or nullopt with `why` set.
std::optional<std::map<std::string, std::string>> parse_state_pairs(std::string_view datagram,
                                                                    std::string& why);

struct TelloState {
  double pitch_deg = 0, roll_deg = 0, yaw_deg = 0;
  double vgx = 0, vgy = 0, vgz = 0;  // raw speed units, vgz positive down
  double templ_c = 0, temph_c = 0;
  double tof_cm = 0, h_cm = 0;
  double bat_pct = 0;
  double baro_m = 0;
  double time_s = 0;
  double agx = 0, agy = 0, agz = 0;  // 0.001 g
  std::map<std::string, std::string> fields;  // every pair, as received
};

// Decodes the fields above (absent optional ones stay 0); nullopt with `why` for a malformed
// datagram or a missing/non-numeric required field.
std::optional<TelloState> decode_state(std::string_view datagram, std::string& why);

}  // namespace gbdcs::adapters
