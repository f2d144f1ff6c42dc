// Shared by the TwinSim tests: one model for the process, a fixture that fails a test when
// any of its sims raised a MuJoCo warning, and stepping helpers (simulated time only).
#pragma once

#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "gbdcs/sim/twin_sim.hpp"

namespace gbdcs::sim {

inline std::shared_ptr<const TwinModel> shared_model() {
  static const auto model = std::make_shared<const TwinModel>();
  return model;
}

class TwinTest : public ::testing::Test {
 protected:
  void TearDown() override {
    for (const auto& sim : sims_) {
      std::string all;
      for (const auto& w : sim->mujoco_warnings()) all += w + "; ";
      EXPECT_TRUE(all.empty()) << "MuJoCo warnings: " << all;
    }
  }

  TwinSim& make_sim(TwinOptions options = {}, std::uint32_t seed = 1) {
    sims_.push_back(std::make_unique<TwinSim>(shared_model(), std::move(options), seed));
    return *sims_.back();
  }

  // Takes off and waits until it hovers at the take-off altitude (5 s is plenty).
  static void take_off(TwinSim& sim) {
    ASSERT_TRUE(sim.takeoff().ok);
    sim.step_to(sim.time_s() + 5.0);
    ASSERT_EQ(sim.mode(), TwinMode::kFlying);
  }

  // Steps one physics step at a time until `t_s`, calling check(status) after each.
  template <typename Check>
  static void each_step_until(TwinSim& sim, double t_s, Check check) {
    const double dt = sim.model()->opt.timestep;
    while (sim.time_s() + dt / 2 < t_s) {
      sim.step_to(sim.time_s() + dt);
      check(sim.status());
    }
  }

 private:
  std::vector<std::unique_ptr<TwinSim>> sims_;
};

}  // namespace gbdcs::sim
