// The Tello video stream: the encoder/decoder round trip, the twin's emulator streaming its
// camera over loopback to the adapter's video source, and the errors when there is no stream.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <thread>

#include "gbdcs/adapters/tello_adapter.hpp"
#include "gbdcs/adapters/tello_video_decoder.hpp"
#include "gbdcs/adapters/tello_video_source.hpp"
#include "gbdcs/contracts/clock.hpp"
#include "gbdcs/sim/h264_encoder.hpp"
#include "gbdcs/sim/tello_emulator.hpp"
#include "gbdcs/sim/tello_video_streamer.hpp"
#include "gbdcs/sim/twin_host.hpp"

namespace gbdcs {
namespace {

using adapters::TelloVideoDecoder;
using adapters::TelloVideoOptions;
using adapters::TelloVideoSource;

std::shared_ptr<const sim::TwinModel> shared_model() {
  static const auto model =
      std::make_shared<const sim::TwinModel>(GBDCS_SOURCE_DIR "/sim/models/quadrotor.xml");
  return model;
}

// A loopback UDP socket on an ephemeral port that nobody reads from (a silent "drone").
class SilentSocket {
 public:
  SilentSocket() : fd_(::socket(AF_INET, SOCK_DGRAM, 0)) {
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ::bind(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a);
  }
  ~SilentSocket() { ::close(fd_); }
  int port() const {
    sockaddr_in a{};
    socklen_t n = sizeof a;
    ::getsockname(fd_, reinterpret_cast<sockaddr*>(&a), &n);
    return ntohs(a.sin_port);
  }
  void send_to(int port, const std::vector<std::uint8_t>& bytes) const {
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    a.sin_port = htons(static_cast<std::uint16_t>(port));
    ::sendto(fd_, bytes.data(), bytes.size(), 0, reinterpret_cast<sockaddr*>(&a), sizeof a);
  }

 private:
  int fd_;
};

// A test picture: a gradient with a bright square at `step`'s position.
cv::Mat picture(int width, int height, int step) {
  cv::Mat bgr(height, width, CV_8UC3);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      bgr.at<cv::Vec3b>(y, x) = cv::Vec3b(static_cast<std::uint8_t>(x * 255 / width),
                                          static_cast<std::uint8_t>(y * 255 / height), 80);
    }
  }
  cv::rectangle(bgr, cv::Rect(10 + 6 * step, 20 + 3 * step, 40, 40), cv::Scalar(255, 255, 255),
                cv::FILLED);
  return bgr;
}

double mean_abs_diff(const cv::Mat& a, const cv::Mat& b) {
  cv::Mat d;
  cv::absdiff(a, b, d);
  const auto m = cv::mean(d);
  return (m[0] + m[1] + m[2]) / 3;
}

TEST(TelloVideoCodec, SplitDatagramsLikeATello) {
  std::vector<std::uint8_t> frame(1460 * 3 + 17, 7);
  auto parts = sim::split_datagrams(frame);
  ASSERT_EQ(parts.size(), 4u);
  for (std::size_t i = 0; i + 1 < parts.size(); ++i) EXPECT_EQ(parts[i].size(), 1460u);
  EXPECT_EQ(parts.back().size(), 17u);
  // An exact multiple of 1460 gets a shorter last datagram (one trailing zero byte).
  parts = sim::split_datagrams(std::vector<std::uint8_t>(2920, 1));
  ASSERT_EQ(parts.size(), 3u);
  EXPECT_EQ(parts.back(), std::vector<std::uint8_t>{0});
}

TEST(TelloVideoCodec, EncodedFramesDecodeBackToThePictures) {
  sim::H264EncoderOptions eo;
  eo.width = 320;
  eo.height = 240;
  eo.keyframe_interval = 5;
  sim::H264Encoder encoder(eo);
  TelloVideoDecoder decoder;
  std::vector<cv::Mat> decoded;
  for (int i = 0; i < 12; ++i) {
    const auto bytes = encoder.encode(picture(320, 240, i));
    ASSERT_FALSE(bytes.empty()) << "frame " << i;
    for (const auto& d : sim::split_datagrams(bytes)) {
      ASSERT_LE(d.size(), 1460u);
      for (auto& f : decoder.push(d)) decoded.push_back(f);
    }
    // No frame of delay: each frame decodes when its last datagram arrives.
    ASSERT_EQ(decoded.size(), static_cast<std::size_t>(i + 1)) << "frame " << i;
  }
  for (int i = 0; i < 12; ++i) {
    ASSERT_EQ(decoded[i].cols, 320);
    ASSERT_EQ(decoded[i].rows, 240);
    EXPECT_LT(mean_abs_diff(decoded[i], picture(320, 240, i)), 6.0) << "frame " << i;
  }
  EXPECT_GT(mean_abs_diff(decoded[0], decoded[11]), 1.0);  // the square moved
  EXPECT_EQ(decoder.stats().undecodable, 0u);
}

TEST(TelloVideoCodec, JoiningLateWaitsForTheNextKeyFrame) {
  sim::H264EncoderOptions eo;
  eo.width = 160;
  eo.height = 120;
  eo.keyframe_interval = 4;
  sim::H264Encoder encoder(eo);
  std::vector<std::vector<std::uint8_t>> frames;
  for (int i = 0; i < 9; ++i) frames.push_back(encoder.encode(picture(160, 120, i)));
  TelloVideoDecoder decoder;
  std::size_t pictures = 0;
  for (int i = 2; i < 9; ++i) {  // frames 2, 3 are P frames without their key frame
    for (const auto& d : sim::split_datagrams(frames[i])) pictures += decoder.push(d).size();
  }
  EXPECT_GE(pictures, 5u);  // frames 4...8 after the key frame at 4
  EXPECT_LE(pictures, 7u);
}

TEST(TelloVideoCodec, RandomAndTruncatedDatagramsNeverCrash) {
  std::mt19937 rng(42);
  TelloVideoDecoder decoder;
  std::uniform_int_distribution<int> len(0, 1460), byte(0, 255);
  for (int i = 0; i < 400; ++i) {
    std::vector<std::uint8_t> d(static_cast<std::size_t>(len(rng)));
    for (auto& b : d) b = static_cast<std::uint8_t>(byte(rng));
    if (i % 3 == 0 && d.size() > 4) d[0] = 0, d[1] = 0, d[2] = 0, d[3] = 1;  // start codes
    decoder.push(d);
  }
  // A real stream cut short in the middle still decodes its complete frames afterwards.
  sim::H264EncoderOptions eo;
  eo.width = 160;
  eo.height = 120;
  eo.keyframe_interval = 1;
  sim::H264Encoder encoder(eo);
  auto bytes = encoder.encode(picture(160, 120, 0));
  bytes.resize(bytes.size() / 2);
  decoder.push(bytes);
  std::size_t pictures = 0;
  for (int i = 1; i < 4; ++i) {
    for (const auto& d : sim::split_datagrams(encoder.encode(picture(160, 120, i)))) {
      pictures += decoder.push(d).size();
    }
  }
  EXPECT_GE(pictures, 2u);
  EXPECT_GT(decoder.stats().undecodable, 0u);
}

TEST(TelloVideoSpec, ParsesTheOptionsAndNamesBadOnes) {
  auto o = TelloVideoOptions::from_spec("10.0.0.7?video_port=0&streamon=0&timeout_s=2.5");
  EXPECT_EQ(o.address, "10.0.0.7");
  EXPECT_EQ(o.video_port, 0);
  EXPECT_FALSE(o.send_streamon);
  EXPECT_DOUBLE_EQ(o.first_frame_timeout_s, 2.5);
  EXPECT_EQ(TelloVideoOptions::from_spec("").address, "192.168.10.1");
  auto message = [](std::string_view spec) {
    try {
      TelloVideoOptions::from_spec(spec);
    } catch (const vision::CaptureError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message("?video_port=70000").find("video_port=70000"), std::string::npos);
  EXPECT_NE(message("?colour=1").find("unknown option 'colour'"), std::string::npos);
  EXPECT_NE(message("drone.local").find("not an IPv4 address"), std::string::npos);
  EXPECT_TRUE(adapters::is_tello_video_spec("tello-video:"));
  EXPECT_FALSE(adapters::is_tello_video_spec("telloX"));
}

TEST(TelloVideoSource, NoReplyToStreamonNamesTheWifiAndTheAddress) {
  contracts::SteadyClock clock;
  SilentSocket drone;  // bound, never answers
  TelloVideoOptions o;
  o.address = "127.0.0.1";
  o.command_port = drone.port();
  o.bind_address = "127.0.0.1";
  o.video_port = 0;
  o.reply_timeout_ms = 100;
  o.retries = 2;
  try {
    TelloVideoSource source(o, clock);
    FAIL() << "opened without a drone";
  } catch (const vision::CaptureError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("no reply from the Tello at 127.0.0.1:" + std::to_string(drone.port())),
              std::string::npos)
        << what;
    EXPECT_NE(what.find("Wi-Fi"), std::string::npos) << what;
  }
}

TEST(TelloVideoSource, NoStreamNamesThePortAndTheFirewall) {
  contracts::SteadyClock clock;
  TelloVideoOptions o;
  o.bind_address = "127.0.0.1";
  o.video_port = 0;
  o.send_streamon = false;
  o.first_frame_timeout_s = 0.3;
  TelloVideoSource source(o, clock);
  const auto port = std::to_string(source.local_video_port());
  try {
    source.next();
    FAIL() << "a frame without a stream";
  } catch (const vision::CaptureError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("no video datagram on UDP 127.0.0.1:" + port), std::string::npos) << what;
    EXPECT_NE(what.find("firewall"), std::string::npos) << what;
  }
}

TEST(TelloVideoSource, GarbageOnThePortIsReportedAsUndecodable) {
  contracts::SteadyClock clock;
  TelloVideoOptions o;
  o.bind_address = "127.0.0.1";
  o.video_port = 0;
  o.send_streamon = false;
  o.first_frame_timeout_s = 2;
  TelloVideoSource source(o, clock);
  SilentSocket sender;
  for (int i = 0; i < 5; ++i) sender.send_to(source.local_video_port(), {1, 2, 3, 4, 5});
  try {
    source.next();
    FAIL() << "a frame from garbage";
  } catch (const vision::CaptureError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("no picture decoded"), std::string::npos) << what;
  }
}

// The whole path: the adapter's video source sends command + streamon to the twin's Tello
// emulator, which renders its on-board camera, encodes it and streams it back over loopback.
TEST(TelloVideoLoopback, TheEmulatorStreamsTheTwinsCameraToTheSource) {
  contracts::ManualClock clock;
  sim::TwinHost host(clock, shared_model());
  sim::TelloEmulatorOptions eo;
  eo.command_port = 0;
  sim::TelloEmulator emulator(host, eo);
  SilentSocket parking;  // where datagrams go until the source's port is known
  emulator.set_state_port(parking.port());
  sim::TelloVideoStreamOptions so;
  so.width = 320;
  so.height = 240;
  so.client_port = parking.port();
  sim::TelloVideoStreamer streamer(host, so);
  streamer.attach(emulator);

  contracts::SteadyClock wall;
  TelloVideoOptions vo;
  vo.address = "127.0.0.1";
  vo.command_port = emulator.port();
  vo.bind_address = "127.0.0.1";
  vo.video_port = 0;
  vo.reply_timeout_ms = 3000;  // a loaded 2-core machine
  vo.first_frame_timeout_s = 60;
  vo.stall_timeout_s = 60;
  TelloVideoSource source(vo, wall);
  EXPECT_TRUE(streamer.streaming());
  streamer.set_client_port(source.local_video_port());

  auto first = source.next();
  ASSERT_TRUE(first);
  EXPECT_EQ(first->rgb.cols, 320);
  EXPECT_EQ(first->rgb.rows, 240);
  EXPECT_EQ(first->order, vision::PixelOrder::kBgr);
  const cv::Mat on_ground = first->rgb.clone();

  // Take off: the on-board camera climbs, so the picture changes.
  const auto r = host.with_sim([](sim::TwinSim& sim) { return sim.takeoff(); });
  ASSERT_TRUE(r.ok) << r.error;
  double change = 0;
  for (int i = 0; i < 60 && change < 3.0; ++i) {
    clock.advance(contracts::from_seconds(0.1));
    host.poll();
    auto f = source.next();
    ASSERT_TRUE(f);
    ASSERT_EQ(f->rgb.cols, 320);
    change = mean_abs_diff(on_ground, f->rgb);
  }
  EXPECT_GE(change, 3.0) << "the picture did not change while the twin took off";
  const auto st = streamer.stats();
  EXPECT_EQ(st.encoder, "libx264");
  EXPECT_GT(st.datagrams, st.frames);  // more than one datagram per frame at times
  const auto vs = source.stats();
  EXPECT_GE(vs.frames_decoded, 2u);
  EXPECT_EQ(vs.width, 320);

  // A link loss silences the video as it silences the state stream.
  emulator.set_link_lost(true);
  const auto suppressed = streamer.stats().suppressed;
  bool silenced = false;
  for (int i = 0; i < 600 && !silenced; ++i) {  // up to 60 s on a loaded machine
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    silenced = streamer.stats().suppressed >= suppressed + 2;
  }
  EXPECT_TRUE(silenced) << "frames kept going out during the link loss";
  const auto sent = streamer.stats().frames;
  emulator.set_link_lost(false);
  EXPECT_TRUE(source.next());  // may be the last picture from before the loss
  EXPECT_TRUE(source.next());
  EXPECT_GT(streamer.stats().frames, sent);
}

}  // namespace
}  // namespace gbdcs
