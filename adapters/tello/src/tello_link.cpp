#include "tello_link.hpp"

#include <algorithm>
#include <stdexcept>

namespace gbdcs::adapters::detail {

namespace asio = boost::asio;

namespace {

constexpr auto kTickPeriod = std::chrono::milliseconds(10);
constexpr double kDeferredReplyS = 20;  // take-off/land replies come within this (clock)

}  // namespace

std::string trim_reply(std::string s) {
  while (!s.empty() && (s.back() == '\r' || s.back() == '\n' || s.back() == ' ' ||
                        s.back() == '\0')) {
    s.pop_back();
  }
  return s;
}

bool is_error_reply(const std::string& reply) {
  return reply.rfind("error", 0) == 0 || reply.rfind("Error", 0) == 0 ||
         reply.rfind("unknown command", 0) == 0 || reply.rfind("out of range", 0) == 0;
}

TelloLink::TelloLink(const contracts::Clock& c, TelloOptions o)
    : clock(c),
      options(std::move(o)),
      command_socket_(io_),
      state_socket_(io_),
      tick_timer_(io_) {
  boost::system::error_code ec;
  const auto drone_address = asio::ip::make_address(options.address, ec);
  if (ec) {
    throw std::invalid_argument(options.name + " options: 'address' '" + options.address +
                                "' is not an IP address (the " + options.drone_label +
                                "'s is usually 192.168.10.1)");
  }
  drone_ = udp::endpoint(drone_address, static_cast<unsigned short>(options.command_port));
  const auto bind_address = asio::ip::make_address(options.bind_address, ec);
  if (ec) {
    throw std::invalid_argument(options.name + " options: 'bind_address' '" +
                                options.bind_address + "' is not an IP address");
  }
  open_bound(command_socket_,
             udp::endpoint(bind_address, static_cast<unsigned short>(options.local_command_port)),
             "command", "local_command_port");
  open_bound(state_socket_,
             udp::endpoint(bind_address, static_cast<unsigned short>(options.state_port)),
             "state", "state_port");
}

TelloLink::~TelloLink() { stop(); }

void TelloLink::start() {
  receive_reply();
  receive_state();
  schedule_tick();
  io_thread_ = std::thread([this] { io_.run(); });
}

void TelloLink::stop() {
  io_.stop();
  if (io_thread_.joinable()) io_thread_.join();
}

void TelloLink::open_bound(udp::socket& socket, const udp::endpoint& at, const char* what,
                           const char* key) {
  boost::system::error_code ec;
  socket.open(at.protocol(), ec);
  if (!ec) socket.set_option(udp::socket::reuse_address(false), ec);
  if (!ec) socket.bind(at, ec);
  if (ec) {
    throw std::runtime_error(options.name + ": cannot bind the " + what + " socket to " +
                             at.address().to_string() + ":" + std::to_string(at.port()) + ": " +
                             ec.message() +
                             " (another Tello client or gbdcs running? stop it, or set '" + key +
                             "' in the options to another port, 0 for any free one)");
  }
}

// ---- I/O thread ---------------------------------------------------------------------------

void TelloLink::receive_reply() {
  command_socket_.async_receive_from(
      asio::buffer(reply_buffer_), reply_from_,
      [this](boost::system::error_code ec, std::size_t n) {
        if (ec == asio::error::operation_aborted) return;
        if (!ec) on_reply(std::string(reply_buffer_.data(), n));
        receive_reply();
      });
}

void TelloLink::receive_state() {
  state_socket_.async_receive_from(
      asio::buffer(state_buffer_), state_from_,
      [this](boost::system::error_code ec, std::size_t n) {
        if (ec == asio::error::operation_aborted) return;
        if (!ec) on_state_datagram(std::string_view(state_buffer_.data(), n));
        receive_state();
      });
}

void TelloLink::schedule_tick() {
  tick_timer_.expires_after(kTickPeriod);
  tick_timer_.async_wait([this](boost::system::error_code ec) {
    if (ec) return;
    tick();
    schedule_tick();
  });
}

void TelloLink::on_reply(std::string text) {
  text = trim_reply(std::move(text));
  std::lock_guard lock(mutex);
  ++stats.replies;
  if (pending.empty()) {
    ++stats.unexpected_replies;
    return;
  }
  auto p = pending.front();
  pending.pop_front();
  p->reply = text;
  p->answered = true;
  p->done = true;
  if (p->deferred) on_late_reply_locked(*p);
  reply_cv.notify_all();
}

// ---- sending ------------------------------------------------------------------------------

std::shared_ptr<TelloLink::Pending> TelloLink::send_locked(const std::string& text,
                                                           bool expect_reply) {
  std::shared_ptr<Pending> p;
  if (expect_reply) {
    p = std::make_shared<Pending>();
    p->command = text;
    p->expires = clock.now() + contracts::from_seconds(options.reply_timeout_ms / 1000.0);
    pending.push_back(p);
  }
  boost::system::error_code ec;
  command_socket_.send_to(asio::buffer(text), drone_, 0, ec);
  ++stats.commands_sent;
  last_sent_at = clock.now();
  if (ec) {
    last_error = "cannot send '" + text + "' to " + endpoint_text() + ": " + ec.message() + " (" +
                 fix_text() + ")";
    if (p) {
      pending.pop_back();
      p->done = true;
      p->reply.clear();
    }
  }
  return p;
}

std::optional<std::string> TelloLink::request_locked(std::unique_lock<std::mutex>& lock,
                                                     const std::string& text,
                                                     std::chrono::milliseconds wait,
                                                     bool deferred) {
  send_failed = false;
  auto p = send_locked(text, true);
  if (!p || p->done) {
    send_failed = true;
    return std::nullopt;
  }
  reply_cv.wait_for(lock, wait, [&] { return p->done; });
  if (p->answered) return p->reply;
  if (p->done) return std::nullopt;  // expired or abandoned (an emergency cleared it)
  if (deferred) {
    p->deferred = true;
    p->expires = clock.now() + contracts::from_seconds(kDeferredReplyS);
  } else {
    abandon_locked(p);
  }
  return std::nullopt;
}

void TelloLink::abandon_locked(const std::shared_ptr<Pending>& p) {
  auto it = std::find(pending.begin(), pending.end(), p);
  if (it != pending.end()) pending.erase(it);
}

void TelloLink::abandon_all_locked() {
  for (auto& p : pending) p->done = true;
  pending.clear();
  reply_cv.notify_all();
}

// Replies nobody waits for (keep-alive, take-off/land) expire on the injected clock, so a
// lockstep run gives a lost one up after the same simulated time as a real flight would.
void TelloLink::expire_pending_locked() {
  const auto now = clock.now();
  while (!pending.empty() && pending.front()->expires < now) {
    pending.front()->done = true;  // never answered: lost
    pending.pop_front();
  }
}

bool TelloLink::long_command_pending_locked() const {
  return std::any_of(pending.begin(), pending.end(), [](const auto& p) { return p->deferred; });
}

std::string TelloLink::endpoint_text() const {
  return options.address + ":" + std::to_string(options.command_port);
}

std::string TelloLink::fix_text() const {
  return "join " + options.wifi_hint + ", check that the " + options.drone_label +
         " is on and that 'address' (" + options.address + ") and 'command_port' (" +
         std::to_string(options.command_port) + ") in the " + options.name +
         " options are right";
}

std::uint16_t TelloLink::local_state_port() const {
  return state_socket_.local_endpoint().port();
}

std::uint16_t TelloLink::local_command_port() const {
  return command_socket_.local_endpoint().port();
}

}  // namespace gbdcs::adapters::detail
