#include "gbdcs/adapters/tello_video_source.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <charconv>
#include <chrono>
#include <condition_variable>
#include <cstring>
#include <mutex>
#include <optional>
#include <thread>

#include "gbdcs/adapters/tello_video_decoder.hpp"

namespace gbdcs::adapters {

using vision::CaptureError;
using WallClock = std::chrono::steady_clock;

namespace {

constexpr std::string_view kSpecHelp =
    "tello:[ADDRESS][?command_port=8889&video_port=11111&bind=0.0.0.0&streamon=1&timeout_s=5"
    "&stall_s=3]";

// A UDP socket that closes itself.
class UdpSocket {
 public:
  UdpSocket() : fd_(::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0)) {
    if (fd_ < 0) throw CaptureError(std::string("tello video: socket(): ") + std::strerror(errno));
  }
  ~UdpSocket() {
    if (fd_ >= 0) ::close(fd_);
  }
  UdpSocket(const UdpSocket&) = delete;
  UdpSocket& operator=(const UdpSocket&) = delete;
  int fd() const { return fd_; }

  std::uint16_t local_port() const {
    sockaddr_in a{};
    socklen_t n = sizeof a;
    ::getsockname(fd_, reinterpret_cast<sockaddr*>(&a), &n);
    return ntohs(a.sin_port);
  }
  // Waits up to timeout_ms for a datagram; its size, or -1 on timeout.
  long receive(std::uint8_t* buffer, std::size_t size, int timeout_ms) const {
    pollfd p{fd_, POLLIN, 0};
    if (::poll(&p, 1, timeout_ms) <= 0) return -1;
    const auto n = ::recv(fd_, buffer, size, 0);
    return n < 0 ? -1 : static_cast<long>(n);
  }

 private:
  int fd_;
};

sockaddr_in ipv4(const std::string& address, int port, const char* key) {
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<std::uint16_t>(port));
  if (::inet_pton(AF_INET, address.c_str(), &a.sin_addr) != 1) {
    throw CaptureError(std::string("tello video: '") + key + "' " + address +
                       " is not an IPv4 address (spec: " + std::string(kSpecHelp) + ")");
  }
  return a;
}

template <class T>
T parse_number(std::string_view key, std::string_view value, T low, T high) {
  T out{};
  const auto* end = value.data() + value.size();
  const auto [ptr, ec] = std::from_chars(value.data(), end, out);
  if (ec != std::errc() || ptr != end || out < low || out > high) {
    throw CaptureError("tello video: '" + std::string(key) + "=" + std::string(value) +
                       "' must be a number from " + std::to_string(low) + " to " +
                       std::to_string(high) + " (spec: " + std::string(kSpecHelp) + ")");
  }
  return out;
}

std::string trim_reply(std::string s) {
  while (!s.empty() && (s.back() == '\r' || s.back() == '\n' || s.back() == ' ' ||
                        s.back() == '\0')) {
    s.pop_back();
  }
  return s;
}

}  // namespace

TelloVideoOptions TelloVideoOptions::from_spec(std::string_view rest) {
  TelloVideoOptions o;
  const auto q = rest.find('?');
  const auto address = rest.substr(0, q);
  if (!address.empty()) o.address = std::string(address);
  ipv4(o.address, 1, "ADDRESS");  // validates
  if (q == std::string_view::npos) return o;
  auto query = rest.substr(q + 1);
  while (!query.empty()) {
    const auto amp = query.find('&');
    const auto pair = query.substr(0, amp);
    query = amp == std::string_view::npos ? std::string_view{} : query.substr(amp + 1);
    if (pair.empty()) continue;
    const auto eq = pair.find('=');
    if (eq == std::string_view::npos) {
      throw CaptureError("tello video: '" + std::string(pair) +
                         "' is not key=value (spec: " + std::string(kSpecHelp) + ")");
    }
    const auto key = pair.substr(0, eq), value = pair.substr(eq + 1);
    if (key == "command_port") {
      o.command_port = parse_number<int>(key, value, 1, 65535);
    } else if (key == "video_port") {
      o.video_port = parse_number<int>(key, value, 0, 65535);
    } else if (key == "bind") {
      o.bind_address = std::string(value);
      ipv4(o.bind_address, 0, "bind");
    } else if (key == "streamon") {
      o.send_streamon = parse_number<int>(key, value, 0, 1) == 1;
    } else if (key == "timeout_s") {
      o.first_frame_timeout_s = parse_number<double>(key, value, 0.1, 600.0);
    } else if (key == "stall_s") {
      o.stall_timeout_s = parse_number<double>(key, value, 0.1, 600.0);
    } else {
      throw CaptureError("tello video: unknown option '" + std::string(key) +
                         "' (spec: " + std::string(kSpecHelp) + ")");
    }
  }
  return o;
}

struct TelloVideoSource::Impl {
  Impl(TelloVideoOptions o, const contracts::Clock& c) : options(std::move(o)), clock(c) {
    const auto at = ipv4(options.bind_address, options.video_port, "bind");
    const int one = 1;
    ::setsockopt(video.fd(), SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    const int buffer = 4 << 20;  // a key frame arrives as a burst of datagrams
    ::setsockopt(video.fd(), SOL_SOCKET, SO_RCVBUF, &buffer, sizeof buffer);
    if (::bind(video.fd(), reinterpret_cast<const sockaddr*>(&at), sizeof at) != 0) {
      throw CaptureError("tello video: cannot bind UDP " + options.bind_address + ":" +
                         std::to_string(options.video_port) + ": " + std::strerror(errno) +
                         " (another Tello client or gbdcs holds the video port? stop it, or "
                         "set video_port in the spec)");
    }
    name = "tello:" + options.address + "?video_port=" + std::to_string(video.local_port());
    receiver = std::thread([this] { receive_loop(); });
    if (options.send_streamon) {
      try {
        command_socket.emplace();
        request("command");
        request("streamon");
        streaming = true;
      } catch (...) {
        stop_receiver();
        throw;
      }
    }
    opened_at = WallClock::now();
  }

  ~Impl() {
    stop_receiver();
    if (streaming) send("streamoff");  // best effort: the drone stops sending
  }

  void stop_receiver() {
    running = false;
    if (receiver.joinable()) receiver.join();
  }

  std::string where() const {
    return options.address + ":" + std::to_string(options.command_port);
  }

  void send(const std::string& text) {
    const auto to = ipv4(options.address, options.command_port, "ADDRESS");
    ::sendto(command_socket->fd(), text.data(), text.size(), 0,
             reinterpret_cast<const sockaddr*>(&to), sizeof to);
  }

  void request(const std::string& text) {
    std::array<std::uint8_t, 1024> buffer{};
    for (int attempt = 0; attempt < options.retries; ++attempt) {
      send(text);
      const auto n = command_socket->receive(buffer.data(), buffer.size(), options.reply_timeout_ms);
      if (n < 0) continue;
      const auto reply = trim_reply(std::string(reinterpret_cast<const char*>(buffer.data()),
                                                static_cast<std::size_t>(n)));
      if (reply == "ok") return;
      throw CaptureError("tello video: the Tello at " + where() + " answered '" + reply +
                         "' to '" + text + "' (restart the drone; SDK 1.3 firmware also "
                         "supports streamon, older firmware does not)");
    }
    throw CaptureError("tello video: no reply from the Tello at " + where() + " to '" + text +
                       "' (" + std::to_string(options.retries) + " tries, " +
                       std::to_string(options.reply_timeout_ms) +
                       " ms each): join the drone's Wi-Fi (TELLO-XXXXXX), check that it is on "
                       "and that ADDRESS and command_port in the spec are right (" +
                       std::string(kSpecHelp) + ")");
  }

  void receive_loop() {
    std::optional<TelloVideoDecoder> decoder;
    try {
      decoder.emplace();
    } catch (const std::exception& e) {
      std::lock_guard lock(mutex);
      fatal = e.what();
      cv.notify_all();
      return;
    }
    std::vector<std::uint8_t> buffer(65536);
    while (running) {
      const auto n = video.receive(buffer.data(), buffer.size(), 100);
      if (n < 0) continue;
      const auto started = WallClock::now();
      auto pictures = decoder->push({buffer.data(), static_cast<std::size_t>(n)});
      const double ms =
          std::chrono::duration<double, std::milli>(WallClock::now() - started).count();
      std::lock_guard lock(mutex);
      const auto& ds = decoder->stats();
      stats.datagrams = ds.datagrams;
      stats.bytes = ds.bytes;
      stats.undecodable = ds.undecodable + ds.oversized;
      last_decoder_error = ds.last_error;
      for (auto& p : pictures) {
        if (latest) ++stats.frames_skipped;
        ++stats.frames_decoded;
        decode_ms_sum += ms;
        stats.decode_ms_max = std::max(stats.decode_ms_max, ms);
        stats.width = p.cols;
        stats.height = p.rows;
        latest = std::move(p);
      }
      if (!pictures.empty()) {
        stats.decode_ms_mean = decode_ms_sum / static_cast<double>(stats.frames_decoded);
        cv.notify_all();
      }
    }
  }

  std::string no_frame_error(double waited_s) const {  // with `mutex` held
    const std::string port = std::to_string(video.local_port());
    if (stats.frames_returned > 0) {
      return "tello video: the stream stopped: no picture for " + std::to_string(waited_s).substr(0, 4) +
             " s on UDP " + port + " (out of Wi-Fi range, the drone's battery, or streamoff "
             "from another client?)";
    }
    if (stats.datagrams == 0) {
      return "tello video: no video datagram on UDP " + options.bind_address + ":" + port +
             " within " + std::to_string(waited_s).substr(0, 4) + " s" +
             (options.send_streamon ? " after streamon" : "") +
             ": let UDP " + port + " in through the firewall (e.g. `sudo ufw allow " + port +
             "/udp`), make sure this computer is on the drone's Wi-Fi (TELLO-XXXXXX) and that "
             "no other program reads port " + port +
             (options.send_streamon ? "" : "; with streamon=0 someone else must send streamon");
    }
    return "tello video: " + std::to_string(stats.datagrams) + " datagrams (" +
           std::to_string(stats.bytes) + " bytes) on UDP " + port +
           " but no picture decoded within " + std::to_string(waited_s).substr(0, 4) +
           " s: the stream is not H.264 or is corrupt (decoder: " +
           (last_decoder_error.empty() ? "waiting for a key frame" : last_decoder_error) +
           "); check that nothing else sends to port " + port;
  }

  TelloVideoOptions options;
  const contracts::Clock& clock;
  UdpSocket video;
  std::optional<UdpSocket> command_socket;
  std::string name;
  bool streaming = false;
  std::atomic<bool> running{true};
  std::thread receiver;
  WallClock::time_point opened_at;

  mutable std::mutex mutex;
  std::condition_variable cv;
  std::optional<cv::Mat> latest;
  std::string fatal;
  std::string last_decoder_error;
  double decode_ms_sum = 0;
  TelloVideoStats stats;
  std::int64_t next_id = 0;
};

TelloVideoSource::TelloVideoSource(TelloVideoOptions options, const contracts::Clock& clock)
    : impl_(std::make_unique<Impl>(std::move(options), clock)) {}

TelloVideoSource::~TelloVideoSource() = default;

std::optional<vision::Frame> TelloVideoSource::next() {
  auto& d = *impl_;
  std::unique_lock lock(d.mutex);
  const double limit_s =
      d.stats.frames_returned == 0 ? d.options.first_frame_timeout_s : d.options.stall_timeout_s;
  const auto since = WallClock::now();
  const bool got = d.cv.wait_for(lock, std::chrono::duration<double>(limit_s),
                                 [&] { return d.latest.has_value() || !d.fatal.empty(); });
  if (!d.fatal.empty()) throw CaptureError(d.fatal);
  if (!got) {
    const double waited = std::chrono::duration<double>(
                              WallClock::now() - (d.stats.frames_returned == 0 ? d.opened_at : since))
                              .count();
    throw CaptureError(d.no_frame_error(waited));
  }
  vision::Frame f;
  f.rgb = std::move(*d.latest);
  d.latest.reset();
  f.frame_id = d.next_id++;
  f.capture_time = d.clock.now();
  f.capture_utc = d.clock.utc_now();
  f.source = d.name;
  f.order = vision::PixelOrder::kBgr;
  ++d.stats.frames_returned;
  return f;
}

std::string TelloVideoSource::describe() const { return impl_->name; }

std::uint16_t TelloVideoSource::local_video_port() const { return impl_->video.local_port(); }

TelloVideoStats TelloVideoSource::stats() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->stats;
}

bool is_tello_video_spec(std::string_view spec) {
  return spec.substr(0, 6) == "tello:" || spec.substr(0, 12) == "tello-video:";
}

std::unique_ptr<vision::CaptureSource> open_tello_video(std::string_view spec,
                                                        const contracts::Clock& clock) {
  const auto colon = spec.find(':');
  if (!is_tello_video_spec(spec)) {
    throw CaptureError("tello video: '" + std::string(spec) + "' is not a tello: spec (" +
                       std::string(kSpecHelp) + ")");
  }
  return std::make_unique<TelloVideoSource>(TelloVideoOptions::from_spec(spec.substr(colon + 1)),
                                            clock);
}

}  // namespace gbdcs::adapters
