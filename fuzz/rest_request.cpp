// The REST request path: raw bytes through Beast's HTTP request parser, the router and the
// handlers over a real SQLite store (a temp file), with no socket: Server::answer, the same
// code a connection runs. A user is registered once; "@TOKEN@" in the input becomes that
// user's bearer token, so the authenticated routes are reached too.
//
// Checks (read from the server's request counters): no 5xx (a handler that fails on bad input
// instead of answering 4xx), and no successful response carries the marker file placed
// beside (outside) the dashboard folder (path traversal).
#include <stdlib.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "fuzz_harness.hpp"
#include "gbdcs/adapters/dummy_adapter.hpp"
#include "gbdcs/contracts/clock.hpp"
#include "gbdcs/control/command_translator.hpp"
#include "gbdcs/server/server.hpp"

namespace gbdcs::fuzz {
namespace {

constexpr std::string_view kName = "rest_request";
constexpr std::string_view kOutsideMarker = "GBDCS-FUZZ-OUTSIDE-THE-WEB-DIR";

std::filesystem::path make_temp_dir() {
  std::string templ = (std::filesystem::temp_directory_path() / "gbdcs_fuzz_rest_XXXXXX").string();
  require(::mkdtemp(templ.data()) != nullptr, kName, "cannot create a temp dir");
  return templ;
}

struct Rig {
  Rig()
      : dir(make_temp_dir()),
        storage({.path = (dir / "gbdcs.db").string()}, clock),
        tokens(clock, std::string(40, 'k'), 1800),
        hub(clock) {
    std::filesystem::create_directories(dir / "web");
    std::ofstream(dir / "web" / "index.html") << "<!doctype html><title>GBDCS</title>";
    std::ofstream(dir / "outside.txt") << kOutsideMarker;
    drone = std::make_unique<server::DroneService>(
        clock, storage, hub,
        [this](const std::string& name, const nlohmann::json& options)
            -> std::unique_ptr<control::DroneAdapter> {
          // Only the dummy: a fuzzed connect must not send packets anywhere.
          if (name != "dummy") throw std::invalid_argument("fuzz rig: only the dummy drone");
          return std::make_unique<adapters::DummyDroneAdapter>(
              clock, adapters::DummyOptions::from_json(options));
        },
        control::GestureProfile::builtin_default(), nullptr);
    server::ServerOptions o;
    o.web_dir = (dir / "web").string();
    o.threads = 1;
    o.adapters_available = {"dummy"};
    server = std::make_unique<server::Server>(clock, storage, tokens, *drone, hub, o, nullptr);
    const std::string creds = R"({"email":"pilot@example.com","password":"a long pass phrase"})";
    const auto post = [&](const std::string& path) {
      return server->answer("POST " + path + " HTTP/1.1\r\nHost: x\r\nContent-Type: "
                            "application/json\r\nContent-Length: " +
                            std::to_string(creds.size()) + "\r\n\r\n" + creds);
    };
    const auto registered = post("/api/v1/auth/register");
    require(registered.find("HTTP/1.1 201") == 0, kName, "register failed: " + registered);
    const auto login = post("/api/v1/auth/login");
    const auto body = login.find("\r\n\r\n");
    require(body != std::string::npos, kName, "login answered nothing: " + login);
    token = nlohmann::json::parse(login.substr(body + 4)).value("token", "");
    require(!token.empty(), kName, "login gave no token: " + login);
  }
  ~Rig() {
    server.reset();
    drone.reset();
    std::error_code ec;
    std::filesystem::remove_all(dir, ec);
  }

  contracts::SteadyClock clock;
  std::filesystem::path dir;
  storage::StorageManager storage;
  server::TokenService tokens;
  server::LiveHub hub;
  std::unique_ptr<server::DroneService> drone;
  std::unique_ptr<server::Server> server;
  std::string token;
};

}  // namespace

void rest_request(Bytes input) {
  static Rig rig;
  std::string request(as_text(input));
  for (auto at = request.find("@TOKEN@"); at != std::string::npos; at = request.find("@TOKEN@", at)) {
    request.replace(at, 7, rig.token);
    at += rig.token.size();
  }
  auto& metrics = rig.server->metrics();
  const auto failed_before = metrics.requests_with_status(500, 599);
  const auto served_before = metrics.requests_with_status(200, 299);
  const auto out = rig.server->answer(request);
  // Statuses are read from the server's own request counters, never searched for in the
  // output: a body may echo anything the request carried, and the fuzzer learns the strings
  // a harness compares and plants them in the path (the false alarms kept in
  // fuzz_regressions/rest_request/: the marker and "HTTP/1.0 500" echoed in a 404).
  require(metrics.requests_with_status(500, 599) == failed_before, kName,
          "a request was answered 5xx (an unexpected failure, not a clear 4xx): " +
              out.substr(0, 600));
  // Only a successful answer can carry a file, and only when the request did not carry the
  // marker's text itself (an echo).
  const bool served = metrics.requests_with_status(200, 299) != served_before;
  require(!served || request.find(kOutsideMarker) != std::string::npos ||
              out.find(kOutsideMarker) == std::string::npos,
          kName, "a response carries a file from outside the dashboard folder: " + out.substr(0, 600));
}

}  // namespace gbdcs::fuzz

GBDCS_FUZZ_ENTRY(rest_request)
