// The twin's Tello emulator facing a third-party client that sends nonsense: every bad
// command gets a Tello-style answer ("error …", "unknown command: …"), binary junk and
// oversized datagrams are ignored (as a Tello does), nothing crashes, and
// the emulator keeps answering good commands afterwards (docs/RELIABILITY.md, bad-input census).
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <string>

#include "contract_rigs.hpp"
#include "gbdcs/sim/tello_emulator.hpp"
#include "gbdcs/sim/twin_host.hpp"

namespace gbdcs::adapters::testing {
namespace {

class UdpClient {
 public:
  explicit UdpClient(std::uint16_t port) : fd_(::socket(AF_INET, SOCK_DGRAM, 0)) {
    to_.sin_family = AF_INET;
    to_.sin_port = htons(port);
    to_.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    timeval tv{5, 0};
    ::setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  }
  ~UdpClient() { ::close(fd_); }
  // Sends `text` and returns the reply ("" after 5 s without one).
  std::string ask(const std::string& text) {
    send(text);
    char buf[2048];
    const auto n = ::recv(fd_, buf, sizeof buf, 0);
    return n > 0 ? std::string(buf, static_cast<std::size_t>(n)) : std::string();
  }
  void send(const std::string& text) {
    ::sendto(fd_, text.data(), text.size(), 0, reinterpret_cast<const sockaddr*>(&to_), sizeof to_);
  }

 private:
  int fd_;
  sockaddr_in to_{};
};

TEST(TelloEmulatorInput, BadCommandsGetTelloAnswersAndGoodOnesStillWork) {
  contracts::ManualClock clock;
  sim::TwinHost host(clock, shared_model());
  // A socket of our own for the state stream (never read), so no fixed port is needed.
  const int state_fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in any{};
  any.sin_family = AF_INET;
  any.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(::bind(state_fd, reinterpret_cast<const sockaddr*>(&any), sizeof any), 0);
  socklen_t len = sizeof any;
  ASSERT_EQ(::getsockname(state_fd, reinterpret_cast<sockaddr*>(&any), &len), 0);
  sim::TelloEmulatorOptions options;
  options.command_port = 0;
  options.state_port = ntohs(any.sin_port);
  sim::TelloEmulator emulator(host, options);
  UdpClient client(emulator.port());
  ASSERT_EQ(client.ask("command"), "ok");
  EXPECT_EQ(client.ask("fly to the moon").rfind("unknown command", 0), 0u);
  EXPECT_EQ(client.ask("speed 5"), "error");
  EXPECT_EQ(client.ask("speed fast"), "error");
  EXPECT_EQ(client.ask("rc 999 0 0 0"), "error");
  EXPECT_EQ(client.ask("rc 1 2"), "error");
  EXPECT_EQ(client.ask("land").rfind("error", 0), 0u) << "not flying";
  // Binary junk and oversized datagrams are not commands: ignored without a reply, as a Tello.
  client.send(std::string("\x00\xff\xfe garbage", 11));
  client.send(std::string(1500, 'x'));
  // Still serving, and still correct.
  const auto battery = client.ask("battery?");
  ASSERT_FALSE(battery.empty());
  EXPECT_GT(std::stoi(battery), 0);
  EXPECT_EQ(client.ask("speed 50"), "ok");
  ::close(state_fd);
}

}  // namespace
}  // namespace gbdcs::adapters::testing
