#include "ws_publisher.hpp"

#include <utility>  // before Asio: its awaitable.hpp needs std::exchange
#include <boost/asio.hpp>
#include <boost/beast.hpp>
#include <boost/beast/websocket.hpp>
#include <mutex>
#include <regex>
#include <stdexcept>

namespace gbdcs::app {

namespace beast = boost::beast;
namespace websocket = beast::websocket;
namespace net = boost::asio;
using tcp = net::ip::tcp;

struct WsPublisher::Impl {
  net::io_context ioc;
  websocket::stream<beast::tcp_stream> ws{ioc};
  std::mutex mutex;
};

WsPublisher::WsPublisher(const std::string& url) : impl_(std::make_unique<Impl>()) {
  static const std::regex kUrl(R"(^ws://([^/:]+):([0-9]{1,5})(/[^ ]*)$)");
  std::smatch m;
  if (!std::regex_match(url, m, kUrl)) {
    throw std::runtime_error("--publish " + url +
                             " is not ws://HOST:PORT/PATH (e.g. ws://127.0.0.1:8000/worker?secret=S)");
  }
  try {
    tcp::resolver resolver(impl_->ioc);
    auto& layer = beast::get_lowest_layer(impl_->ws);
    layer.connect(resolver.resolve(m[1].str(), m[2].str()));
    layer.socket().set_option(tcp::no_delay(true));
    impl_->ws.handshake(m[1].str() + ":" + m[2].str(), m[3].str());
    impl_->ws.text(true);
  } catch (const std::exception& e) {
    throw std::runtime_error("cannot publish to " + m[1].str() + ":" + m[2].str() + ": " + e.what() +
                             " (is gbdcs serve running, and is the secret right?)");
  }
}

WsPublisher::~WsPublisher() {
  beast::error_code ec;
  impl_->ws.close(websocket::close_code::normal, ec);
}

void WsPublisher::send(const std::string& text) {
  std::lock_guard lock(impl_->mutex);
  beast::error_code ec;
  impl_->ws.write(net::buffer(text), ec);
  if (ec) throw std::runtime_error("the server closed the connection: " + ec.message());
}

}  // namespace gbdcs::app
