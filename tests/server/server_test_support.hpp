// A real server on an ephemeral port with a temp SQLite file, the dummy drone and a manual
// clock (so token expiry is a clock step), plus small blocking HTTP and WebSocket clients.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <utility>  // before Asio
#include <boost/asio.hpp>
#include <boost/beast.hpp>
#include <boost/beast/websocket.hpp>
#include <filesystem>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "gbdcs/adapters/registry.hpp"
#include "gbdcs/contracts/codec.hpp"
#include "gbdcs/server/server.hpp"

namespace gbdcs::server::testing {

namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace net = boost::asio;
using tcp = net::ip::tcp;
using nlohmann::json;

struct HttpResult {
  int status = 0;
  std::string body;
  std::map<std::string, std::string> headers;
  json doc() const { return json::parse(body); }
};

inline HttpResult http_call(unsigned short port, const std::string& method,
                            const std::string& target, const std::string& body = {},
                            const std::string& token = {},
                            const std::string& content_type = "application/json") {
  net::io_context ioc;
  beast::tcp_stream stream(ioc);
  stream.connect(tcp::endpoint(net::ip::make_address("127.0.0.1"), port));
  http::request<http::string_body> req{http::string_to_verb(method), target, 11};
  req.set(http::field::host, "127.0.0.1:" + std::to_string(port));
  if (!token.empty()) req.set(http::field::authorization, "Bearer " + token);
  if (!body.empty()) req.set(http::field::content_type, content_type);
  req.body() = body;
  req.prepare_payload();
  http::write(stream, req);
  beast::flat_buffer buffer;
  http::response_parser<http::string_body> parser;
  parser.body_limit(64 << 20);
  beast::error_code ec;
  http::read(stream, buffer, parser, ec);
  HttpResult r;
  if (ec && !parser.is_header_done()) return r;
  auto res = parser.release();
  r.status = res.result_int();
  r.body = res.body();
  for (const auto& f : res) r.headers[std::string(f.name_string())] = std::string(f.value());
  return r;
}

// Writes raw bytes (whatever the server does with them) and reads one response.
inline HttpResult raw_call(unsigned short port, const std::string& bytes) {
  net::io_context ioc;
  beast::tcp_stream stream(ioc);
  stream.connect(tcp::endpoint(net::ip::make_address("127.0.0.1"), port));
  beast::error_code ec;
  net::write(stream.socket(), net::buffer(bytes), ec);
  beast::flat_buffer buffer;
  http::response_parser<http::string_body> parser;
  http::read(stream, buffer, parser, ec);
  HttpResult r;
  if (!parser.is_header_done()) return r;
  auto res = parser.release();
  r.status = res.result_int();
  r.body = res.body();
  for (const auto& f : res) r.headers[std::string(f.name_string())] = std::string(f.value());
  return r;
}

// The status a WebSocket upgrade gets (101 when accepted).
inline int upgrade_status(unsigned short port, const std::string& target,
                          const std::string& origin = {}) {
  std::string req = "GET " + target + " HTTP/1.1\r\nHost: 127.0.0.1:" + std::to_string(port) +
                    "\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
                    "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n";
  if (!origin.empty()) req += "Origin: " + origin + "\r\n";
  req += "\r\n";
  return raw_call(port, req).status;
}

// Checks an error answer: status, envelope valid against api_error, the code.
inline void expect_error(const HttpResult& r, int status, const std::string& code) {
  EXPECT_EQ(r.status, status) << r.body;
  json doc;
  ASSERT_NO_THROW(doc = json::parse(r.body)) << r.body;
  EXPECT_TRUE(contracts::violations("api_error", doc).empty()) << r.body;
  EXPECT_EQ(doc.value("error", ""), code) << r.body;
  EXPECT_EQ(r.headers.count("X-Request-Id"), 1u);
  if (r.headers.count("X-Request-Id")) {
    EXPECT_EQ(doc.value("request_id", ""), r.headers.at("X-Request-Id"));
  }
}

class WsClient {
 public:
  WsClient() : ws_(ioc_) {}
  // Throws beast::system_error when refused; `refused_status` gets the HTTP status then.
  void connect(unsigned short port, const std::string& target, const std::string& origin = {}) {
    auto& layer = beast::get_lowest_layer(ws_);
    layer.connect(tcp::endpoint(net::ip::make_address("127.0.0.1"), port));
    if (!origin.empty()) {
      ws_.set_option(websocket::stream_base::decorator(
          [origin](websocket::request_type& req) { req.set(http::field::origin, origin); }));
    }
    websocket::response_type res;
    ws_.handshake(res, "127.0.0.1:" + std::to_string(port), target);
  }
  static int refused_status(unsigned short port, const std::string& target,
                            const std::string& origin = {}) {
    net::io_context ioc;
    websocket::stream<beast::tcp_stream> ws(ioc);
    beast::get_lowest_layer(ws).connect(tcp::endpoint(net::ip::make_address("127.0.0.1"), port));
    if (!origin.empty()) {
      ws.set_option(websocket::stream_base::decorator(
          [origin](websocket::request_type& req) { req.set(http::field::origin, origin); }));
    }
    websocket::response_type res;
    beast::error_code ec;
    ws.handshake(res, "127.0.0.1:" + std::to_string(port), target, ec);
    return ec ? res.result_int() : 101;
  }
  void send(const std::string& text) {
    ws_.text(true);
    ws_.write(net::buffer(text));
  }
  // The next message, or nullopt when the socket closed; gives up after `timeout_s`.
  std::optional<json> next(double timeout_s = 10) {
    beast::get_lowest_layer(ws_).expires_after(std::chrono::milliseconds(static_cast<int>(timeout_s * 1000)));
    beast::flat_buffer buffer;
    beast::error_code ec;
    ws_.read(buffer, ec);
    if (ec) {
      closed_ = ec == websocket::error::closed;
      close_code_ = ws_.reason().code;
      return std::nullopt;
    }
    return json::parse(beast::buffers_to_string(buffer.data()));
  }
  // The next message of `type` (skipping others), or nullopt.
  std::optional<json> next_of(const std::string& type, double timeout_s = 10) {
    for (int i = 0; i < 100000; ++i) {
      auto m = next(timeout_s);
      if (!m) return std::nullopt;
      if ((*m)["type"] == type) return m;
    }
    return std::nullopt;
  }
  bool closed() const { return closed_; }
  int close_code() const { return close_code_; }

 private:
  net::io_context ioc_;
  websocket::stream<beast::tcp_stream> ws_;
  bool closed_ = false;
  int close_code_ = 0;
};

class TempDir {
 public:
  TempDir() {
    static int counter = 0;
    path_ = std::filesystem::temp_directory_path() /
            ("gbdcs_server_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

// Everything a server needs, started on port 0.
struct TestServer {
  explicit TestServer(ServerOptions o = {}, std::string web_dir = "")
      : storage({.path = (dir.path() / "gbdcs.db").string()}, clock),
        tokens(clock, std::string(40, 'k'), 1800),
        hub(clock) {
    drone = std::make_unique<DroneService>(
        clock, storage, hub,
        [this](const std::string& name, const json& options) {
          return adapters::make_adapter(name, clock, options);
        },
        control::GestureProfile::builtin_default(), nullptr);
    o.port = 0;
    o.threads = 2;
    o.web_dir = web_dir.empty() ? (dir.path() / "no-dist").string() : web_dir;
    o.adapters_available = adapters::adapter_names();
    server = std::make_unique<Server>(clock, storage, tokens, *drone, hub, o, nullptr);
    server->start();
    port = server->port();
  }
  ~TestServer() {
    server->stop();
    drone.reset();
  }
  std::string register_and_login(const std::string& email = "pilot@example.com",
                                 const std::string& password = "correct horse battery") {
    json body = {{"email", email}, {"password", password}};
    http_call(port, "POST", "/api/v1/auth/register", body.dump());
    auto r = http_call(port, "POST", "/api/v1/auth/login", body.dump());
    EXPECT_EQ(r.status, 200) << r.body;
    return r.doc().value("token", "");
  }

  TempDir dir;
  contracts::ManualClock clock{contracts::UtcTime{std::chrono::milliseconds{1'767'225'600'000}}};
  storage::StorageManager storage;
  TokenService tokens;
  LiveHub hub;
  std::unique_ptr<DroneService> drone;
  std::unique_ptr<Server> server;
  unsigned short port = 0;
};

}  // namespace gbdcs::server::testing
