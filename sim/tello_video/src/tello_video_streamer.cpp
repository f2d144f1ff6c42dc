#include "gbdcs/sim/tello_video_streamer.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <condition_variable>
#include <cstring>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <thread>

#include "gbdcs/contracts/json_options.hpp"
#include "gbdcs/sim/h264_encoder.hpp"
#include "gbdcs/sim/renderer.hpp"

namespace gbdcs::sim {

using WallClock = std::chrono::steady_clock;

TelloVideoStreamOptions TelloVideoStreamOptions::from_json(const nlohmann::json& doc) {
  TelloVideoStreamOptions o;
  const std::string owner = "tello video options";
  if (doc.is_null()) return o;
  if (!doc.is_object()) throw std::invalid_argument(owner + ": must be a JSON object");
  nlohmann::json rest = doc;
  if (auto it = rest.find("camera"); it != rest.end()) {
    if (!it->is_string()) throw std::invalid_argument(owner + ": 'camera' must be a string");
    o.camera = it->get<std::string>();
    rest.erase("camera");
  }
  contracts::JsonOptionReader r(rest, owner);
  r.read("width", o.width);
  r.read("height", o.height);
  r.read("fps", o.fps);
  r.read("bitrate_kbps", o.bitrate_kbps);
  r.read("keyframe_interval", o.keyframe_interval);
  r.read("client_port", o.client_port);
  r.read("max_datagram", o.max_datagram);
  r.finish();
  contracts::require(o.width >= 16 && o.width <= 1920 && o.width % 2 == 0, owner, "width",
                     "must be even, within [16, 1920]");
  contracts::require(o.height >= 16 && o.height <= 1080 && o.height % 2 == 0, owner, "height",
                     "must be even, within [16, 1080]");
  contracts::require(o.fps > 0 && o.fps <= 60, owner, "fps", "must be within (0, 60]");
  contracts::require(o.bitrate_kbps >= 50, owner, "bitrate_kbps", "must be >= 50");
  contracts::require(o.keyframe_interval >= 1, owner, "keyframe_interval", "must be >= 1");
  contracts::require(o.client_port >= 1 && o.client_port <= 65535, owner, "client_port",
                     "must be within [1, 65535]");
  contracts::require(o.max_datagram >= 64 && o.max_datagram <= 65000, owner, "max_datagram",
                     "must be within [64, 65000]");
  return o;
}

struct TelloVideoStreamer::Impl {
  Impl(TwinHost& h, TelloVideoStreamOptions o) : host(h), options(std::move(o)) {
    fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    if (fd < 0) throw std::runtime_error(std::string("tello video: socket(): ") + std::strerror(errno));
    const int buffer = 1 << 20;
    ::setsockopt(fd, SOL_SOCKET, SO_SNDBUF, &buffer, sizeof buffer);
    worker = std::thread([this] { run(); });
  }

  ~Impl() {
    {
      std::lock_guard lock(mutex);
      quit = true;
      cv.notify_all();
    }
    if (worker.joinable()) worker.join();
    ::close(fd);
  }

  void run() {
    // The Renderer (an OSMesa context) and its state copy live and die on this thread.
    std::unique_ptr<Renderer> renderer;
    std::unique_ptr<H264Encoder> encoder;
    mjData* copy = nullptr;
    const mjModel* model = nullptr;
    const auto period = std::chrono::duration_cast<WallClock::duration>(
        std::chrono::duration<double>(1.0 / options.fps));
    auto due = WallClock::now();
    double render_ms_sum = 0, encode_ms_sum = 0;
    for (;;) {
      std::optional<sockaddr_in> to;
      {
        std::unique_lock lock(mutex);
        cv.wait_until(lock, due, [&] { return quit; });
        if (quit) break;
        if (!target) {
          cv.wait(lock, [&] { return quit || target.has_value(); });
          if (quit) break;
          due = WallClock::now();
        }
        to = target;
      }
      try {
        bool lost = false;
        host.with_sim([&](TwinSim& sim) {
          model = sim.model();
          if (!copy) copy = mj_makeData(model);
          mj_copyData(copy, model, sim.data());
          lost = sim.link_lost(sim.time_s());
        });
        if (const auto* e = emulator.load()) lost = lost || e->link_lost();
        if (!renderer) {
          RendererOptions ro;
          ro.width = options.width;
          ro.height = options.height;
          renderer = std::make_unique<Renderer>(model, ro);
          H264EncoderOptions eo;
          eo.width = options.width;
          eo.height = options.height;
          eo.fps = options.fps;
          eo.bitrate_kbps = options.bitrate_kbps;
          eo.keyframe_interval = options.keyframe_interval;
          encoder = std::make_unique<H264Encoder>(eo);
          std::lock_guard lock(mutex);
          stats.encoder = encoder->codec_name();
        }
        const auto t0 = WallClock::now();
        const cv::Mat bgr = renderer->render(copy, options.camera);
        const auto t1 = WallClock::now();
        const auto bytes = encoder->encode(bgr);
        const auto t2 = WallClock::now();
        render_ms_sum += std::chrono::duration<double, std::milli>(t1 - t0).count();
        encode_ms_sum += std::chrono::duration<double, std::milli>(t2 - t1).count();
        std::uint64_t sent = 0, sent_bytes = 0;
        if (!lost) {
          for (const auto& d : split_datagrams(bytes, static_cast<std::size_t>(options.max_datagram))) {
            if (::sendto(fd, d.data(), d.size(), 0, reinterpret_cast<const sockaddr*>(&*to),
                         sizeof *to) >= 0) {
              ++sent;
              sent_bytes += d.size();
            }
          }
        }
        std::lock_guard lock(mutex);
        ++frames_made;
        if (lost) ++stats.suppressed;
        else ++stats.frames;
        stats.datagrams += sent;
        stats.bytes += sent_bytes;
        stats.render_ms_mean = render_ms_sum / static_cast<double>(frames_made);
        stats.encode_ms_mean = encode_ms_sum / static_cast<double>(frames_made);
      } catch (const std::exception& e) {
        std::lock_guard lock(mutex);
        stats.last_error = e.what();
        target.reset();  // the stream stops; a new streamon tries again
        renderer.reset();
        encoder.reset();
        continue;
      }
      due += period;
      const auto now = WallClock::now();
      if (due < now) {  // behind: skip the frames that are already late
        std::lock_guard lock(mutex);
        while (due < now) {
          due += period;
          ++stats.late_frames;
        }
      }
    }
    renderer.reset();
    if (copy) mj_deleteData(copy);
  }

  TwinHost& host;
  TelloVideoStreamOptions options;
  int fd = -1;
  std::thread worker;
  std::atomic<const TelloEmulator*> emulator{nullptr};  // its set_link_lost() silences us

  mutable std::mutex mutex;
  std::condition_variable cv;
  bool quit = false;
  std::optional<sockaddr_in> target;
  std::uint64_t frames_made = 0;
  TelloVideoStreamStats stats;
};

TelloVideoStreamer::TelloVideoStreamer(TwinHost& host, TelloVideoStreamOptions options)
    : impl_(std::make_unique<Impl>(host, std::move(options))) {}

TelloVideoStreamer::~TelloVideoStreamer() = default;

void TelloVideoStreamer::attach(TelloEmulator& emulator) {
  impl_->emulator = &emulator;
  emulator.set_stream_handler([this](bool on, const std::string& client_address) {
    if (!on) return stop();
    try {
      start(client_address);
    } catch (const std::invalid_argument& e) {  // an IPv6 client: say so in stats()
      std::lock_guard lock(impl_->mutex);
      impl_->stats.last_error = e.what();
    }
  });
}

void TelloVideoStreamer::start(const std::string& client_address) {
  sockaddr_in a{};
  a.sin_family = AF_INET;
  if (::inet_pton(AF_INET, client_address.c_str(), &a.sin_addr) != 1) {
    throw std::invalid_argument("tello video: client address '" + client_address +
                                "' is not an IPv4 address");
  }
  std::lock_guard lock(impl_->mutex);
  a.sin_port = htons(static_cast<std::uint16_t>(impl_->options.client_port));
  impl_->target = a;
  impl_->cv.notify_all();
}

void TelloVideoStreamer::stop() {
  std::lock_guard lock(impl_->mutex);
  impl_->target.reset();
  impl_->cv.notify_all();
}

bool TelloVideoStreamer::streaming() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->target.has_value();
}

void TelloVideoStreamer::set_client_port(int port) {
  std::lock_guard lock(impl_->mutex);
  impl_->options.client_port = port;
  if (impl_->target) impl_->target->sin_port = htons(static_cast<std::uint16_t>(port));
}

TelloVideoStreamStats TelloVideoStreamer::stats() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->stats;
}

}  // namespace gbdcs::sim
