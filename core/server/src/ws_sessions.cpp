// The WebSocket sessions: /ws/live (a dashboard client, fed by LiveHub through its bounded
// queue; it may send ack, input and emergency_stop) and /worker (the vision worker's results).
#include "gbdcs/contracts/codec.hpp"
#include "server_impl.hpp"

namespace gbdcs::server {

using nlohmann::json;

namespace {

using Request = http::request<http::string_body>;

// ---- /ws/live ---------------------------------------------------------------------------
class LiveSession final : public LiveClient, public std::enable_shared_from_this<LiveSession> {
 public:
  LiveSession(tcp::socket socket, Server::Impl& impl, TokenClaims claims)
      : ws_(std::move(socket)), impl_(impl), claims_(std::move(claims)) {}

  void start(Request req) {
    ws_.set_option(websocket::stream_base::timeout::suggested(beast::role_type::server));
    ws_.read_message_max(impl_.options.max_ws_message_bytes);
    ws_.async_accept(req, [self = shared_from_this()](beast::error_code ec) {
      if (ec) return;
      self->impl_.hub.add(self);
      self->deliver(self->impl_.hub.make("state", self->impl_.drone.state()));
      self->read();
    });
  }

  void deliver(const OutMessagePtr& m) override {
    bool start_write = false, too_slow = false;
    {
      std::lock_guard lock(mutex_);
      if (closed_) return;
      too_slow = !queue_.push(m);
      if (!writing_) start_write = writing_ = true;
    }
    if (too_slow) close_with(1008, "client too slow: alerts backed up");
    if (start_write) net::post(ws_.get_executor(), [self = shared_from_this()] { self->write_next(); });
  }

  void close_with(int code, const std::string& reason) override {
    net::post(ws_.get_executor(), [self = shared_from_this(), code, reason] {
      if (self->closing_) return;
      self->closing_ = true;
      self->ws_.async_close(websocket::close_reason(static_cast<websocket::close_code>(code), reason),
                            [self](beast::error_code) { self->finish(); });
    });
  }
  const std::string& token_id() const override { return claims_.jti; }
  contracts::UtcTime token_expires() const override { return claims_.expires_at; }
  std::uint64_t dropped() const override {
    std::lock_guard lock(mutex_);
    return queue_.dropped();
  }
  std::size_t queued() const override {
    std::lock_guard lock(mutex_);
    return queue_.size();
  }

 private:
  void finish() {
    {
      std::lock_guard lock(mutex_);
      closed_ = true;
    }
    impl_.hub.remove(this);
  }

  void write_next() {
    {
      std::lock_guard lock(mutex_);
      auto next = queue_.pop();
      if (!next || closed_) {
        writing_ = false;
        return;
      }
      current_ = *next;
    }
    ws_.text(true);
    ws_.async_write(net::buffer(current_->text),
                    [self = shared_from_this()](beast::error_code ec, std::size_t) {
                      if (ec) {
                        self->finish();
                        std::lock_guard lock(self->mutex_);
                        self->writing_ = false;
                        return;
                      }
                      self->impl_.metrics.ws_delivery_ms.observe(
                          contracts::to_seconds(self->impl_.clock.now() - self->current_->enqueued) *
                          1000.0);
                      self->write_next();
                    });
  }

  void read() {
    ws_.async_read(buffer_, [self = shared_from_this()](beast::error_code ec, std::size_t) {
      if (ec) {
        self->finish();
        return;
      }
      std::string text = beast::buffers_to_string(self->buffer_.data());
      self->buffer_.consume(self->buffer_.size());
      self->on_message(text);
      self->read();
    });
  }

  void reply_error(const std::string& code, const std::string& cause, const std::string& suggestion) {
    deliver(impl_.hub.make("error", {{"error", code}, {"cause", cause},
                                     {"suggestion", suggestion}, {"request_id", impl_.ids.next()}}));
  }

  void on_message(const std::string& text) {
    json doc;
    try {
      doc = contracts::parse_json(text);
    } catch (const std::exception& e) {
      return reply_error("malformed_json", e.what(), "send one JSON object per message");
    }
    const std::string type = doc.is_object() && doc.contains("type") && doc["type"].is_string()
                                 ? doc["type"].get<std::string>() : "";
    std::string schema;
    if (type == "ack") schema = "ws_ack";
    else if (type == "input") schema = "ws_input";
    else if (type == "emergency_stop") schema = "ws_emergency_stop";
    else return reply_error("invalid_message", "unknown message type '" + type.substr(0, 40) + "'",
                            "send type ack, input or emergency_stop (docs/API.md)");
    try {
      contracts::validate(schema, doc);
    } catch (const contracts::ContractError& e) {
      return reply_error("invalid_message", e.what(),
                         "see core/contracts/schemas/" + schema + ".schema.json");
    }
    if (type == "emergency_stop") {
      impl_.drone.emergency_stop(contracts::CommandSource::kApi,
                                 "ws:user:" + std::to_string(claims_.user_id));
    } else if (type == "input") {
      impl_.drone.key(doc["key"].get<std::string>(), doc["pressed"].get<bool>());
    } else {
      const auto id = doc["alert_id"].get<std::int64_t>();
      if (!impl_.storage.acknowledge_alert_by(id, claims_.user_id)) {
        return reply_error("not_found", "there is no alert " + std::to_string(id),
                           "acknowledge the data.id of an alert message");
      }
      auto a = impl_.storage.find_alert(id);
      if (impl_.log) impl_.log("info", {{"event", "alert_ack"}, {"alert_id", id},
                                        {"user_id", claims_.user_id}});
      deliver(impl_.hub.make(
          "ack_result", {{"alert_id", id},
                         {"acknowledged_at", contracts::format_utc(a && a->acknowledged_at
                                                                        ? *a->acknowledged_at
                                                                        : impl_.clock.utc_now())}}));
    }
  }

  websocket::stream<beast::tcp_stream> ws_;
  Server::Impl& impl_;
  TokenClaims claims_;
  beast::flat_buffer buffer_;
  mutable std::mutex mutex_;
  ClientQueue queue_;
  bool writing_ = false;
  bool closed_ = false;
  bool closing_ = false;
  OutMessagePtr current_;
};

// ---- /worker ----------------------------------------------------------------------------
class WorkerSession final : public std::enable_shared_from_this<WorkerSession> {
 public:
  WorkerSession(tcp::socket socket, Server::Impl& impl) : ws_(std::move(socket)), impl_(impl) {}
  void start(Request req) {
    ws_.read_message_max(8 << 20);  // frames carry a JPEG
    ws_.async_accept(req, [self = shared_from_this()](beast::error_code ec) {
      if (ec) return;
      WorkerHandlers h;
      {
        std::lock_guard lock(self->impl_.worker_mutex);
        h = self->impl_.worker;
      }
      if (h.connected) h.connected();
      self->read();
    });
  }

 private:
  void read() {
    ws_.async_read(buffer_, [self = shared_from_this()](beast::error_code ec, std::size_t) {
      WorkerHandlers h;
      {
        std::lock_guard lock(self->impl_.worker_mutex);
        h = self->impl_.worker;
      }
      if (ec) {
        if (h.closed) h.closed();
        return;
      }
      const auto text = beast::buffers_to_string(self->buffer_.data());
      self->buffer_.consume(self->buffer_.size());
      try {
        auto doc = contracts::parse_json(text);
        const auto type = doc.value("type", "");
        contracts::validate(type == "heartbeat"  ? "vision_heartbeat"
                            : type == "picture" ? "vision_picture"
                                                : "vision_frame",
                            doc);
        if (h.message) h.message(doc);
      } catch (const std::exception& e) {
        if (self->impl_.log) self->impl_.log("warn", {{"event", "worker_bad_message"}, {"cause", e.what()}});
      }
      self->read();
    });
  }
  websocket::stream<beast::tcp_stream> ws_;
  Server::Impl& impl_;
  beast::flat_buffer buffer_;
};

}  // namespace

void start_live_session(tcp::socket socket, Server::Impl& impl, TokenClaims claims, Request upgrade) {
  std::make_shared<LiveSession>(std::move(socket), impl, std::move(claims))->start(std::move(upgrade));
}

void start_worker_session(tcp::socket socket, Server::Impl& impl, Request upgrade) {
  std::make_shared<WorkerSession>(std::move(socket), impl)->start(std::move(upgrade));
}

}  // namespace gbdcs::server
