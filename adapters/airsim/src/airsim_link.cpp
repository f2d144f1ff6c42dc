#include "airsim_link.hpp"

#include <algorithm>
#include <stdexcept>

namespace gbdcs::adapters::detail {

namespace asio = boost::asio;
using control::Result;

namespace {

constexpr auto kTickPeriod = std::chrono::milliseconds(10);
constexpr std::size_t kMaxBuffered = 4 << 20;  // a frame bigger than this is not AirSim's

}  // namespace

AirSimLink::AirSimLink(const contracts::Clock& c, AirSimOptions o)
    : clock(c), options(std::move(o)), socket_(io_), tick_timer_(io_), unpacker_(make_unpacker()) {
  boost::system::error_code ec;
  const auto address = asio::ip::make_address(options.address, ec);
  if (ec) {
    throw std::invalid_argument("airsim options: 'address' '" + options.address +
                                "' is not an IP address");
  }
  server_ = tcp::endpoint(address, static_cast<unsigned short>(options.port));
}

AirSimLink::~AirSimLink() { stop(); }

void AirSimLink::start() {
  schedule_tick();
  io_thread_ = std::thread([this] { io_.run(); });
}

void AirSimLink::stop() {
  io_.stop();
  if (io_thread_.joinable()) io_thread_.join();
}

// Copies every string (no references into the buffer) and bounds what one frame may hold.
std::unique_ptr<msgpack::unpacker> AirSimLink::make_unpacker() {
  return airsim::make_reply_unpacker();  // the bounds the fuzz target checks (airsim_rpc.hpp)
}

std::string AirSimLink::where() const {
  return options.address + ":" + std::to_string(options.port);
}

std::string AirSimLink::fix() const {
  return "start the AirSim environment (Unreal, a multirotor vehicle) or `gbdcs twin "
         "--airsim`, and check 'address'/'port' in the airsim options against "
         "settings.json's ApiServerPort";
}

void AirSimLink::schedule_tick() {
  tick_timer_.expires_after(kTickPeriod);
  tick_timer_.async_wait([this](boost::system::error_code ec) {
    if (ec) return;
    tick();
    schedule_tick();
  });
}

// ---- connection (I/O thread) --------------------------------------------------------------

void AirSimLink::dial() {
  dialing = true;
  ++dial_generation;
  const auto generation = dial_generation;
  asio::post(io_, [this, generation] {
    boost::system::error_code ignored;
    socket_.close(ignored);
    unpacker_ = make_unpacker();
    socket_.async_connect(server_, [this, generation](boost::system::error_code ec) {
      std::lock_guard lock(mutex);
      if (generation != dial_generation) return;
      dialing = false;
      dial_error = ec ? ec.message() : "";
      if (!ec) {
        boost::system::error_code e2;
        socket_.set_option(tcp::no_delay(true), e2);
        socket_up = true;
        ++stats.connects;
        backoff_s = options.reconnect_min_s;
        read();
        if (connected) on_redialled_locked();
      } else if (connected) {
        reconnect_at = clock.now() + contracts::from_seconds(backoff_s);
        backoff_s = std::min(backoff_s * 2, options.reconnect_max_s);
      }
      cv.notify_all();
    });
  });
}

void AirSimLink::read() {
  socket_.async_read_some(asio::buffer(read_buffer_), [this](boost::system::error_code ec,
                                                             std::size_t n) {
    if (ec == asio::error::operation_aborted) return;
    if (ec) {
      lost_socket("the connection to AirSim at " + where() + " closed: " + ec.message());
      return;
    }
    if (!on_bytes(n)) return;
    read();
  });
}

void AirSimLink::lost_socket(const std::string& why) {
  std::lock_guard lock(mutex);
  lost_socket_locked(why);
}

void AirSimLink::lost_socket_locked(const std::string& why) {
  if (!socket_up) return;
  socket_up = false;
  boost::system::error_code ignored;
  socket_.close(ignored);
  last_error = why + " (reconnecting)";
  stats.lost_requests += calls.size();
  for (auto& [id, c] : calls) {
    c->done = true;
    c->error = "connection lost";
  }
  calls.clear();
  cv.notify_all();
  reconnect_at = clock.now() + contracts::from_seconds(backoff_s);
}

// Feeds the unpacker; false when the stream is broken (the socket is dropped).
bool AirSimLink::on_bytes(std::size_t n) {
  std::vector<contracts::TelemetryFrame> frames;
  control::TelemetrySink to;
  {
    std::lock_guard lock(mutex);
    if (unpacker_->nonparsed_size() + n > kMaxBuffered) {
      ++stats.malformed;
      stats.last_malformed = "a frame larger than 4 MiB";
      lost_socket_locked("AirSim sent a frame larger than 4 MiB");
      return false;
    }
    unpacker_->reserve_buffer(n);
    std::copy_n(read_buffer_.data(), n, unpacker_->buffer());
    unpacker_->buffer_consumed(n);
    try {
      msgpack::object_handle message;
      while (unpacker_->next(message)) on_message(std::move(message), frames);
    } catch (const std::exception& e) {
      ++stats.malformed;
      stats.last_malformed = std::string("undecodable msgpack: ") + e.what();
      lost_socket_locked("AirSim sent undecodable msgpack (" + std::string(e.what()) + ")");
      return false;
    }
    to = sink;
  }
  deliver(frames, to);
  return true;
}

void AirSimLink::on_message(msgpack::object_handle&& message,
                            std::vector<contracts::TelemetryFrame>& frames) {
  std::string why;
  auto response = airsim::decode_response(std::move(message), why);
  if (!response) {
    ++stats.malformed;
    stats.last_malformed = why;
    return;
  }
  ++stats.responses;
  const auto it = calls.find(response->msgid);
  if (it == calls.end()) return;  // abandoned (timed out) or from before a reconnect
  auto call = it->second;
  calls.erase(it);
  call->done = true;
  call->answered = true;
  call->ok = response->ok;
  call->error = response->error;
  call->result = std::move(response->result);
  if (call->is_state) {
    on_state_response_locked(*call, frames);
  } else if (call->deferred) {
    const auto& r = call->result.get();
    if (!call->ok) {
      last_error = call->method + ": AirSim answered: " + call->error;
    } else if (r.type == msgpack::type::BOOLEAN && !r.via.boolean &&
               call->method != "moveByVelocityBodyFrame") {
      last_error = call->method + ": AirSim answered false (timed out or cancelled)";
    }
  }
  cv.notify_all();
}

void AirSimLink::deliver(const std::vector<contracts::TelemetryFrame>& frames,
                         const control::TelemetrySink& to) {
  if (!to || frames.empty()) return;
  std::lock_guard order(sink_mutex);
  for (const auto& f : frames) to(f);
}

// ---- calls --------------------------------------------------------------------------------

std::shared_ptr<AirSimLink::Call> AirSimLink::call_locked(
    const std::string& method, const std::function<void(Packer&)>& params, bool deferred,
    bool is_state) {
  if (!socket_up) return nullptr;
  auto c = std::make_shared<Call>();
  c->method = method;
  c->deferred = deferred;
  c->is_state = is_state;
  const double life_s = deferred ? std::max(options.takeoff_timeout_s, options.land_timeout_s) + 5
                                 : options.rpc_timeout_ms / 1000.0;
  c->expires = clock.now() + contracts::from_seconds(life_s);
  const auto id = next_id_++;
  const auto bytes = airsim::encode_request(id, method, [&](Packer& p) { params(p); });
  calls[id] = c;
  boost::system::error_code ec;
  asio::write(socket_, asio::buffer(bytes), ec);
  if (!ec) ++stats.requests;
  if (ec) {
    calls.erase(id);
    lost_socket_locked("cannot send to AirSim at " + where() + ": " + ec.message());
    return nullptr;
  }
  return c;
}

std::shared_ptr<AirSimLink::Call> AirSimLink::wait_locked(
    std::unique_lock<std::mutex>& lock, const std::string& method,
    const std::function<void(Packer&)>& params, std::chrono::milliseconds wait, bool deferred) {
  auto c = call_locked(method, params, false);
  if (!c) return nullptr;
  cv.wait_for(lock, wait, [&] { return c->done; });
  if (!c->done) {
    if (deferred) {
      c->deferred = true;
      c->expires = clock.now() + contracts::from_seconds(options.land_timeout_s + 5);
    }
  }
  return c;
}

Result AirSimLink::check(const std::shared_ptr<Call>& c, const std::string& what,
                         bool want_true) {
  if (!c) {
    last_error = what + ": not sent (" + last_error + ")";
    return Result::kNotConnected;
  }
  if (!c->done) {
    last_error = what + ": no answer from AirSim at " + where() + " in " +
                 std::to_string(options.rpc_timeout_ms) + " ms";
    return Result::kTimeout;
  }
  if (!c->answered) {
    last_error = what + ": " + (c->error.empty() ? "no answer from AirSim" : c->error) +
                 " (AirSim at " + where() + ")";
    return c->error.empty() ? Result::kTimeout : Result::kNotConnected;
  }
  if (!c->ok) {
    last_error = what + ": AirSim answered: " + c->error;
    return Result::kRejected;
  }
  const auto& r = c->result.get();
  if (want_true && !(r.type == msgpack::type::BOOLEAN && r.via.boolean)) {
    last_error = what + ": AirSim answered " + airsim::describe(r);
    return Result::kRejected;
  }
  return Result::kOk;
}

// Calls nobody waits for any more expire on the injected clock (simulated time in a lockstep
// run); the blocking waits themselves are real time (a socket's).
void AirSimLink::expire_calls_locked() {
  const auto now = clock.now();
  for (auto it = calls.begin(); it != calls.end();) {
    if (it->second->expires < now) {
      it->second->done = true;
      it = calls.erase(it);
    } else {
      ++it;
    }
  }
  stats.outstanding = calls.size();
}

void AirSimLink::redial_if_due_locked(contracts::Duration now) {
  if (!socket_up && !dialing && now >= reconnect_at) dial();
}

}  // namespace gbdcs::adapters::detail
