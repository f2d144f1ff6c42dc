// Server::Impl: the state the transport's pieces share (the listener and HTTP sessions in
// http_server.cpp, the WebSocket sessions in ws_sessions.cpp). Private to core/server.
#pragma once

#include <utility>  // before Asio: its awaitable.hpp needs std::exchange

#include <boost/asio.hpp>
#include <boost/beast.hpp>
#include <boost/beast/websocket.hpp>
#include <mutex>
#include <thread>
#include <vector>

#include "api.hpp"
#include "gbdcs/server/server.hpp"

namespace gbdcs::server {

namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace net = boost::asio;
using tcp = net::ip::tcp;

struct Server::Impl {
  Impl(const contracts::Clock& c, storage::StorageManager& s, TokenService& t, DroneService& d,
       LiveHub& h, ServerOptions o, EventLog l)
      : clock(c), storage(s), tokens(t), drone(d), hub(h), options(std::move(o)), log(std::move(l)),
        limiter(c), replays(c, s, h, d), ids(c),
        ctx{c, s, t, d, h, metrics, replays, limiter, options, log, c.now()}, acceptor(ioc) {}

  const contracts::Clock& clock;
  storage::StorageManager& storage;
  TokenService& tokens;
  DroneService& drone;
  LiveHub& hub;
  ServerOptions options;
  EventLog log;
  Metrics metrics;
  LoginLimiter limiter;
  ReplayManager replays;
  UlidGenerator ids;
  ApiContext ctx;
  net::io_context ioc;
  tcp::acceptor acceptor;
  std::vector<std::thread> threads;
  std::mutex worker_mutex;
  WorkerHandlers worker;
  bool stopped = false;

  void accept();

  // The transport-free half of an HTTP exchange, shared by the sockets (HttpSession) and
  // Server::answer (the fuzz target): parser limits, the error for an unparsable request,
  // and routing a parsed request to its response (logged, counted).
  using Request = http::request<http::string_body>;
  using Response = http::response<http::string_body>;
  void limit(http::request_parser<http::string_body>& parser) const;
  Response parse_failure(beast::error_code ec, const std::string& remote);
  Response respond(const Request& req, const std::string& remote);
  ApiResponse dispatch(const Request& req, const std::string& remote, const std::string& rid,
                       std::string& path);
  void log_request(const std::string& rid, const std::string& method, const std::string& path,
                   const std::string& remote, const ApiResponse& a, double ms);
};

// The WebSocket sessions (ws_sessions.cpp), started once HttpSession has accepted the upgrade
// request: /ws/live for an authenticated dashboard client, /worker for the vision worker.
void start_live_session(tcp::socket socket, Server::Impl& impl, TokenClaims claims,
                        http::request<http::string_body> upgrade);
void start_worker_session(tcp::socket socket, Server::Impl& impl,
                          http::request<http::string_body> upgrade);

}  // namespace gbdcs::server
