// `gbdcs serve`: the server operators run (docs/API.md, docs/OPERATIONS.md). Wires the
// production core (runtime::ControlLoop inside server::DroneService) to a drone made by
// make_drone, the HTTP/WebSocket server, SQLite, and the supervised vision worker
// (`gbdcs vision --publish ws://127.0.0.1:PORT/worker?secret=S`).
#include <unistd.h>

#include <atomic>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <mutex>
#include <optional>
#include <sstream>
#include <thread>

#include "command_registry.hpp"
#include "commands.hpp"
#include "drone_factory.hpp"
#include "gbdcs/contracts/codec.hpp"
#include "gbdcs/server/event_log.hpp"
#include "gbdcs/server/server.hpp"
#include "gbdcs/server/worker_supervisor.hpp"

namespace gbdcs::app {
namespace {

using nlohmann::json;

struct ServeOptions {
  unsigned short port = 8000;
  std::string bind = "127.0.0.1";
  std::string db = "var/gbdcs.db";
  std::string adapter;  // empty: the stored choice, else twin
  std::string adapter_options = "{}";
  std::string source = "recipe:fixtures/recipes/demo_flight.json?live=1&fps=30";
  std::string config;
  std::string web = "web/dist";
  bool log_json = false;
  bool no_worker = false;
  double worker_silence_s = 2.0;
  double drone_view_fps = 5.0;  // the twin's chase camera as drone_view messages; 0: off
};

std::atomic<bool> g_stop{false};
void on_stop_signal(int) { g_stop = true; }

std::string env(const char* name, const std::string& fallback = {}) {
  const char* v = std::getenv(name);
  return v ? std::string(v) : fallback;
}

// A whole-number setting from the environment, checked: a bad value names the variable, what
// it must be and where it is documented, instead of a bare "stoi".
long long env_int(const char* name, long long fallback, long long min, long long max) {
  const std::string text = env(name);
  if (text.empty()) return fallback;
  std::size_t used = 0;
  long long value = 0;
  try {
    value = std::stoll(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != text.size() || value < min || value > max) {
    throw std::runtime_error(std::string(name) + "='" + text.substr(0, 40) +
                             "' is not valid: set a whole number from " + std::to_string(min) +
                             " to " + std::to_string(max) + " or unset it (see .env.example)");
  }
  return value;
}

// --config FILE: the same settings as the options, as JSON; options on the command line win.
void apply_config_file(ServeOptions& o, const CLI::App& cmd) {
  std::ifstream in(o.config);
  if (!in) throw std::runtime_error("--config " + o.config + ": cannot read (check the path)");
  std::stringstream text;
  text << in.rdbuf();
  json doc;
  try {
    doc = contracts::parse_json(text.str());
  } catch (const std::exception& e) {
    throw std::runtime_error("--config " + o.config + ": " + e.what() + " (fix the JSON)");
  }
  if (!doc.is_object()) throw std::runtime_error("--config " + o.config + ": must be a JSON object");
  for (const auto& [key, value] : doc.items()) {
    const bool given = cmd.count("--" + key) > 0;
    try {
      if (key == "port") { if (!given) o.port = value.get<unsigned short>(); }
      else if (key == "bind") { if (!given) o.bind = value.get<std::string>(); }
      else if (key == "db") { if (!given) o.db = value.get<std::string>(); }
      else if (key == "adapter") { if (!given) o.adapter = value.get<std::string>(); }
      else if (key == "adapter-options") { if (!given) o.adapter_options = value.dump(); }
      else if (key == "source") { if (!given) o.source = value.get<std::string>(); }
      else if (key == "web") { if (!given) o.web = value.get<std::string>(); }
      else if (key == "log-json") { if (!given) o.log_json = value.get<bool>(); }
      else if (key == "drone-view-fps") { if (!given) o.drone_view_fps = value.get<double>(); }
      else throw std::runtime_error("unknown key");
    } catch (const std::exception& e) {
      throw std::runtime_error("--config " + o.config + ": key '" + key + "': " + e.what() +
                               " (keys: port, bind, db, adapter, adapter-options, source, web, log-json, "
                               "drone-view-fps)");
    }
  }
}

int run_serve(ServeOptions o) {
  if (!(o.drone_view_fps >= 0 && o.drone_view_fps <= 30)) {
    throw std::runtime_error("drone-view-fps " + std::to_string(o.drone_view_fps) +
                             " is out of range: give 0 (off) to 30");
  }
  contracts::SteadyClock clock;
  auto log = server::make_event_log(clock, o.log_json);
  // A file-size limit (ulimit -f) must fail the write (EFBIG, reported like a full disk), not
  // kill the server in mid-flight with SIGXFSZ. The vision worker inherits this.
  std::signal(SIGXFSZ, SIG_IGN);

  std::string secret = env("GBDCS_JWT_SECRET");
  if (secret.empty()) {
    secret = server::TokenService::random_secret();
    log("warn", {{"event", "jwt_secret_random"},
                 {"cause", "GBDCS_JWT_SECRET is not set: tokens are signed with a random secret "
                           "and die with this process"},
                 {"suggestion", "set GBDCS_JWT_SECRET (e.g. `openssl rand -hex 32`), see .env.example"}});
  }
  server::TokenService tokens(clock, secret,
                              static_cast<int>(env_int("GBDCS_TOKEN_TTL_S", 1800, 60, 1800)));

  storage::StorageOptions so;
  so.path = o.db;
  storage::StorageManager storage(so, clock);
  // Every failed write, for debugging; the operator-facing error (logged once per episode and
  // every 10 s while it lasts, plus an alert) comes from DroneService's storage watch.
  storage.set_error_handler([&log](const std::string& e) { log("debug", {{"event", "storage_error"}, {"cause", e}}); });
  storage.end_open_sessions();
  storage.apply_retention();
  storage.purge_revoked_tokens();

  auto profile = control::GestureProfile::builtin_default();
  if (auto stored = storage.get_config("profile")) {
    try {
      profile = control::GestureProfile::from_json(*stored);
    } catch (const std::exception& e) {
      log("warn", {{"event", "stored_profile_invalid"}, {"cause", e.what()}});
    }
  }
  std::string adapter = o.adapter;
  json adapter_options = contracts::parse_json(o.adapter_options);
  if (adapter.empty()) {
    adapter = "twin";
    if (auto stored = storage.get_config("adapter"); stored && stored->contains("name")) {
      adapter = stored->value("name", "twin");
      adapter_options = stored->value("options", json::object());
    }
  }

  server::LiveHub hub(clock);
  server::DroneService drone(
      clock, storage, hub,
      [&clock](const std::string& name, const json& options) { return make_drone(name, clock, options); },
      profile, log, [&o] {
        server::DroneServiceOptions dso;
        dso.view.fps = o.drone_view_fps;  // 320x240 JPEG: cheap next to vision on 2 cores
        return dso;
      }());

  const std::string worker_secret = server::TokenService::random_secret();
  server::ServerOptions so2;
  so2.bind = o.bind;
  so2.port = o.port;
  so2.web_dir = o.web;
  so2.worker_secret = worker_secret;
  so2.version = GBDCS_VERSION;
  so2.source = o.source;
  so2.adapters_available = drone_names();
  so2.max_body_bytes =
      static_cast<std::size_t>(env_int("GBDCS_MAX_BODY_BYTES", 1048576, 1024, 64LL << 20));
  for (std::stringstream origins(env("GBDCS_ALLOWED_ORIGINS")); origins.good();) {
    std::string one;
    std::getline(origins, one, ',');
    if (!one.empty()) so2.allowed_origins.push_back(one);
  }
  server::Server http(clock, storage, tokens, drone, hub, so2, log);
  http.start();
  const auto port = http.port();

  std::unique_ptr<server::WorkerSupervisor> supervisor;
  std::atomic<double> fps{0};
  // What the drone service was last told of vision. A heartbeat passes on a change of it: of
  // health (both ways), or of the reason while unhealthy (the camera's preparation counts its
  // frames). Told under the lock, so a worker's loss and a heartbeat cannot cross.
  // Health comes only from the pipeline's heartbeats (and a worker's loss), not from a new
  // worker's first message: one that cannot open its camera says so, then exits.
  std::mutex vision_told_mutex;
  std::optional<std::pair<bool, std::string>> vision_told;
  std::string worker_said;  // the current worker's last "not healthy" reason
  auto tell_vision = [&](bool healthy, const std::string& reason) {
    std::lock_guard lock(vision_told_mutex);
    if (vision_told && vision_told->first == healthy && vision_told->second == reason) return;
    vision_told.emplace(healthy, reason);
    drone.on_vision_health(healthy, reason);
  };
  auto heard_worker_say = [&](const std::string& reason) {
    std::lock_guard lock(vision_told_mutex);
    worker_said = reason;
  };
  // Why a worker was lost, with what it last said was wrong (the camera it could not open).
  auto loss_cause = [&](const std::string& why) {
    std::lock_guard lock(vision_told_mutex);
    return worker_said.empty() ? why : why + " (it said: " + worker_said + ")";
  };
  if (!o.no_worker) {
    server::WorkerOptions wo;
    wo.argv = {std::filesystem::read_symlink("/proc/self/exe").string(), "vision", "--source",
               o.source, "--publish",
               "ws://127.0.0.1:" + std::to_string(port) + "/worker?secret=" + worker_secret,
               "--publish-jpeg"};
    wo.silence_s = o.worker_silence_s;
    supervisor = std::make_unique<server::WorkerSupervisor>(
        clock, wo,
        [&](const std::string& why) {
          const auto cause = loss_cause(why);
          // HOVER first (the failsafe does it on unhealthy vision while flying), then the alert.
          tell_vision(false, cause);
          contracts::Alert a;
          a.severity = contracts::Severity::kCritical;
          a.code = "VISION_WORKER_LOST";
          a.cause = cause;
          a.suggestion = "the drone was told to hover; the worker is being restarted. Land with "
                         "the keyboard (l) if it does not come back";
          drone.raise_alert(a);
          http.metrics().worker_restarts++;
        },
        [&] { heard_worker_say(""); }, log);
    http.set_worker_handlers(
        {[&] { supervisor->on_connected(); },
         [&](const json& msg) {
           supervisor->on_message();
           if (msg["type"] == "heartbeat") {
             fps = msg.value("fps", 0.0);
             // The pipeline's own verdict.
             const bool healthy = msg.value("healthy", true);
             const std::string reason = healthy ? "" : msg.value("reason", "");
             heard_worker_say(reason);
             tell_vision(healthy, reason);
             return;
           }
           if (msg["type"] == "picture") {
             // The live feed's picture, at the camera's rate: shown, never acted on (commands
             // come only from vision results, below).
             http.metrics().feed_pictures++;
             hub.broadcast("picture", {{"frame_id", msg["frame_id"]},
                                       {"capture_time", msg["capture_time"]},
                                       {"width", msg["width"]}, {"height", msg["height"]},
                                       {"jpeg", msg["jpeg"]}});
             return;
           }
           http.metrics().vision_frames++;
           http.metrics().vision_latency_ms.observe(msg.value("latency_ms", 0.0));
           drone.on_vision_frame(msg);
           json data = {{"frame_id", msg["frame_id"]}, {"capture_time", msg["capture_time"]},
                        {"width", msg["width"]}, {"height", msg["height"]},
                        {"latency_ms", msg["latency_ms"]}, {"hands", msg["hands"]}};
           hub.broadcast("frame", data);
         },
         [&] { supervisor->on_disconnected(); }});
    supervisor->start();
  }

  if (auto error = drone.connect(adapter, adapter_options); !error.empty()) {
    log("error", {{"event", "drone_connect_failed"}, {"cause", error},
                  {"suggestion", "choose another adapter with PUT /api/v1/config or --adapter"}});
  }
  log("info", {{"event", "listening"}, {"url", "http://" + o.bind + ":" + std::to_string(port)},
               {"adapter", adapter}, {"source", o.source}, {"db", o.db}});
  // For scripts and tests that start on --port 0.
  std::cout << "gbdcs serve: listening on http://" << o.bind << ":" << port << std::endl;

  std::signal(SIGINT, on_stop_signal);
  std::signal(SIGTERM, on_stop_signal);
  while (!g_stop) {
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    if (supervisor) {
      drone.set_vision_status({supervisor->running(), supervisor->restarts(), fps.load(), o.source});
    }
  }
  log("info", {{"event", "stopping"}});
  if (supervisor) supervisor->stop();
  http.stop();
  drone.disconnect();
  return 0;
}

void add_serve_command(CLI::App& app) {
  static ServeOptions o;
  auto* cmd = app.add_subcommand(
      "serve",
      "Run the server: REST /api/v1, /ws/live, the dashboard, the drone (twin by default) and "
      "the supervised vision worker on a rendered hand video (docs/API.md, docs/OPERATIONS.md)");
  cmd->add_option("--port", o.port, "TCP port (0: any free one)")->capture_default_str();
  cmd->add_option("--bind", o.bind, "Address to listen on")->capture_default_str();
  cmd->add_option("--db", o.db, "SQLite database")->capture_default_str();
  cmd->add_option("--adapter", o.adapter,
                  "Drone: dummy, twin, tello, airsim, ... (default: the last one chosen with PUT "
                  "/config, else twin)");
  cmd->add_option("--adapter-options", o.adapter_options, "Adapter options JSON (docs/ADAPTERS.md)")
      ->capture_default_str();
  cmd->add_option("--source", o.source,
                  "Camera for the vision worker: camera:N, video:PATH, recipe:PATH[?live=1], "
                  "timeline:PATH, tello:[ADDRESS][?...] (the drone's own camera)")
      ->capture_default_str();
  cmd->add_option("--config", o.config, "JSON file with any of these options (the command line wins)");
  cmd->add_option("--web", o.web, "The built dashboard")->capture_default_str();
  cmd->add_flag("--log-json", o.log_json, "Log one JSON object per line");
  cmd->add_flag("--no-worker", o.no_worker, "Do not start the vision worker (API only)");
  cmd->add_option("--worker-silence", o.worker_silence_s,
                  "Seconds without a worker message before it is declared lost")
      ->capture_default_str()
      ->check(CLI::Range(0.2, 60.0));
  cmd->add_option("--drone-view-fps", o.drone_view_fps,
                  "Pictures per second of the drone from its own camera (the twin's chase camera, "
                  "320x240 JPEG) sent as drone_view messages; 0: off")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 30.0));
  cmd->callback([cmd] {
    try {
      if (!o.config.empty()) apply_config_file(o, *cmd);
      g_exit_code = run_serve(o);
    } catch (const std::exception& e) {
      std::cerr << "gbdcs serve: " << e.what() << "\n";
      g_exit_code = 2;
    }
  });
}

const CommandRegistration kServe{50, &add_serve_command};

}  // namespace
}  // namespace gbdcs::app
