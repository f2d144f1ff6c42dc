// Server: Boost.Beast HTTP + WebSocket on one port (default 127.0.0.1:8000).
//
//   REST /api/v1 (docs/API.md, core/server/openapi.json), /metrics, /ws/live?token=...,
//   /worker?secret=... (the vision worker, loopback only), and the dashboard from web_dir.
// Every request gets a ULID request id (X-Request-Id, the log line, the error envelope);
// bodies are limited to max_body_bytes (413) and validated against their JSON Schemas.
// Threads: `threads` I/O threads; one write outstanding per socket; per-client bounded
// queues (LiveHub). stop() closes the listener and every socket, then joins.
#pragma once

#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "gbdcs/contracts/clock.hpp"
#include "gbdcs/server/auth.hpp"
#include "gbdcs/server/drone_service.hpp"
#include "gbdcs/server/live_hub.hpp"
#include "gbdcs/server/metrics.hpp"
#include "gbdcs/storage/storage_manager.hpp"

namespace gbdcs::server {

struct ServerOptions {
  std::string bind = "127.0.0.1";
  unsigned short port = 8000;  // 0: any free port (tests)
  std::string web_dir = "web/dist";
  std::size_t max_body_bytes = 1 << 20;
  std::size_t max_ws_message_bytes = 64 << 10;
  std::vector<std::string> allowed_origins;  // besides the server's own
  int threads = 4;
  std::string worker_secret;  // empty: /worker refuses everyone
  std::string version = "0";
  std::string source;  // the vision source, shown in GET /config
  std::vector<std::string> adapters_available;
};

struct WorkerHandlers {
  std::function<void()> connected;
  std::function<void(const nlohmann::json&)> message;  // validated frame or heartbeat
  std::function<void()> closed;
};

class Server {
 public:
  Server(const contracts::Clock& clock, storage::StorageManager& storage, TokenService& tokens,
         DroneService& drone, LiveHub& hub, ServerOptions options, EventLog log);
  ~Server();
  void set_worker_handlers(WorkerHandlers handlers);
  void start();  // binds and listens; throws std::runtime_error naming the address and the fix
  void stop();
  unsigned short port() const;
  Metrics& metrics();

  // Answers raw HTTP/1.1 bytes without a socket (the REST fuzz target, fuzz/rest_request.cpp):
  // the connection's parser limits, error envelope, routing and handlers, up to `max_requests`
  // pipelined requests while each keeps the connection alive. Returns the raw responses, in
  // order; "" when the bytes hold no request. Needs no start(). A WebSocket upgrade is
  // answered 400 (upgrades need a socket).
  std::string answer(std::string_view request_bytes, const std::string& remote = "127.0.0.1",
                     int max_requests = 8);

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace gbdcs::server
