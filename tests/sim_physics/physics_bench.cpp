// Prints the twin's physics speed without rendering: simulated seconds per wall second.
#include <cstdio>
#include <cstdlib>
#include <memory>

#include "gbdcs/sim/twin_sim.hpp"

int main(int argc, char** argv) {
  const double sim_seconds = argc > 1 ? std::atof(argv[1]) : 60.0;
  auto model = std::make_shared<const gbdcs::sim::TwinModel>();
  for (int run = 0; run < 3; ++run) {
    const double factor = gbdcs::sim::measure_physics_realtime_factor(model, sim_seconds);
    std::printf("{\"physics_realtime_factor\": %.1f, \"sim_seconds\": %.1f}\n", factor,
                sim_seconds);
  }
  return 0;
}
