// `gbdcs bench server`: the real server (core/server) on a loopback port with N WebSocket
// clients; a publisher broadcasts telemetry at --rate-hz plus a gesture event every 10th
// tick through the same LiveHub the control loop uses. Each client measures delivery time
// (broadcast -> received, same process, same monotonic clock). Prints figures; --json one
// JSON document. Pass: delivery_ms_p99 <= 50 and rss_mb_max < 300 (clients included).
#include <algorithm>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <mutex>
#include <thread>
#include <utility>  // before Asio
#include <boost/asio.hpp>
#include <boost/beast.hpp>
#include <boost/beast/websocket.hpp>
#include <unistd.h>

#include "command_registry.hpp"
#include "commands.hpp"
#include "drone_factory.hpp"
#include "gbdcs/contracts/codec.hpp"
#include "gbdcs/server/server.hpp"

namespace gbdcs::app {
namespace {

namespace beast = boost::beast;
namespace websocket = beast::websocket;
namespace net = boost::asio;
using tcp = net::ip::tcp;
using nlohmann::json;
using Steady = std::chrono::steady_clock;

struct BenchServerOptions {
  int clients = 50;
  double rate_hz = 20;
  double duration_s = 10;
  bool json_out = false;
};

double rss_mb_max() {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;
  }
  return 0;
}

double pct(std::vector<double>& v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size())))];
}

int run_bench_server(const BenchServerOptions& o) {
  contracts::SteadyClock clock;
  const auto dir = std::filesystem::temp_directory_path() / ("gbdcs_bench_server_" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  int rc = 0;
  {
    storage::StorageManager storage({.path = (dir / "bench.db").string()}, clock);
    server::TokenService tokens(clock, server::TokenService::random_secret(), 1800);
    server::LiveHub hub(clock);
    server::DroneService drone(
        clock, storage, hub,
        [&clock](const std::string& name, const json& opts) { return make_drone(name, clock, opts); },
        control::GestureProfile::builtin_default(), nullptr);
    server::ServerOptions so;
    so.port = 0;
    so.threads = 2;
    so.web_dir = (dir / "none").string();
    server::Server http(clock, storage, tokens, drone, hub, so, nullptr);
    http.start();
    const auto port = http.port();
    const auto user = storage.create_user("bench@example.com", "x");
    const auto token = tokens.issue(*user, "bench@example.com").token;

    // Sequence number -> broadcast time.
    const auto ticks = static_cast<std::size_t>(o.duration_s * o.rate_hz);
    std::vector<std::atomic<std::int64_t>> sent_ns(ticks + 1);
    std::mutex results_mutex;
    std::vector<double> latencies;
    std::atomic<std::int64_t> received{0};
    std::atomic<int> connected{0};
    std::atomic<bool> done{false};
    std::vector<std::thread> clients;
    for (int c = 0; c < o.clients; ++c) {
      clients.emplace_back([&] {
        net::io_context ioc;
        websocket::stream<beast::tcp_stream> ws(ioc);
        beast::get_lowest_layer(ws).connect(tcp::endpoint(net::ip::make_address("127.0.0.1"), port));
        ws.handshake("127.0.0.1", "/ws/live?token=" + token);
        connected++;
        std::vector<double> mine;
        beast::flat_buffer buffer;
        while (!done) {
          beast::get_lowest_layer(ws).expires_after(std::chrono::seconds(2));
          beast::error_code ec;
          ws.read(buffer, ec);
          if (ec) break;
          const auto now = Steady::now().time_since_epoch().count();
          auto doc = json::parse(beast::buffers_to_string(buffer.data()));
          buffer.consume(buffer.size());
          std::int64_t seq = -1;
          if (doc["type"] == "telemetry") seq = static_cast<std::int64_t>(doc["data"]["x_m"].get<double>());
          if (doc["type"] == "gesture") seq = doc["data"]["frame_id"].get<std::int64_t>();
          if (seq < 0 || seq > static_cast<std::int64_t>(ticks)) continue;
          received++;
          mine.push_back(static_cast<double>(now - sent_ns[static_cast<std::size_t>(seq)].load()) / 1e6);
        }
        beast::error_code ignored;
        ws.close(websocket::close_code::normal, ignored);
        std::lock_guard lock(results_mutex);
        latencies.insert(latencies.end(), mine.begin(), mine.end());
      });
    }
    while (connected < o.clients) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    const auto period = std::chrono::duration<double>(1.0 / o.rate_hz);
    const auto start = Steady::now();
    std::int64_t sent = 0;
    for (std::size_t i = 0; i < ticks; ++i) {
      std::this_thread::sleep_until(start + std::chrono::duration_cast<Steady::duration>(period * static_cast<double>(i)));
      contracts::TelemetryFrame f;
      f.timestamp = clock.utc_now();
      f.x_m = static_cast<double>(i);
      f.flight_state = contracts::FlightState::kFlying;
      sent_ns[i] = Steady::now().time_since_epoch().count();
      hub.broadcast("telemetry", contracts::to_json(f));
      sent += o.clients;
      if (i % 10 == 0) {
        contracts::GestureEvent g;
        g.gesture = contracts::GestureType::kOpenPalm;
        g.confidence = 0.9;
        g.frame_id = static_cast<std::int64_t>(i);
        g.timestamp = clock.utc_now();
        hub.broadcast("gesture", contracts::to_json(g));
        sent += o.clients;
      }
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    done = true;
    for (auto& t : clients) t.join();
    http.stop();

    const double p50 = pct(latencies, 0.50), p95 = pct(latencies, 0.95), p99 = pct(latencies, 0.99);
    const double max = latencies.empty() ? 0 : latencies.back();
    const double rss = rss_mb_max();
    const bool pass = p99 <= 50 && rss < 300 && received > 0;
    const json doc = {{"clients", o.clients},          {"rate_hz", o.rate_hz},
                      {"duration_s", o.duration_s},    {"messages_sent", sent},
                      {"messages_received", received.load()},
                      {"messages_dropped", hub.dropped_total()},
                      {"delivery_ms_p50", p50},        {"delivery_ms_p95", p95},
                      {"delivery_ms_p99", p99},        {"delivery_ms_max", max},
                      {"rss_mb_max", rss},             {"delivery_ms_p99_limit", 50},
                      {"rss_mb_limit", 300},           {"pass", pass}};
    if (o.json_out) {
      std::cout << doc.dump(1) << "\n";
    } else {
      std::cout << "bench server: " << o.clients << " clients, " << o.rate_hz << " Hz telemetry + gestures for "
                << o.duration_s << " s\n  delivered " << received << " of " << sent << " messages\n  delivery p50 "
                << p50 << " ms, p95 " << p95 << " ms, p99 " << p99 << " ms (limit 50), max " << max
                << " ms\n  peak RSS " << rss << " MB (limit 300, clients included)\n"
                << (pass ? "PASS" : "FAIL") << "\n";
    }
    rc = pass ? 0 : 1;
  }
  std::error_code ec;
  std::filesystem::remove_all(dir, ec);
  return rc;
}

void add_bench_server(CLI::App& app) {
  static BenchServerOptions o;
  auto* cmd = group_command(app, "bench", "Benchmarks")
                  ->add_subcommand("server",
                                   "N WebSocket clients on the real server: telemetry at a rate plus gesture "
                                   "events; delivery latency percentiles and peak memory");
  cmd->add_option("--clients", o.clients, "WebSocket clients")->capture_default_str()->check(CLI::Range(1, 500));
  cmd->add_option("--rate-hz", o.rate_hz, "Telemetry rate")->capture_default_str()->check(CLI::Range(1.0, 200.0));
  cmd->add_option("--duration", o.duration_s, "Seconds")->capture_default_str()->check(CLI::Range(1.0, 600.0));
  cmd->add_flag("--json", o.json_out, "One JSON document");
  cmd->callback([] {
    try {
      g_exit_code = run_bench_server(o);
    } catch (const std::exception& e) {
      std::cerr << "gbdcs bench server: " << e.what() << "\n";
      g_exit_code = 2;
    }
  });
}

const CommandRegistration kBenchServer{60, &add_bench_server};

}  // namespace
}  // namespace gbdcs::app
