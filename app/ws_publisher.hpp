// WsPublisher: the vision worker's side of INTERFACES.md section 2. Connects to
// ws://HOST:PORT/PATH?QUERY (the server's /worker with its per-run secret) and sends each
// message as one WebSocket text message. send() is thread-safe and throws
// std::runtime_error when the connection is gone (the worker then exits and the server's
// supervisor restarts it).
#pragma once

#include <memory>
#include <string>

namespace gbdcs::app {

class WsPublisher {
 public:
  explicit WsPublisher(const std::string& url);  // throws std::runtime_error
  ~WsPublisher();
  void send(const std::string& text);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace gbdcs::app
