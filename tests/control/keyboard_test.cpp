#include <gtest/gtest.h>

#include "gbdcs/control/keyboard_input.hpp"

namespace gbdcs::control {
namespace {

using contracts::CommandType;

TEST(Keyboard, MapsFlyingKeys) {
  KeyboardInput k;
  auto fwd = k.command_for("W");
  ASSERT_TRUE(fwd);
  EXPECT_EQ(fwd->type, CommandType::kMove);
  EXPECT_GT(fwd->payload->vx_m_s, 0);
  EXPECT_EQ(fwd->source, contracts::CommandSource::kKeyboard);
  EXPECT_LT(k.command_for("ArrowLeft")->payload->vy_m_s, 0);
  EXPECT_GT(k.command_for("e")->payload->yaw_rate_deg_s, 0);
  EXPECT_LT(k.command_for("f")->payload->vz_m_s, 0);
  EXPECT_EQ(k.command_for("t")->type, CommandType::kTakeoff);
  EXPECT_EQ(k.command_for("l")->type, CommandType::kLand);
  EXPECT_EQ(k.command_for(" ")->type, CommandType::kEmergencyStop);
  EXPECT_FALSE(k.command_for("z"));
  EXPECT_FALSE(k.command_for(""));
}

}  // namespace
}  // namespace gbdcs::control
