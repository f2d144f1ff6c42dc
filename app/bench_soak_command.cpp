// `gbdcs bench soak`: a long run of `gbdcs serve` as operators run it (a child process: the
// drone, default the twin; the supervised vision worker on a camera, default the rendered
// demo-flight recipe; SQLite in a temp folder) with N dashboard-like /ws/live clients
// (app/soak_support.hpp) that renew their tokens as a dashboard that stays open does.
// Every --kill-worker-every seconds the vision worker is killed with SIGKILL, so the server
// must hover, raise VISION_WORKER_LOST and restart it: alerts to deliver, under load.
//
// Measured over the window (after --warmup):
//   rss_mb_start/max/end/growth of the server process (VmRSS sampled every --sample-every s;
//   start and end are the lowest sample of the window's first and last quarter, so growth
//   is the rise of the floor, not a transient peak caught at one end),
//   worker_rss_mb_max; alerts_sent (the server's own `alert` log lines in the window),
//   alerts_received / alerts_expected (sent x clients) / alerts_dropped; delivery_ms_p50/p99
//   (telemetry: envelope stamp -> client), frame_age_ms_p99 (capture -> client),
//   command_age_ms_p99 (issued -> client), rest_ms_p99 (healthz + sessions list), the hub's
//   ws_dropped (frames and telemetry shed for slow clients), load averages.
// Pass (exit 0): alerts_dropped == 0, alerts_sent > 0 when workers are killed,
//   rss_mb_growth <= --rss-growth-limit-mb, no unexpected client disconnects, the server ran
//   the whole window and stopped cleanly, and the database passes quick_check afterwards.
//   Latencies are reported, not judged (docs/PERFORMANCE.md holds the targets).
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <sstream>

#include "command_registry.hpp"
#include "commands.hpp"
#include "gbdcs/contracts/clock.hpp"
#include "gbdcs/storage/storage_manager.hpp"
#include "soak_support.hpp"

namespace gbdcs::app {
namespace {

using nlohmann::json;
using Steady = std::chrono::steady_clock;

struct SoakOptions {
  std::string duration = "30m";
  int clients = 20;
  std::string source = "recipe:fixtures/recipes/demo_flight.json?live=1&fps=30";
  std::string adapter = "twin";
  double kill_worker_every_s = 300;
  double warmup_s = 30;
  double sample_every_s = 5;
  double rss_growth_limit_mb = 64;
  double drain_timeout_s = 120;
  int token_ttl_s = 1800;
  std::string keep_dir;
  bool json_out = false;
};

double parse_duration_s(const std::string& text) {
  std::size_t used = 0;
  double value = 0;
  try {
    value = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  const std::string unit = text.substr(used);
  double scale = 0;
  if (unit.empty() || unit == "s") scale = 1;
  if (unit == "m" || unit == "min") scale = 60;
  if (unit == "h") scale = 3600;
  if (used == 0 || scale == 0 || value <= 0) {
    throw std::runtime_error("--duration '" + text + "': use seconds or a unit, e.g. 90, 90s, 30m, 1h");
  }
  return value * scale;
}

std::array<double, 3> load_average() {
  std::ifstream in("/proc/loadavg");
  std::array<double, 3> l{};
  in >> l[0] >> l[1] >> l[2];
  return l;
}

double metric_value(const std::string& text, const std::string& name) {
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind(name + " ", 0) == 0) return std::stod(line.substr(name.size() + 1));
  }
  return -1;
}

int run_soak(const SoakOptions& o) {
  const double duration_s = parse_duration_s(o.duration);
  const auto dir = o.keep_dir.empty()
                       ? std::filesystem::temp_directory_path() / ("gbdcs_soak_" + std::to_string(::getpid()))
                       : std::filesystem::path(o.keep_dir);
  std::filesystem::create_directories(dir);
  const auto db = (dir / "soak.db").string();

  // The server's own record of every alert it raised: (log time, alert as broadcast).
  std::mutex alerts_mutex;
  std::vector<std::pair<std::int64_t, std::string>> logged_alerts;
  std::atomic<std::int64_t> log_errors{0};
  auto on_line = [&](const std::string& line) {
    const json doc = json::parse(line, nullptr, false);
    if (doc.is_discarded() || !doc.is_object()) return;
    if (doc.value("level", "") == "error") ++log_errors;
    if (doc.value("event", "") == "alert" && doc.contains("alert")) {
      std::lock_guard lock(alerts_mutex);
      logged_alerts.emplace_back(soak::utc_ms(doc.value("ts", "")), doc["alert"].dump());
    }
  };
  soak::ServeChild serve({"--port", "0", "--db", db, "--adapter", o.adapter, "--source", o.source,
                          "--web", (dir / "no-dashboard").string(), "--log-json"},
                         // No GBDCS_JWT_SECRET: the server makes a random one for this run.
                         {{"GBDCS_TOKEN_TTL_S", std::to_string(o.token_ttl_s)}},
                         on_line);
  if (serve.port() == 0) {
    std::string tail;
    for (const auto& l : serve.tail()) tail += "  " + l;
    throw std::runtime_error("gbdcs serve did not start:\n" + tail);
  }
  const auto port = serve.port();
  const std::string email = "soak@example.com", password = "correct horse battery staple";
  const auto reg = soak::http_call(port, "POST", "/api/v1/auth/register",
                                   json{{"email", email}, {"password", password}}.dump());
  if (reg.status != 201) throw std::runtime_error("register: HTTP " + std::to_string(reg.status) + " " + reg.body);

  std::atomic<bool> stop_clients{false};
  std::vector<std::unique_ptr<soak::SoakClient>> clients;
  // Declared after the clients, so it runs first: on any early return they stop, then join.
  struct StopOnExit {
    std::atomic<bool>& flag;
    ~StopOnExit() { flag = true; }
  } stop_guard{stop_clients};
  for (int i = 0; i < o.clients; ++i) {
    const double renew = 0.6 + 0.3 * static_cast<double>(i) / std::max(1, o.clients - 1);
    clients.push_back(std::make_unique<soak::SoakClient>(port, email, password, renew, stop_clients));
  }
  int connected = 0;
  for (auto& c : clients) connected += c->wait_connected(std::chrono::seconds(120)) ? 1 : 0;
  if (connected != o.clients) {
    stop_clients = true;
    throw std::runtime_error(std::to_string(connected) + " of " + std::to_string(o.clients) +
                             " clients connected");
  }
  const auto probe_login = [&] {
    const auto r = soak::http_call(port, "POST", "/api/v1/auth/login",
                                   json{{"email", email}, {"password", password}}.dump());
    return r.status == 200 ? json::parse(r.body).value("token", "") : std::string();
  };
  std::string probe_token = probe_login();
  auto probe_token_at = Steady::now();

  // Warm-up: the twin takes off, the worker reaches its pace, caches fill.
  std::this_thread::sleep_for(std::chrono::duration<double>(std::max(2.0, o.warmup_s)));
  const auto window_start = Steady::now();
  const std::int64_t t0_ms = soak::now_utc_ms();
  const auto load_start = load_average();
  // (seconds into the window, server VmRSS MB): growth compares the floors of the first and
  // the last quarter, so a transient peak (a login's password hash takes tens of MB for a
  // moment) sampled at either end is not counted as growth; a leak raises the floor.
  std::vector<std::pair<double, double>> rss_samples = {{0.0, soak::rss_mb(serve.pid())}};
  double rss_max = rss_samples.front().second, worker_rss_max = 0;
  double load_sum = 0;
  int load_samples = 0;
  std::vector<double> rest_ms;
  std::int64_t rest_failures = 0, worker_kills = 0;
  auto next_kill = window_start + std::chrono::duration_cast<Steady::duration>(
                                      std::chrono::duration<double>(o.kill_worker_every_s / 2));
  const auto end = window_start + std::chrono::duration_cast<Steady::duration>(
                                      std::chrono::duration<double>(duration_s));
  bool server_alive = true;
  for (auto next_sample = window_start; Steady::now() < end;) {
    std::this_thread::sleep_until(std::min(next_sample, end));
    if (!serve.alive()) {
      server_alive = false;
      break;
    }
    next_sample += std::chrono::duration_cast<Steady::duration>(std::chrono::duration<double>(o.sample_every_s));
    const double rss = soak::rss_mb(serve.pid());
    rss_max = std::max(rss_max, rss);
    rss_samples.emplace_back(std::chrono::duration<double>(Steady::now() - window_start).count(), rss);
    for (auto w : soak::children_of(serve.pid())) worker_rss_max = std::max(worker_rss_max, soak::rss_mb(w));
    load_sum += load_average()[0];
    ++load_samples;
    // What the dashboard asks over REST, timed.
    if (Steady::now() - probe_token_at > std::chrono::seconds(o.token_ttl_s / 2)) {
      probe_token = probe_login();
      probe_token_at = Steady::now();
    }
    const std::vector<std::pair<std::string, std::string>> probes = {
        {"/api/v1/healthz", ""}, {"/api/v1/sessions?limit=20", probe_token}};
    for (const auto& [target, token] : probes) {
      const auto r = soak::http_call(port, "GET", target, {}, token);
      if (r.status == 200) rest_ms.push_back(r.elapsed_ms);
      else ++rest_failures;
    }
    if (o.kill_worker_every_s > 0 && Steady::now() >= next_kill) {
      for (auto w : soak::children_of(serve.pid())) {
        if (::kill(w, SIGKILL) == 0) ++worker_kills;
      }
      next_kill += std::chrono::duration_cast<Steady::duration>(std::chrono::duration<double>(o.kill_worker_every_s));
    }
  }
  const std::int64_t t1_ms = soak::now_utc_ms();
  const double window_s = std::chrono::duration<double>(Steady::now() - window_start).count();
  // The alerts of the window, as the server logged them (the log line follows the broadcast).
  std::this_thread::sleep_for(std::chrono::seconds(1));
  std::set<std::string> sent;
  {
    std::lock_guard lock(alerts_mutex);
    for (const auto& [ts, alert] : logged_alerts) {
      if (ts >= t0_ms && ts <= t1_ms) sent.insert(alert);
    }
  }
  // A slow client is sent its alerts late, never not at all: wait until every client has every
  // one (or --drain-timeout passes; what is still missing then counts as dropped).
  const auto drain_start = Steady::now();
  const auto drain_until = drain_start + std::chrono::duration_cast<Steady::duration>(
                                             std::chrono::duration<double>(o.drain_timeout_s));
  for (;;) {
    std::size_t missing = 0;
    for (auto& c : clients) missing += c->missing(sent);
    if (missing == 0 || Steady::now() >= drain_until) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(250));
  }
  const double drain_s = std::chrono::duration<double>(Steady::now() - drain_start).count();
  const auto metrics = soak::http_call(port, "GET", "/api/v1/metrics", {}, probe_token);
  const auto health = soak::http_call(port, "GET", "/api/v1/healthz");
  const auto load_end = load_average();
  stop_clients = true;
  std::int64_t received = 0, dropped = 0, unexpected_closes = 0, renewals = 0, messages = 0;
  std::vector<double> delivery, frame_age, command_age, alert_age;
  std::string client_error;
  for (auto& c : clients) {
    auto r = c->report();
    for (const auto& a : sent) {
      if (r.alerts.count(a)) ++received;
      else ++dropped;
    }
    unexpected_closes += r.unexpected_closes;
    renewals += r.renewals;
    for (const auto& [type, n] : r.messages) messages += n;
    delivery.insert(delivery.end(), r.delivery_ms.begin(), r.delivery_ms.end());
    frame_age.insert(frame_age.end(), r.frame_age_ms.begin(), r.frame_age_ms.end());
    command_age.insert(command_age.end(), r.command_age_ms.begin(), r.command_age_ms.end());
    alert_age.insert(alert_age.end(), r.alert_age_ms.begin(), r.alert_age_ms.end());
    if (r.unexpected_closes > 0 && client_error.empty()) client_error = r.last_error;
  }
  clients.clear();
  const int exit_status = serve.stop();
  bool quick_check_ok = true;
  std::string quick_check_error;
  try {
    contracts::SteadyClock clock;
    storage::StorageManager reopened({.path = db, .read_only = true}, clock);  // runs quick_check
  } catch (const std::exception& e) {
    quick_check_ok = false;
    quick_check_error = e.what();
  }
  const auto floor_between = [&](double from_s, double to_s) {
    double lowest = std::numeric_limits<double>::infinity();
    for (const auto& [at_s, mb] : rss_samples) {
      if (at_s >= from_s && at_s <= to_s) lowest = std::min(lowest, mb);
    }
    return lowest;
  };
  const double rss_start = floor_between(0, window_s / 4);
  const double rss_end = std::min(floor_between(window_s * 3 / 4, window_s), rss_samples.back().second);
  const double growth = rss_end - rss_start;
  const bool pass = server_alive && exit_status == 0 && dropped == 0 &&
                    (o.kill_worker_every_s <= 0 || !sent.empty()) &&
                    growth <= o.rss_growth_limit_mb && unexpected_closes == 0 && quick_check_ok;
  json doc = {{"duration_s", window_s},
              {"clients", o.clients},
              {"adapter", o.adapter},
              {"source", o.source},
              {"token_ttl_s", o.token_ttl_s},
              {"rss_mb_start", rss_start},
              {"rss_mb_max", rss_max},
              {"rss_mb_end", rss_end},
              {"rss_mb_growth", growth},
              {"rss_mb_growth_limit", o.rss_growth_limit_mb},
              {"worker_rss_mb_max", worker_rss_max},
              {"worker_kills", worker_kills},
              {"alerts_sent", sent.size()},
              {"alerts_expected", static_cast<std::int64_t>(sent.size()) * o.clients},
              {"alerts_received", received},
              {"alerts_dropped", dropped},
              {"alert_age_ms_p99", soak::percentile(alert_age, 0.99)},
              {"alert_age_ms_max", alert_age.empty() ? 0.0 : *std::max_element(alert_age.begin(), alert_age.end())},
              {"alerts_drain_s", drain_s},
              {"messages_received", messages},
              {"ws_dropped", metric_value(metrics.body, "gbdcs_ws_dropped_total")},
              {"ws_broadcasts", metric_value(metrics.body, "gbdcs_ws_broadcasts_total")},
              {"vision_frames", metric_value(metrics.body, "gbdcs_vision_frames_total")},
              {"storage_write_failures", metric_value(metrics.body, "gbdcs_storage_write_failures")},
              {"delivery_ms_p50", soak::percentile(delivery, 0.5)},
              {"delivery_ms_p99", soak::percentile(delivery, 0.99)},
              {"frame_age_ms_p50", soak::percentile(frame_age, 0.5)},
              {"frame_age_ms_p99", soak::percentile(frame_age, 0.99)},
              {"command_age_ms_p99", soak::percentile(command_age, 0.99)},
              {"command_messages", command_age.size()},
              {"rest_ms_p50", soak::percentile(rest_ms, 0.5)},
              {"rest_ms_p99", soak::percentile(rest_ms, 0.99)},
              {"rest_failures", rest_failures},
              {"token_renewals", renewals},
              {"unexpected_disconnects", unexpected_closes},
              {"server_error_log_lines", log_errors.load()},
              {"server_exit_status", exit_status},
              {"db_mb_end", static_cast<double>(std::filesystem::file_size(db)) / 1048576.0},
              {"db_quick_check_ok", quick_check_ok},
              {"loadavg_1m_start", load_start[0]},
              {"loadavg_1m_mean", load_samples ? load_sum / load_samples : 0.0},
              {"loadavg_1m_end", load_end[0]},
              {"cpus", std::thread::hardware_concurrency()},
              {"pass", pass}};
  if (!health.body.empty()) doc["health_end"] = json::parse(health.body, nullptr, false);
  if (!client_error.empty()) doc["client_error"] = client_error;
  if (!quick_check_error.empty()) doc["db_error"] = quick_check_error;
  if (o.json_out) {
    std::cout << doc.dump(1) << "\n";
  } else {
    std::cout << "bench soak: " << o.clients << " clients on gbdcs serve (" << o.adapter << ", "
              << o.source << ") for " << window_s << " s\n"
              << "  server RSS " << rss_start << " -> " << rss_end << " MB (max " << rss_max
              << ", growth " << growth << ", limit " << o.rss_growth_limit_mb << ")\n"
              << "  alerts: " << sent.size() << " sent, " << received << " of "
              << sent.size() * static_cast<std::size_t>(o.clients) << " received, " << dropped
              << " dropped (" << worker_kills << " worker kills)\n"
              << "  telemetry delivery p99 " << soak::percentile(delivery, 0.99)
              << " ms, frame age p99 " << soak::percentile(frame_age, 0.99)
              << " ms, command age p99 " << soak::percentile(command_age, 0.99)
              << " ms, REST p99 " << soak::percentile(rest_ms, 0.99) << " ms\n"
              << "  load average " << load_start[0] << " -> " << load_end[0] << "\n"
              << (pass ? "PASS" : "FAIL") << "\n";
  }
  if (o.keep_dir.empty()) {
    std::error_code ec;
    std::filesystem::remove_all(dir, ec);
  }
  return pass ? 0 : 1;
}

void add_bench_soak(CLI::App& app) {
  static SoakOptions o;
  auto* cmd = group_command(app, "bench", "Benchmarks")
                  ->add_subcommand("soak",
                                   "gbdcs serve (child process, twin, supervised vision worker) with N "
                                   "dashboard clients for a long run; the worker is killed now and then. "
                                   "Memory growth, alerts sent/received/dropped, p99 latencies "
                                   "(docs/RELIABILITY.md)");
  cmd->add_option("--duration", o.duration, "Measured window: seconds or 90s, 30m, 1h")->capture_default_str();
  cmd->add_option("--clients", o.clients, "WebSocket clients")->capture_default_str()->check(CLI::Range(1, 200));
  cmd->add_option("--source", o.source, "Camera for the vision worker (as gbdcs serve --source)")
      ->capture_default_str();
  cmd->add_option("--adapter", o.adapter, "Drone (as gbdcs serve --adapter)")->capture_default_str();
  cmd->add_option("--kill-worker-every", o.kill_worker_every_s,
                  "Seconds between SIGKILLs of the vision worker (0: never); the first at half of it")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 86400.0));
  cmd->add_option("--warmup", o.warmup_s, "Seconds before the window starts")->capture_default_str()->check(CLI::Range(0.0, 3600.0));
  cmd->add_option("--sample-every", o.sample_every_s, "Seconds between memory samples and REST probes")
      ->capture_default_str()
      ->check(CLI::Range(0.2, 600.0));
  cmd->add_option("--rss-growth-limit-mb", o.rss_growth_limit_mb,
                  "Fail when the server's RSS grows more than this over the window")
      ->capture_default_str();
  cmd->add_option("--drain-timeout", o.drain_timeout_s,
                  "After the window, seconds to wait for every client to get every alert")
      ->capture_default_str()
      ->check(CLI::Range(1.0, 3600.0));
  cmd->add_option("--token-ttl", o.token_ttl_s, "GBDCS_TOKEN_TTL_S for the server (60-1800)")
      ->capture_default_str()
      ->check(CLI::Range(60, 1800));
  cmd->add_option("--keep", o.keep_dir, "Keep the database in this folder (default: a temp folder, removed)");
  cmd->add_flag("--json", o.json_out, "One JSON document");
  cmd->callback([] {
    try {
      g_exit_code = run_soak(o);
    } catch (const std::exception& e) {
      std::cerr << "gbdcs bench soak: " << e.what() << "\n";
      g_exit_code = 2;
    }
  });
}

const CommandRegistration kBenchSoak{61, &add_bench_soak};

}  // namespace
}  // namespace gbdcs::app
