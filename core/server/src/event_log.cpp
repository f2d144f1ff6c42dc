#include "gbdcs/server/event_log.hpp"

#include <spdlog/sinks/stdout_sinks.h>
#include <spdlog/spdlog.h>

#include "gbdcs/contracts/codec.hpp"

namespace gbdcs::server {

EventLog make_event_log(const contracts::Clock& clock, bool json) {
  auto logger = spdlog::get("gbdcs");
  if (!logger) {
    logger = spdlog::stdout_logger_mt("gbdcs");
    logger->set_pattern("%v");  // the timestamp comes from the injected clock
    logger->flush_on(spdlog::level::info);
  }
  return [&clock, json, logger](const std::string& level, const nlohmann::json& event) {
    const auto lvl = spdlog::level::from_str(level);
    const auto ts = contracts::format_utc(clock.utc_now());
    if (json) {
      nlohmann::json line = {{"ts", ts}, {"level", level}};
      line.update(event);
      logger->log(lvl, line.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
    } else {
      auto rest = event;
      const auto name = rest.value("event", "");
      rest.erase("event");
      logger->log(lvl, "{} {:5} {} {}", ts, level, name,
                  rest.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
    }
  };
}

}  // namespace gbdcs::server
