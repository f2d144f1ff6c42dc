#include "soak_support.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <utility>  // before Asio
#include <boost/asio.hpp>
#include <boost/beast.hpp>
#include <boost/beast/websocket.hpp>

#include "gbdcs/contracts/codec.hpp"

namespace gbdcs::app::soak {

namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace net = boost::asio;
using tcp = net::ip::tcp;
using nlohmann::json;
using Steady = std::chrono::steady_clock;

HttpReply http_call(unsigned short port, const std::string& method, const std::string& target,
                    const std::string& body, const std::string& token) {
  HttpReply r;
  const auto start = Steady::now();
  try {
    net::io_context ioc;
    beast::tcp_stream stream(ioc);
    stream.expires_after(std::chrono::seconds(30));
    stream.connect(tcp::endpoint(net::ip::make_address("127.0.0.1"), port));
    http::request<http::string_body> req{http::string_to_verb(method), target, 11};
    req.set(http::field::host, "127.0.0.1:" + std::to_string(port));
    if (!token.empty()) req.set(http::field::authorization, "Bearer " + token);
    if (!body.empty()) req.set(http::field::content_type, "application/json");
    req.body() = body;
    req.prepare_payload();
    http::write(stream, req);
    beast::flat_buffer buffer;
    http::response<http::string_body> res;
    http::read(stream, buffer, res);
    r.status = res.result_int();
    r.body = res.body();
  } catch (const std::exception&) {
    r.status = 0;
  }
  r.elapsed_ms = std::chrono::duration<double, std::milli>(Steady::now() - start).count();
  return r;
}

std::int64_t utc_ms(const std::string& text) {
  try {
    return contracts::parse_utc(text).time_since_epoch().count();
  } catch (const std::exception&) {
    return -1;
  }
}

std::int64_t now_utc_ms() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

double rss_mb(pid_t pid, bool peak) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  const std::string key = peak ? "VmHWM:" : "VmRSS:";
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind(key, 0) == 0) return std::stod(line.substr(key.size())) / 1024.0;
  }
  return 0;
}

std::vector<pid_t> children_of(pid_t pid) {
  std::vector<pid_t> out;
  for (const auto& e : std::filesystem::directory_iterator("/proc")) {
    const auto name = e.path().filename().string();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    std::ifstream stat(e.path() / "stat");
    std::string text;
    std::getline(stat, text);
    const auto close_paren = text.rfind(')');
    if (close_paren == std::string::npos || close_paren + 2 >= text.size()) continue;
    std::istringstream rest(text.substr(close_paren + 2));
    char state = 0;
    int ppid = 0;
    rest >> state >> ppid;
    if (ppid == pid && state != 'Z') out.push_back(std::stoi(name));
  }
  return out;
}

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size())))];
}

// ---- ServeChild -------------------------------------------------------------------------

ServeChild::ServeChild(const std::vector<std::string>& args,
                       const std::map<std::string, std::string>& env,
                       std::function<void(const std::string&)> on_line)
    : on_line_(std::move(on_line)) {
  int out[2];
  if (::pipe(out) != 0) throw std::runtime_error("pipe failed");
  const std::string self = std::filesystem::read_symlink("/proc/self/exe").string();
  pid_ = ::fork();
  if (pid_ < 0) throw std::runtime_error("fork failed");
  if (pid_ == 0) {
    ::dup2(out[1], 1);
    ::dup2(out[1], 2);
    ::close(out[0]);
    for (const auto& [k, v] : env) ::setenv(k.c_str(), v.c_str(), 1);
    std::vector<std::string> all = {self, "serve"};
    all.insert(all.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (auto& a : all) argv.push_back(a.data());
    argv.push_back(nullptr);
    ::execv(self.c_str(), argv.data());
    ::_exit(127);
  }
  ::close(out[1]);
  fd_ = out[0];
  FILE* stream = ::fdopen(fd_, "r");
  std::string line;
  char buf[8192];
  // The port first (synchronously), then the rest of the log on a thread.
  while (std::fgets(buf, sizeof buf, stream)) {
    line = buf;
    {
      std::lock_guard lock(tail_mutex_);
      tail_.push_back(line);
    }
    const auto at = line.find("listening on http://127.0.0.1:");
    if (at != std::string::npos) {
      port_ = static_cast<unsigned short>(std::stoi(line.substr(at + 30)));
      break;
    }
  }
  reader_ = std::thread([this, stream] {
    char b[65536];
    while (std::fgets(b, sizeof b, stream)) {
      std::string l(b);
      if (on_line_) on_line_(l);
      std::lock_guard lock(tail_mutex_);
      tail_.push_back(std::move(l));
      if (tail_.size() > 40) tail_.erase(tail_.begin());
    }
    std::fclose(stream);
  });
}

ServeChild::~ServeChild() { stop(); }

namespace {
int decode_status(int status) { return WIFEXITED(status) ? WEXITSTATUS(status) : -WTERMSIG(status); }
}  // namespace

bool ServeChild::alive() {
  if (stopped_ || exited_) return false;
  int status = 0;
  if (::waitpid(pid_, &status, WNOHANG) == pid_) {
    exited_ = true;
    status_ = decode_status(status);
    return false;
  }
  return true;
}

std::vector<std::string> ServeChild::tail() const {
  std::lock_guard lock(tail_mutex_);
  return tail_;
}

int ServeChild::stop() {
  if (stopped_) return status_;
  stopped_ = true;
  if (!exited_) {
    ::kill(pid_, SIGTERM);
    int status = 0;
    ::waitpid(pid_, &status, 0);
    status_ = decode_status(status);
  }
  if (reader_.joinable()) reader_.join();
  return status_;
}

// ---- SoakClient -------------------------------------------------------------------------

namespace {

using Ws = websocket::stream<beast::tcp_stream>;

struct Login {
  std::string token;
  double expires_in_s = 0;
};

Login login(unsigned short port, const std::string& email, const std::string& password) {
  const auto r = http_call(port, "POST", "/api/v1/auth/login",
                           json{{"email", email}, {"password", password}}.dump());
  if (r.status != 200) {
    throw std::runtime_error("login: HTTP " + std::to_string(r.status) + " " + r.body.substr(0, 200));
  }
  const auto doc = json::parse(r.body);
  return {doc.at("token").get<std::string>(), doc.at("expires_in_s").get<double>()};
}

std::unique_ptr<Ws> open_ws(net::io_context& ioc, unsigned short port, const std::string& token) {
  auto ws = std::make_unique<Ws>(ioc);
  beast::get_lowest_layer(*ws).expires_after(std::chrono::seconds(30));
  beast::get_lowest_layer(*ws).connect(tcp::endpoint(net::ip::make_address("127.0.0.1"), port));
  ws->handshake("127.0.0.1", "/ws/live?token=" + token);
  return ws;
}

}  // namespace

SoakClient::SoakClient(unsigned short port, std::string email, std::string password,
                       double renew_fraction, const std::atomic<bool>& stop)
    : port_(port), email_(std::move(email)), password_(std::move(password)),
      renew_fraction_(renew_fraction), stop_(stop) {
  thread_ = std::thread([this] { run(); });
}

SoakClient::~SoakClient() {
  if (thread_.joinable()) thread_.join();
}

bool SoakClient::wait_connected(std::chrono::seconds timeout) {
  const auto until = Steady::now() + timeout;
  while (!connected_ && Steady::now() < until) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  return connected_;
}

std::size_t SoakClient::missing(const std::set<std::string>& alerts) const {
  std::lock_guard lock(alerts_mutex_);
  std::size_t n = 0;
  for (const auto& a : alerts) n += report_.alerts.count(a) ? 0 : 1;
  return n;
}

ClientReport SoakClient::report() {
  if (thread_.joinable()) thread_.join();
  return report_;
}

void SoakClient::run() {
  net::io_context ioc;
  beast::flat_buffer buffer;
  // Reads one message; returns its envelope or nullopt on error (the socket is then dead).
  auto read_one = [&](Ws& ws, bool measure) -> std::optional<json> {
    // Telemetry comes at >= 5 Hz, so 30 s of silence means the socket is dead.
    beast::get_lowest_layer(ws).expires_after(std::chrono::seconds(30));
    beast::error_code ec;
    buffer.consume(buffer.size());
    ws.read(buffer, ec);
    if (ec) {
      report_.last_error = ec.message();
      return std::nullopt;
    }
    const auto received = now_utc_ms();
    json doc = json::parse(beast::buffers_to_string(buffer.data()), nullptr, false);
    if (doc.is_discarded() || !doc.is_object()) return json::object();
    const auto type = doc.value("type", "");
    ++report_.messages[type];
    const auto& data = doc["data"];
    if (type == "alert") {
      std::lock_guard lock(alerts_mutex_);
      report_.alerts.insert(data.dump());
      if (data.is_object()) {
        if (auto ts = utc_ms(data.value("timestamp", "")); ts > 0) report_.alert_age_ms.push_back(double(received - ts));
      }
    }
    if (!measure || !data.is_object()) return doc;
    if (type == "telemetry") {
      if (auto ts = utc_ms(doc.value("ts", "")); ts > 0) report_.delivery_ms.push_back(double(received - ts));
    } else if (type == "frame") {
      if (auto ts = utc_ms(data.value("capture_time", "")); ts > 0) report_.frame_age_ms.push_back(double(received - ts));
    } else if (type == "command" && data.contains("command") && data["command"].is_object()) {
      if (auto ts = utc_ms(data["command"].value("issued_at", "")); ts > 0) {
        report_.command_age_ms.push_back(double(received - ts));
      }
    }
    return doc;
  };

  std::unique_ptr<Ws> ws;
  Steady::time_point renew_at;
  while (!stop_) {
    try {
      if (!ws) {
        const auto l = login(port_, email_, password_);
        ws = open_ws(ioc, port_, l.token);
        renew_at = Steady::now() + std::chrono::milliseconds(static_cast<std::int64_t>(l.expires_in_s * 1000 * renew_fraction_));
        connected_ = true;
      }
      if (Steady::now() >= renew_at) {
        // A dashboard that stays up: a new token and socket before the old token expires.
        const auto l = login(port_, email_, password_);
        auto fresh = open_ws(ioc, port_, l.token);
        const auto accepted_ms = now_utc_ms();
        // Everything stamped before the new socket was accepted went to the old one: read it
        // until a later message shows that the old queue holds nothing older.
        for (int i = 0; i < 10000; ++i) {
          auto doc = read_one(*ws, true);
          if (!doc) break;
          if (utc_ms(doc->value("ts", "")) > accepted_ms) break;
        }
        beast::get_lowest_layer(*ws).expires_after(std::chrono::seconds(2));
        beast::error_code ignored;
        ws->close(websocket::close_code::normal, ignored);
        ws = std::move(fresh);
        renew_at = Steady::now() + std::chrono::milliseconds(static_cast<std::int64_t>(l.expires_in_s * 1000 * renew_fraction_));
        ++report_.renewals;
      }
      if (!read_one(*ws, true)) {
        if (stop_) break;
        ++report_.unexpected_closes;
        ws.reset();
      }
    } catch (const std::exception& e) {
      report_.last_error = e.what();
      if (stop_) break;
      ++report_.unexpected_closes;
      ws.reset();
      std::this_thread::sleep_for(std::chrono::milliseconds(500));
    }
  }
  if (ws) {
    beast::get_lowest_layer(*ws).expires_after(std::chrono::seconds(2));
    beast::error_code ignored;
    ws->close(websocket::close_code::normal, ignored);
  }
}

}  // namespace gbdcs::app::soak
