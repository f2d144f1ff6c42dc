// The REST API without the transport: an ApiRequest in, an ApiResponse out. http_server.cpp
// does the sockets; this file's handlers (api_routes.cpp) do the work, so every route is
// plain code over the injected clock, the store, the token service and the drone.
#pragma once

#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "gbdcs/server/auth.hpp"
#include "gbdcs/server/drone_service.hpp"
#include "gbdcs/server/live_hub.hpp"
#include "gbdcs/server/metrics.hpp"
#include "gbdcs/server/server.hpp"
#include "replay.hpp"

namespace gbdcs::server {

struct ApiRequest {
  std::string method;
  std::string path;  // without the query
  std::map<std::string, std::string> query;
  std::string body;
  std::string content_type;
  std::string authorization;
  std::string remote;  // client address
  std::string request_id;
};

struct ApiResponse {
  int status = 200;
  std::string body;
  std::string content_type = "application/json";
  std::vector<std::pair<std::string, std::string>> headers;
  std::string log_detail;  // extra for the log line (the error's cause)
};

// Thrown by handlers; becomes the error envelope.
struct ApiError : std::runtime_error {
  ApiError(int status_, std::string code_, std::string cause_, std::string suggestion_,
           std::string field_ = {})
      : std::runtime_error(cause_), status(status_), code(std::move(code_)),
        cause(std::move(cause_)), suggestion(std::move(suggestion_)), field(std::move(field_)) {}
  int status;
  std::string code, cause, suggestion, field;
  std::vector<std::pair<std::string, std::string>> headers;
};

ApiResponse error_response(const ApiError& e, const std::string& request_id);
std::string_view reason_phrase(int status);

struct ApiContext {
  const contracts::Clock& clock;
  storage::StorageManager& storage;
  TokenService& tokens;
  DroneService& drone;
  LiveHub& hub;
  Metrics& metrics;
  ReplayManager& replays;
  LoginLimiter& limiter;
  const ServerOptions& options;
  EventLog log;
};

// The authenticated caller, or throws ApiError 401.
TokenClaims authenticate(ApiContext& ctx, std::string_view token);

// Dispatches to the route; throws ApiError for 4xx/5xx.
ApiResponse handle_api(ApiContext& ctx, const ApiRequest& request);

// The routes (method, path pattern with {id}) for the OpenAPI check.
std::vector<std::pair<std::string, std::string>> api_routes();
std::string_view openapi_document();

}  // namespace gbdcs::server
