// The server's console log (spdlog): one line per HTTP request, command and safety event.
// json = true: one JSON object a line {"ts", "level", "event", ...}; otherwise
// "<ts> <level> <event> {fields}". Timestamps from the injected Clock (UTC).
#pragma once

#include "gbdcs/contracts/clock.hpp"
#include "gbdcs/server/drone_service.hpp"

namespace gbdcs::server {

EventLog make_event_log(const contracts::Clock& clock, bool json);

}  // namespace gbdcs::server
