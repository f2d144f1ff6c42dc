#include "gbdcs/sim/airsim_emulator.hpp"

#include <algorithm>

#include "airsim_emulator_impl.hpp"

// The msgpack-RPC server: the listener, one session per client, framing, malformed input,
// responses queued per connection. The methods themselves are in airsim_methods.cpp.

namespace gbdcs::sim {

using namespace airsim_emulator_detail;

namespace {

constexpr std::size_t kMaxFrame = 1 << 20;

}  // namespace

AirSimEmulator::Impl::Impl(TwinHost& h, AirSimEmulatorOptions o) : host(h), options(std::move(o)), acceptor(io) {
  boost::system::error_code ec;
  const auto address = asio::ip::make_address(options.bind_address, ec);
  if (ec) {
    throw std::invalid_argument("airsim emulator: bind_address '" + options.bind_address +
                                "' is not an IP address");
  }
  const tcp::endpoint at(address, static_cast<unsigned short>(options.port));
  acceptor.open(at.protocol(), ec);
  if (!ec) acceptor.set_option(tcp::acceptor::reuse_address(true), ec);
  if (!ec) acceptor.bind(at, ec);
  if (!ec) acceptor.listen(asio::socket_base::max_listen_connections, ec);
  if (ec) {
    throw std::runtime_error("airsim emulator: cannot listen on TCP " + options.bind_address +
                             ":" + std::to_string(options.port) + ": " + ec.message() +
                             " (AirSim or another emulator running? use --airsim-port, 0 "
                             "for any)");
  }
}

void AirSimEmulator::Impl::start() {
  listener = host.add_listener([this](TwinSim& sim, double t) { on_step(sim, t); });
  accept();
  thread = std::thread([this] { io.run(); });
}

void AirSimEmulator::Impl::shutdown() {
  host.remove_listener(listener);
  io.stop();
  if (thread.joinable()) thread.join();
}

void AirSimEmulator::Impl::accept() {
  auto session = std::make_shared<Session>(io);
  acceptor.async_accept(session->socket, [this, session](boost::system::error_code ec) {
    if (ec == asio::error::operation_aborted) return;
    if (!ec) {
      boost::system::error_code e2;
      session->socket.set_option(tcp::no_delay(true), e2);
      {
        std::lock_guard lock(mutex);
        ++stats.connections;
        sessions.insert(session);
      }
      read(session);
    }
    accept();
  });
}

void AirSimEmulator::Impl::close(const std::shared_ptr<Session>& s) {
  if (s->closed) return;
  s->closed = true;
  if (!s->writing) discarded += s->queue.size();
  boost::system::error_code ignored;
  s->socket.close(ignored);
  std::lock_guard lock(mutex);
  sessions.erase(s);
}

void AirSimEmulator::Impl::read(const std::shared_ptr<Session>& s) {
  s->socket.async_read_some(asio::buffer(s->buffer), [this, s](boost::system::error_code ec,
                                                               std::size_t n) {
    if (ec) {
      close(s);
      return;
    }
    if (s->unpacker.nonparsed_size() + n > kMaxFrame) {
      malformed(s, "a frame larger than 1 MiB");
      return;
    }
    s->unpacker.reserve_buffer(n);
    std::copy_n(s->buffer.data(), n, s->unpacker.buffer());
    s->unpacker.buffer_consumed(n);
    try {
      msgpack::object_handle message;
      while (!s->closed && s->unpacker.next(message)) on_frame(s, message.get());
    } catch (const std::exception& e) {
      malformed(s, std::string("undecodable msgpack (") + e.what() + ")");
      return;
    }
    if (!s->closed) read(s);
  });
}

void AirSimEmulator::Impl::malformed(const std::shared_ptr<Session>& s, const std::string& why) {
  {
    std::lock_guard lock(mutex);
    ++stats.malformed;
    stats.last_malformed = why;
  }
  close(s);
}

// I/O thread only.
void AirSimEmulator::Impl::write(const std::shared_ptr<Session>& s, std::string bytes) {
  if (s->closed) return;
  s->queue.push_back(std::move(bytes));
  if (s->writing) return;
  write_next(s);
}

void AirSimEmulator::Impl::write_next(const std::shared_ptr<Session>& s) {
  if (s->queue.empty() || s->closed) {
    s->writing = false;
    return;
  }
  s->writing = true;
  asio::async_write(s->socket, asio::buffer(s->queue.front()),
                    [this, s](boost::system::error_code ec, std::size_t) {
                      s->queue.pop_front();
                      if (ec) {
                        discarded += s->queue.size() + 1;
                        close(s);
                        return;
                      }
                      write_next(s);
                    });
}

void AirSimEmulator::Impl::respond_bool(const std::weak_ptr<Session>& s, std::uint32_t id, bool value) {
  respond(s, id, nullptr, [value](Packer& p) { p.pack(value); });
}

void AirSimEmulator::Impl::on_frame(const std::shared_ptr<Session>& s, const msgpack::object& o) {
  if (o.type != msgpack::type::ARRAY || o.via.array.size < 3) {
    malformed(s, "a frame that is not an msgpack-RPC array");
    return;
  }
  const auto* a = o.via.array.ptr;
  if (a[0].type == msgpack::type::POSITIVE_INTEGER && a[0].via.u64 == 2) return;  // notify
  const bool has_id = a[1].type == msgpack::type::POSITIVE_INTEGER && a[1].via.u64 <= 0xffffffffu;
  const auto id = has_id ? static_cast<std::uint32_t>(a[1].via.u64) : 0u;
  std::string why;
  if (o.via.array.size != 4) {
    why = "a request has 4 elements [0, msgid, method, params]";
  } else if (a[0].type != msgpack::type::POSITIVE_INTEGER || a[0].via.u64 != 0) {
    why = "type must be 0 (request)";
  } else if (!has_id) {
    why = "msgid must be an unsigned 32-bit integer";
  } else if (a[2].type != msgpack::type::STR) {
    why = "method must be a string";
  } else if (a[3].type != msgpack::type::ARRAY) {
    why = "params must be an array";
  }
  if (!why.empty()) {
    if (!has_id) {
      malformed(s, "malformed request: " + why);
      return;
    }
    {
      std::lock_guard lock(mutex);
      ++stats.malformed;
      stats.last_malformed = why;
    }
    const std::string error = "malformed request: " + why;
    respond(s, id, &error, [](Packer&) {});
    return;
  }
  const std::string method(a[2].via.str.ptr, a[2].via.str.size);
  host.with_sim([&](TwinSim& sim) {
    std::lock_guard lock(mutex);
    ++stats.requests;
    if (link_lost || sim.link_lost(sim.time_s())) {
      ++stats.dropped;
      return;
    }
    try {
      call_locked(sim, s, id, method, Args(method, a[3]));
    } catch (const CallError& e) {
      const std::string error = e.what();
      respond(s, id, &error, [](Packer&) {});
    }
  });
}


AirSimEmulator::AirSimEmulator(TwinHost& host, AirSimEmulatorOptions options)
    : impl_(std::make_shared<Impl>(host, std::move(options))) {
  impl_->start();
}

AirSimEmulator::~AirSimEmulator() { impl_->shutdown(); }

std::uint16_t AirSimEmulator::port() const { return impl_->acceptor.local_endpoint().port(); }

void AirSimEmulator::set_link_lost(bool lost) {
  std::lock_guard lock(impl_->mutex);
  impl_->link_lost = lost;
}

void AirSimEmulator::drop_connections() {
  auto impl = impl_;
  asio::post(impl->io, [impl] {
    std::set<std::shared_ptr<Impl::Session>> all;
    {
      std::lock_guard lock(impl->mutex);
      all = impl->sessions;
    }
    for (const auto& s : all) impl->close(s);
  });
}

AirSimEmulatorStats AirSimEmulator::stats() const {
  std::lock_guard lock(impl_->mutex);
  auto s = impl_->stats;
  s.responses = impl_->responses - impl_->discarded;
  return s;
}

}  // namespace gbdcs::sim
