#include <gtest/gtest.h>

#include "gbdcs/control/command_arbiter.hpp"

namespace gbdcs::control {
namespace {

using contracts::CommandSource;
using contracts::CommandType;
using contracts::DroneCommand;
using contracts::FlightState;

DroneCommand cmd(CommandType type, CommandSource source = CommandSource::kGesture) {
  DroneCommand c;
  c.type = type;
  c.source = source;
  if (type == CommandType::kMove) c.payload = contracts::MotionPayload{0.5, 0, 0, 0, 1};
  return c;
}

class ArbiterTest : public ::testing::Test {
 protected:
  void ready() {
    arbiter.set_vision_healthy(true);
    arbiter.set_adapter_state(FlightState::kReady);
  }
  contracts::ManualClock clock;
  CommandArbiter arbiter{clock};
};

TEST_F(ArbiterTest, TakeoffRefusedUntilVisionHealthyAndReady) {
  auto d = arbiter.submit(cmd(CommandType::kTakeoff));
  EXPECT_FALSE(d.accepted);
  EXPECT_NE(d.reason.find("vision is not ready"), std::string::npos) << d.reason;

  arbiter.set_vision_healthy(true);
  d = arbiter.submit(cmd(CommandType::kTakeoff));
  EXPECT_FALSE(d.accepted);
  EXPECT_NE(d.reason.find("INIT, not READY"), std::string::npos) << d.reason;

  arbiter.set_adapter_state(FlightState::kReady);
  EXPECT_TRUE(arbiter.submit(cmd(CommandType::kTakeoff)).accepted);
  EXPECT_EQ(arbiter.next()->type, CommandType::kTakeoff);
}

TEST_F(ArbiterTest, TakeoffRecheckedAtDispatch) {
  ready();
  std::vector<std::string> refusals;
  arbiter.set_refusal_handler(
      [&](const DroneCommand&, const std::string& why) { refusals.push_back(why); });
  ASSERT_TRUE(arbiter.submit(cmd(CommandType::kTakeoff)).accepted);
  arbiter.set_vision_healthy(false);  // vision dies before the take-off goes out
  EXPECT_FALSE(arbiter.next().has_value());
  ASSERT_EQ(refusals.size(), 1u);
  EXPECT_NE(refusals[0].find("vision"), std::string::npos);
}

TEST_F(ArbiterTest, TakeoffInhibitBlocks) {
  ready();
  arbiter.set_takeoff_inhibit("battery critical");
  auto d = arbiter.submit(cmd(CommandType::kTakeoff));
  EXPECT_FALSE(d.accepted);
  EXPECT_NE(d.reason.find("battery critical"), std::string::npos);
  arbiter.clear_takeoff_inhibit("battery critical");
  EXPECT_TRUE(arbiter.submit(cmd(CommandType::kTakeoff)).accepted);
}

TEST_F(ArbiterTest, EmergencyStopPreemptsPendingMove) {
  ready();
  std::vector<DroneCommand> dropped;
  arbiter.set_refusal_handler([&](const DroneCommand& c, const std::string&) { dropped.push_back(c); });
  ASSERT_TRUE(arbiter.submit(cmd(CommandType::kMove)).accepted);
  ASSERT_TRUE(arbiter.submit(cmd(CommandType::kMove, CommandSource::kKeyboard)).accepted);
  auto d = arbiter.submit(cmd(CommandType::kEmergencyStop, CommandSource::kApi));
  EXPECT_TRUE(d.accepted);
  EXPECT_EQ(d.dropped, 2u);
  EXPECT_EQ(dropped.size(), 2u);
  auto next = arbiter.next();
  ASSERT_TRUE(next);
  EXPECT_EQ(next->type, CommandType::kEmergencyStop);
  EXPECT_FALSE(arbiter.next());
}

TEST_F(ArbiterTest, EmergencyLatchesUntilReset) {
  ready();
  arbiter.submit(cmd(CommandType::kEmergencyStop, CommandSource::kApi));
  arbiter.next();
  auto d = arbiter.submit(cmd(CommandType::kTakeoff));
  EXPECT_FALSE(d.accepted);
  EXPECT_NE(d.reason.find("latched"), std::string::npos);
  EXPECT_FALSE(arbiter.submit(cmd(CommandType::kHover, CommandSource::kFailsafe)).accepted);
  EXPECT_TRUE(arbiter.submit(cmd(CommandType::kEmergencyStop)).accepted);  // still allowed
  arbiter.reset_emergency();
  EXPECT_TRUE(arbiter.submit(cmd(CommandType::kTakeoff)).accepted);
}

TEST_F(ArbiterTest, FailsafeBeatsOperatorAndDropsIt) {
  ready();
  arbiter.submit(cmd(CommandType::kMove));
  auto d = arbiter.submit(cmd(CommandType::kHover, CommandSource::kFailsafe));
  EXPECT_EQ(d.dropped, 1u);
  // An operator command after the failsafe queues behind it.
  arbiter.submit(cmd(CommandType::kMove, CommandSource::kKeyboard));
  EXPECT_EQ(arbiter.next()->source, CommandSource::kFailsafe);
  EXPECT_EQ(arbiter.next()->source, CommandSource::kKeyboard);
}

TEST_F(ArbiterTest, PriorityOrderFifoWithin) {
  ready();
  auto a = arbiter.submit(cmd(CommandType::kMove)).command.id;
  auto b = arbiter.submit(cmd(CommandType::kHover)).command.id;
  EXPECT_LT(a, b);
  EXPECT_EQ(arbiter.next()->id, a);
  EXPECT_EQ(arbiter.next()->id, b);
}

TEST_F(ArbiterTest, MoveWithoutPayloadRefused) {
  DroneCommand c;
  c.type = CommandType::kMove;
  EXPECT_FALSE(arbiter.submit(c).accepted);
}

TEST_F(ArbiterTest, FullQueueDropsOldestOperatorCommand) {
  CommandArbiter small(clock, ArbiterOptions{2});
  small.submit(cmd(CommandType::kHover));
  small.submit(cmd(CommandType::kMove));
  auto third = small.submit(cmd(CommandType::kLand));
  EXPECT_TRUE(third.accepted);
  EXPECT_EQ(small.pending(), 2u);
  EXPECT_EQ(small.next()->type, CommandType::kMove);
}

TEST_F(ArbiterTest, FillsIdAndTimestamp) {
  clock.advance(contracts::from_seconds(2));
  auto d = arbiter.submit(cmd(CommandType::kHover));
  EXPECT_GT(d.command.id, 0);
  EXPECT_EQ(d.command.issued_at, clock.utc_now());
}

}  // namespace
}  // namespace gbdcs::control
