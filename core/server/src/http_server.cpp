// The transport: the Beast listener and HTTP sessions; an upgrade request is checked here and
// handed to the WebSocket sessions (ws_sessions.cpp). Routing and auth decisions live in
// api_routes.cpp and live_hub.cpp.
#include <openssl/crypto.h>

#include <sstream>

#include "gbdcs/contracts/codec.hpp"
#include "server_impl.hpp"
#include "static_files.hpp"

namespace gbdcs::server {

using nlohmann::json;

namespace {

using Request = http::request<http::string_body>;
using Response = http::response<http::string_body>;

Response to_http(const ApiResponse& a, unsigned version, bool keep_alive, const std::string& rid) {
  Response res{static_cast<http::status>(a.status), version};
  res.set(http::field::server, "gbdcs");
  res.set("X-Request-Id", rid);
  if (a.status != 204) res.set(http::field::content_type, a.content_type);
  res.set(http::field::cache_control, "no-store");
  for (const auto& [k, v] : a.headers) res.set(k, v);
  res.keep_alive(keep_alive);
  res.body() = a.body;
  res.prepare_payload();
  return res;
}

std::map<std::string, std::string> parse_query(std::string_view q) {
  std::map<std::string, std::string> out;
  while (!q.empty()) {
    auto amp = q.find('&');
    auto pair = q.substr(0, amp);
    auto eq = pair.find('=');
    auto key = percent_decode(pair.substr(0, eq), true);
    auto value = eq == std::string_view::npos ? std::string() : percent_decode(pair.substr(eq + 1), true);
    if (!key.empty()) out[key] = value;
    if (amp == std::string_view::npos) break;
    q = q.substr(amp + 1);
  }
  return out;
}

bool is_loopback(const tcp::endpoint& e) { return e.address().is_loopback(); }

// ---- HTTP -------------------------------------------------------------------------------
class HttpSession final : public std::enable_shared_from_this<HttpSession> {
 public:
  HttpSession(tcp::socket socket, Server::Impl& impl) : stream_(std::move(socket)), impl_(impl) {}
  void run() {
    net::dispatch(stream_.get_executor(), [self = shared_from_this()] { self->read(); });
  }

 private:
  void read() {
    parser_.emplace();
    impl_.limit(*parser_);
    stream_.expires_after(std::chrono::seconds(30));
    http::async_read(stream_, buffer_, *parser_,
                     [self = shared_from_this()](beast::error_code ec, std::size_t) {
                       self->on_read(ec);
                     });
  }

  void on_read(beast::error_code ec) {
    if (ec == http::error::end_of_stream || ec == net::error::operation_aborted ||
        ec == beast::error::timeout || ec == net::error::eof || ec == net::error::connection_reset) {
      beast::error_code ignored;
      stream_.socket().shutdown(tcp::socket::shutdown_send, ignored);
      return;
    }
    if (ec) {
      send(impl_.parse_failure(ec, remote()), true);
      return;
    }
    Request req = parser_->release();
    if (websocket::is_upgrade(req)) return upgrade(std::move(req));
    handle(std::move(req));
  }

  std::string remote() const {
    beast::error_code ec;
    auto ep = stream_.socket().remote_endpoint(ec);
    return ec ? std::string("?") : ep.address().to_string();
  }

  void handle(Request req) { send(impl_.respond(req, remote()), !req.keep_alive()); }

  void send(Response res, bool close) {
    auto sp = std::make_shared<Response>(std::move(res));
    http::async_write(stream_, *sp,
                      [self = shared_from_this(), sp, close](beast::error_code ec, std::size_t) {
                        if (ec || close) {
                          beast::error_code ignored;
                          self->stream_.socket().shutdown(tcp::socket::shutdown_send, ignored);
                          return;
                        }
                        self->read();
                      });
  }

  void refuse(const ApiError& e, const Request& req) {
    impl_.metrics.ws_rejected++;
    const auto rid = impl_.ids.next();
    auto a = error_response(e, rid);
    impl_.log_request(rid, "GET", std::string(req.target()).substr(0, std::string(req.target()).find('?')),
                      remote(), a, 0);
    send(to_http(a, req.version(), false, rid), true);
  }

  bool origin_allowed(const Request& req) const {
    const auto origin = std::string(req[http::field::origin]);
    if (origin.empty()) return true;  // not a browser
    const auto host = std::string(req[http::field::host]);
    if (origin == "http://" + host || origin == "https://" + host) return true;
    for (const auto& o : impl_.options.allowed_origins) {
      if (o == origin) return true;
    }
    return false;
  }

  void upgrade(Request req) {
    const std::string target(req.target());
    const auto qpos = target.find('?');
    const auto path = target.substr(0, qpos);
    const auto query = qpos == std::string::npos ? std::map<std::string, std::string>{}
                                                 : parse_query(std::string_view(target).substr(qpos + 1));
    if (path == "/ws/live") {
      if (!origin_allowed(req)) {
        return refuse(ApiError(403, "forbidden_origin",
                               "WebSocket from origin '" + std::string(req[http::field::origin]).substr(0, 100) +
                                   "' is not allowed",
                               "open the dashboard from this server, or add the origin to "
                               "GBDCS_ALLOWED_ORIGINS"),
                      req);
      }
      TokenClaims claims;
      try {
        auto it = query.find("token");
        claims = authenticate(impl_.ctx, it == query.end() ? "" : it->second);
      } catch (const ApiError& e) {
        return refuse(e, req);
      }
      stream_.expires_never();
      start_live_session(stream_.release_socket(), impl_, claims, std::move(req));
      return;
    }
    if (path == "/worker") {
      beast::error_code ec;
      const auto ep = stream_.socket().remote_endpoint(ec);
      auto it = query.find("secret");
      const auto& want = impl_.options.worker_secret;
      const bool secret_ok = !want.empty() && it != query.end() && it->second.size() == want.size() &&
                             CRYPTO_memcmp(it->second.data(), want.data(), want.size()) == 0;
      if (ec || !is_loopback(ep) || !secret_ok) {
        return refuse(ApiError(403, "forbidden", "the vision worker endpoint takes only the worker "
                                                 "this server started (loopback, per-run secret)",
                               "do not connect to /worker yourself; use /ws/live"),
                      req);
      }
      stream_.expires_never();
      start_worker_session(stream_.release_socket(), impl_, std::move(req));
      return;
    }
    refuse(ApiError(404, "not_found", "no WebSocket at " + path.substr(0, 200), "use /ws/live?token=..."), req);
  }

  beast::tcp_stream stream_;
  Server::Impl& impl_;
  beast::flat_buffer buffer_;
  std::optional<http::request_parser<http::string_body>> parser_;
};

}  // namespace

// ---- the transport-free half (sockets and Server::answer) ---------------------------------
void Server::Impl::limit(http::request_parser<http::string_body>& parser) const {
  parser.body_limit(options.max_body_bytes);
  parser.header_limit(16 * 1024);
}

Server::Impl::Response Server::Impl::parse_failure(beast::error_code ec, const std::string& remote) {
  const auto rid = ids.next();
  const bool too_large = ec == http::error::body_limit || ec == http::error::header_limit;
  ApiError e(too_large ? 413 : 400, too_large ? "body_too_large" : "malformed_request",
             too_large ? "the request is larger than " + std::to_string(options.max_body_bytes) + " bytes"
                       : "the HTTP request cannot be parsed: " + ec.message(),
             too_large ? "send a smaller body (GBDCS_MAX_BODY_BYTES sets the limit)"
                       : "send a well-formed HTTP/1.1 request");
  auto a = error_response(e, rid);
  log_request(rid, "?", "?", remote, a, 0);
  return to_http(a, 11, false, rid);
}

void Server::Impl::log_request(const std::string& rid, const std::string& method,
                               const std::string& path, const std::string& remote,
                               const ApiResponse& a, double ms) {
  metrics.count_request(a.status);
  metrics.request_ms.observe(ms);
  if (!log) return;
  json e = {{"event", "http"}, {"request_id", rid}, {"method", method},
            {"path", path.substr(0, 200)}, {"status", a.status}, {"ms", ms},
            {"remote", remote}};
  if (!a.log_detail.empty()) e["cause"] = a.log_detail;
  log(a.status >= 500 ? "error" : (a.status >= 400 ? "warn" : "info"), e);
}

ApiResponse Server::Impl::dispatch(const Request& req, const std::string& remote,
                                   const std::string& rid, std::string& path) {
  const std::string target(req.target());
  const auto qpos = target.find('?');
  path = percent_decode(std::string_view(target).substr(0, qpos), false);
  ApiRequest ar;
  ar.method = std::string(req.method_string());
  ar.path = path;
  if (qpos != std::string::npos) ar.query = parse_query(std::string_view(target).substr(qpos + 1));
  ar.body = req.body();
  ar.content_type = std::string(req[http::field::content_type]);
  ar.authorization = std::string(req[http::field::authorization]);
  ar.remote = remote;
  ar.request_id = rid;
  try {
    if (path == "/metrics") ar.path = "/api/v1/metrics";
    if (ar.path == "/api/v1" || ar.path.rfind("/api/v1/", 0) == 0) return handle_api(ctx, ar);
    if (ar.path.rfind("/api/", 0) == 0 || ar.path == "/ws/live" || ar.path == "/worker") {
      throw ApiError(404, "not_found", "there is no route " + ar.method + " " + path.substr(0, 200),
                     "the API is under /api/v1 (GET /api/v1/openapi.json); /ws/live needs a "
                     "WebSocket upgrade");
    }
    if (req.method() != http::verb::get && req.method() != http::verb::head) {
      ApiError e(405, "method_not_allowed", "static files are read-only", "use GET");
      e.headers.emplace_back("Allow", "GET, HEAD");
      throw e;
    }
    return serve_static(options.web_dir, path);
  } catch (const ApiError& e) {
    return error_response(e, rid);
  } catch (const std::exception& e) {
    return error_response(ApiError(500, "internal", e.what(),
                                   "retry; if it persists, report the request id with the "
                                   "server log"),
                          rid);
  }
}

Server::Impl::Response Server::Impl::respond(const Request& req, const std::string& remote) {
  const auto t0 = clock.now();
  const auto rid = ids.next();
  std::string path;
  auto a = dispatch(req, remote, rid, path);
  log_request(rid, std::string(req.method_string()), path, remote, a,
              contracts::to_seconds(clock.now() - t0) * 1000.0);
  auto res = to_http(a, req.version(), req.keep_alive(), rid);
  if (req.method() == http::verb::head) {
    const auto length = res.body().size();
    res.body().clear();
    res.content_length(length);
  }
  return res;
}

void Server::Impl::accept() {
  acceptor.async_accept(net::make_strand(ioc), [this](beast::error_code ec, tcp::socket socket) {
    if (ec == net::error::operation_aborted || !acceptor.is_open()) return;
    if (!ec) std::make_shared<HttpSession>(std::move(socket), *this)->run();
    accept();
  });
}

Server::Server(const contracts::Clock& clock, storage::StorageManager& storage,
               TokenService& tokens, DroneService& drone, LiveHub& hub, ServerOptions options,
               EventLog log)
    : impl_(std::make_unique<Impl>(clock, storage, tokens, drone, hub, std::move(options),
                                   std::move(log))) {
  auto& m = impl_->metrics;
  m.gauge("gbdcs_ws_clients", "Connected /ws/live clients",
          [&h = hub] { return static_cast<double>(h.client_count()); });
  m.gauge("gbdcs_ws_queue_depth", "Messages waiting in all client queues",
          [&h = hub] { return static_cast<double>(h.queued_total()); });
  m.gauge("gbdcs_ws_dropped_total", "Messages dropped for slow clients",
          [&h = hub] { return static_cast<double>(h.dropped_total()); });
  m.gauge("gbdcs_ws_broadcasts_total", "Messages broadcast",
          [&h = hub] { return static_cast<double>(h.broadcast_total()); });
  m.gauge("gbdcs_drone_connected", "1 when a drone is connected",
          [&d = drone] { return d.connected() ? 1.0 : 0.0; });
  m.gauge("gbdcs_storage_write_failures", "Failed SQLite writes",
          [&s = storage] { return static_cast<double>(s.write_failures()); });
}

Server::~Server() { stop(); }

void Server::set_worker_handlers(WorkerHandlers handlers) {
  std::lock_guard lock(impl_->worker_mutex);
  impl_->worker = std::move(handlers);
}

void Server::start() {
  auto& i = *impl_;
  beast::error_code ec;
  const auto address = net::ip::make_address(i.options.bind, ec);
  if (ec) throw std::runtime_error("--bind " + i.options.bind + " is not an IP address (e.g. 127.0.0.1)");
  tcp::endpoint ep(address, i.options.port);
  i.acceptor.open(ep.protocol(), ec);
  if (!ec) i.acceptor.set_option(net::socket_base::reuse_address(true), ec);
  if (!ec) i.acceptor.bind(ep, ec);
  if (!ec) i.acceptor.listen(net::socket_base::max_listen_connections, ec);
  if (ec) {
    throw std::runtime_error("cannot listen on " + i.options.bind + ":" +
                             std::to_string(i.options.port) + ": " + ec.message() +
                             " (another server on that port? choose one with --port)");
  }
  i.accept();
  for (int t = 0; t < std::max(1, i.options.threads); ++t) i.threads.emplace_back([&i] { i.ioc.run(); });
}

void Server::stop() {
  auto& i = *impl_;
  if (i.stopped) return;
  i.stopped = true;
  i.replays.stop_all();
  net::post(i.ioc, [&i] {
    beast::error_code ec;
    i.acceptor.close(ec);
  });
  i.ioc.stop();
  for (auto& t : i.threads) {
    if (t.joinable()) t.join();
  }
}

std::string Server::answer(std::string_view request_bytes, const std::string& remote,
                           int max_requests) {
  auto& i = *impl_;
  std::string out;
  for (int n = 0; n < max_requests && !request_bytes.empty(); ++n) {
    http::request_parser<http::string_body> parser;
    i.limit(parser);
    parser.eager(true);
    beast::error_code ec;
    // The input is everything the peer sent before closing: parse what it holds, then EOF.
    // Stops when the bytes run out: put() on an empty buffer mid-body consumes nothing and
    // reports nothing (the fuzz target found that loop: fuzz_regressions/rest_request/).
    while (!parser.is_done() && !request_bytes.empty()) {
      const auto used = parser.put(net::buffer(request_bytes.data(), request_bytes.size()), ec);
      request_bytes.remove_prefix(used);
      if (ec == http::error::need_more) ec = {};
      if (ec || used == 0) break;
    }
    if (!ec && !parser.is_done()) {
      parser.put_eof(ec);
      if (ec == http::error::end_of_stream) return out;  // the peer sent nothing more
    }
    if (ec || !parser.is_done()) {
      std::ostringstream s;
      s << i.parse_failure(ec ? ec : beast::error_code(http::error::partial_message), remote);
      return out + s.str();
    }
    const Impl::Request& req = parser.get();
    std::ostringstream s;
    if (websocket::is_upgrade(req)) {
      const auto rid = i.ids.next();
      auto a = error_response(ApiError(400, "upgrade_needs_socket",
                                       "a WebSocket upgrade cannot be answered without a socket",
                                       "connect over TCP"),
                              rid);
      s << to_http(a, req.version(), false, rid);
      return out + s.str();
    }
    s << i.respond(req, remote);
    out += s.str();
    if (!req.keep_alive()) break;
  }
  return out;
}

unsigned short Server::port() const { return impl_->acceptor.local_endpoint().port(); }
Metrics& Server::metrics() { return impl_->metrics; }

}  // namespace gbdcs::server
