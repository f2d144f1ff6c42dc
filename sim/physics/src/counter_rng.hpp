// Counter-based random numbers: a value is a pure function of (seed, counter, channel), so the
// twin's noise does not depend on how often or in which order anyone asks for it.
#pragma once

#include <cmath>
#include <cstdint>
#include <numbers>

namespace gbdcs::sim::detail {

inline std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

// Uniform in [0, 1).
inline double counter_uniform(std::uint32_t seed, std::uint64_t counter, std::uint32_t channel) {
  const std::uint64_t key = splitmix64(seed ^ (static_cast<std::uint64_t>(channel) << 32));
  return static_cast<double>(splitmix64(key ^ splitmix64(counter)) >> 11) * 0x1.0p-53;
}

// Standard normal (Box-Muller on two channels).
inline double counter_gaussian(std::uint32_t seed, std::uint64_t counter, std::uint32_t channel) {
  const double u1 = 1.0 - counter_uniform(seed, counter, 2 * channel);  // (0, 1]
  const double u2 = counter_uniform(seed, counter, 2 * channel + 1);
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
}

}  // namespace gbdcs::sim::detail
