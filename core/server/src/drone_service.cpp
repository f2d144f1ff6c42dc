#include "gbdcs/server/drone_service.hpp"

#include "gbdcs/contracts/codec.hpp"
#include "gbdcs/server/auth.hpp"
#include "gbdcs/control/keyboard_input.hpp"
#include "gbdcs/gesture/gesture_engine.hpp"
#include "gbdcs/gesture/rule_based_recognizer.hpp"

namespace gbdcs::server {

using nlohmann::json;

namespace {

// Records and broadcasts what the control loop does; alerts go to storage first so the id
// the dashboard acknowledges is the stored one.
class Recorder final : public runtime::EventListener {
 public:
  Recorder(storage::StorageManager& storage, std::int64_t session, LiveHub& hub, EventLog log,
           std::vector<std::shared_ptr<runtime::EventListener>> extra)
      : storage_(storage), session_(session), hub_(hub), log_(std::move(log)),
        extra_(std::move(extra)) {}
  void on_gesture(const contracts::GestureEvent& e) override {
    storage_.log_gesture(session_, e);
    hub_.broadcast("gesture", contracts::to_json(e));
    for (auto& l : extra_) l->on_gesture(e);
  }
  void on_command(const contracts::DroneCommand& c, const std::string& outcome) override {
    storage_.log_command(session_, c, outcome);
    hub_.broadcast("command", {{"command", contracts::to_json(c)}, {"outcome", outcome}});
    if (log_) {
      log_(outcome == "OK" ? "info" : "warn",
           {{"event", "command"}, {"session_id", session_}, {"command", contracts::to_json(c)},
            {"outcome", outcome}});
    }
    for (auto& l : extra_) l->on_command(c, outcome);
  }
  void on_alert(const contracts::Alert& a) override {
    auto alert = a;
    if (auto r = storage_.log_alert(session_, a)) alert.id = r.row_id;
    hub_.broadcast("alert", contracts::to_json(alert));
    if (log_) {
      log_(alert.severity == contracts::Severity::kCritical ? "error" : "warn",
           {{"event", "alert"}, {"session_id", session_}, {"alert", contracts::to_json(alert)}});
    }
    for (auto& l : extra_) l->on_alert(alert);
  }
  void on_telemetry(const contracts::TelemetryFrame& f) override {
    storage_.log_telemetry(session_, f);
    hub_.broadcast("telemetry", contracts::to_json(f));
    for (auto& l : extra_) l->on_telemetry(f);
  }

 private:
  storage::StorageManager& storage_;
  std::int64_t session_;
  LiveHub& hub_;
  EventLog log_;
  std::vector<std::shared_ptr<runtime::EventListener>> extra_;
};

std::optional<contracts::Landmarks> best_hand(const json& hands) {
  if (!hands.is_array() || hands.empty()) return std::nullopt;
  const json* best = nullptr;
  for (const auto& h : hands) {
    if (!best || h.value("score", 0.0) > best->value("score", 0.0)) best = &h;
  }
  contracts::Landmarks l;
  const auto& points = best->at("landmarks");
  for (std::size_t i = 0; i < contracts::kLandmarkCount; ++i) {
    l.points[i] = {points.at(i).at(0).get<double>(), points.at(i).at(1).get<double>(),
                   points.at(i).at(2).get<double>()};
  }
  l.handedness = contracts::handedness_from_string(best->value("handedness", "Right"))
                     .value_or(contracts::Handedness::kRight);
  l.score = best->value("score", 0.0);
  return l;
}

}  // namespace

struct DroneService::Active {
  std::unique_ptr<control::DroneAdapter> adapter;
  std::unique_ptr<gesture::GestureEngine> engine;
  std::unique_ptr<control::CommandTranslator> translator;
  std::unique_ptr<runtime::ControlLoop> loop;
  std::int64_t session = 0;
  std::string name;
  control::DroneViewSource* view = nullptr;  // the adapter, when it sends drone_view pictures
};

DroneService::DroneService(const contracts::Clock& clock, storage::StorageManager& storage,
                           LiveHub& hub, DroneFactory factory, control::GestureProfile profile,
                           EventLog log, DroneServiceOptions options)
    : clock_(clock), storage_(storage), hub_(hub), factory_(std::move(factory)),
      log_(std::move(log)), options_(options), profile_(std::move(profile)) {
  ticker_ = std::thread([this] { tick_loop(); });
}

DroneService::~DroneService() {
  running_ = false;
  if (ticker_.joinable()) ticker_.join();
  disconnect();
}

void DroneService::end_session_quietly(std::int64_t session) {
  if (session == 0) return;
  try {
    storage_.end_session(session);
  } catch (const std::exception& e) {
    // Shutting down or swapping with a full disk: the row stays open and the next start's
    // end_open_sessions() closes it at its last logged row.
    if (log_) log_("warn", {{"event", "session_end_not_recorded"}, {"session_id", session},
                            {"cause", e.what()}});
  }
}

void DroneService::stop_active_locked() {
  if (!active_) return;
  auto& a = *active_;
  if (a.view) a.view->stop_view();  // no picture of a drone we let go
  const auto state = a.adapter->state();
  if (state == contracts::FlightState::kFlying) {
    // Never leave a drone in the air without an operator: land before letting go.
    contracts::DroneCommand land;
    land.type = contracts::CommandType::kLand;
    land.source = contracts::CommandSource::kApi;
    land.source_id = "ADAPTER_SWAP";
    a.loop->submit(land);
    a.loop->tick();
  }
  a.loop->telemetry().drain(std::chrono::milliseconds(500));
  a.loop->stop();
  end_session_quietly(a.session);
  if (log_) log_("info", {{"event", "drone_disconnected"}, {"adapter", a.name},
                          {"session_id", a.session}});
  active_.reset();
}

std::string DroneService::check_adapter(const std::string& name, const json& options) const {
  try {
    factory_(name, options.is_object() ? options : json::object());
  } catch (const std::invalid_argument& e) {
    return std::string("cannot create the '") + name + "' drone: " + e.what();
  } catch (const std::exception&) {
    // Not the options' fault (a socket in use, say): connect() reports it if it lasts.
  }
  return {};
}

std::string DroneService::connect(const std::string& name, const json& options) {
  std::unique_lock lock(active_mutex_);
  stop_active_locked();
  adapter_name_ = name;
  adapter_options_ = options.is_object() ? options : json::object();
  auto a = std::make_unique<Active>();
  a->name = name;
  try {
    a->adapter = factory_(name, adapter_options_);
  } catch (const std::exception& e) {
    lock.unlock();
    publish_state();
    return std::string("cannot create the '") + name + "' drone: " + e.what();
  }
  a->engine = std::make_unique<gesture::GestureEngine>(
      clock_, std::make_unique<gesture::RuleBasedRecognizer>());
  a->translator = std::make_unique<control::CommandTranslator>(profile_);
  a->loop = std::make_unique<runtime::ControlLoop>(clock_, *a->adapter, *a->engine,
                                                   *a->translator, options_.loop);
  try {
    a->session = storage_.begin_session(std::nullopt, name, profile_.name);
  } catch (const std::exception& e) {
    // A full disk must not ground the drone: fly unrecorded (session 0, every log_* fails and
    // is counted; watch_storage raises the alert that says so).
    a->session = 0;
    if (log_) log_("error", {{"event", "session_not_recorded"}, {"cause", e.what()}});
  }
  std::vector<std::shared_ptr<runtime::EventListener>> extra;
  {
    std::lock_guard s(status_mutex_);
    extra = extra_listeners_;
  }
  a->loop->add_listener(std::make_shared<Recorder>(storage_, a->session, hub_, log_, extra));
  const auto result = a->loop->start();
  if (result != control::Result::kOk) {
    const std::string why = std::string(control::to_string(result)) + " " + a->adapter->last_error();
    end_session_quietly(a->session);
    lock.unlock();
    publish_state();
    return "cannot connect to the '" + name + "' drone: " + why;
  }
  bool healthy;
  std::string reason;
  {
    std::lock_guard s(status_mutex_);
    healthy = vision_healthy_;
    reason = vision_reason_;
  }
  if (!healthy) a->loop->on_vision_health(false, reason);
  auto* view_source = dynamic_cast<control::DroneViewSource*>(a->adapter.get());
  if (view_source && options_.view.fps > 0) {
    // The drone's own picture (the twin's chase camera), rendered on the adapter's thread at a
    // low rate; sent only while somebody watches.
    LiveHub* hub = &hub_;
    const auto started = view_source->start_view(options_.view, [hub](const control::DroneView& v) {
      if (hub->client_count() == 0) return;
      hub->broadcast("drone_view", {{"frame_id", v.frame_id},
                                    {"camera", v.camera},
                                    {"width", v.width},
                                    {"height", v.height},
                                    {"jpeg", base64_encode(v.jpeg)}});
    });
    if (started == control::Result::kOk) {
      a->view = view_source;
    } else if (log_) {
      log_("warn", {{"event", "drone_view_unavailable"}, {"cause", a->adapter->last_error()}});
    }
  }
  if (log_) log_("info", {{"event", "drone_connected"}, {"adapter", name},
                          {"session_id", a->session}, {"drone_view", a->view != nullptr}});
  active_ = std::move(a);
  lock.unlock();
  publish_state();
  return {};
}

void DroneService::disconnect() {
  {
    std::unique_lock lock(active_mutex_);
    stop_active_locked();
  }
}

void DroneService::on_vision_frame(const json& msg) {
  std::optional<contracts::Landmarks> hand;
  try {
    hand = best_hand(msg.at("hands"));
  } catch (const std::exception&) {
    return;  // validated by the caller; a malformed hand is no hand
  }
  std::shared_lock lock(active_mutex_);
  if (active_) active_->loop->on_frame(hand, msg.value("frame_id", std::int64_t{0}));
}

void DroneService::on_vision_health(bool healthy, const std::string& reason) {
  bool changed;
  {
    std::lock_guard s(status_mutex_);
    changed = healthy != vision_healthy_ || reason != vision_reason_;  // both are shown
    vision_healthy_ = healthy;
    vision_reason_ = reason;
  }
  {
    std::shared_lock lock(active_mutex_);
    if (active_) active_->loop->on_vision_health(healthy, reason);
  }
  if (changed) publish_state();
}

void DroneService::raise_alert(contracts::Alert alert) {
  if (alert.timestamp == contracts::UtcTime{}) alert.timestamp = clock_.utc_now();
  std::shared_lock lock(active_mutex_);
  if (active_) {
    if (auto r = storage_.log_alert(active_->session, alert)) alert.id = r.row_id;
  }
  hub_.broadcast("alert", contracts::to_json(alert));
  if (log_) {
    log_(alert.severity == contracts::Severity::kCritical ? "error" : "warn",
         {{"event", "alert"}, {"alert", contracts::to_json(alert)}});
  }
  std::vector<std::shared_ptr<runtime::EventListener>> extra;
  {
    std::lock_guard s(status_mutex_);
    extra = extra_listeners_;
  }
  for (auto& l : extra) l->on_alert(alert);
}

control::Decision DroneService::emergency_stop(contracts::CommandSource source,
                                               const std::string& source_id) {
  control::Decision d;
  {
    std::shared_lock lock(active_mutex_);
    if (active_) d = active_->loop->emergency_stop(source, source_id);
    else d.reason = "no drone is connected";
  }
  if (log_) log_("error", {{"event", "emergency_stop"}, {"source", contracts::to_string(source)},
                           {"source_id", source_id}, {"accepted", d.accepted},
                           {"reason", d.reason}});
  publish_state();
  return d;
}

void DroneService::reset_emergency() {
  {
    std::shared_lock lock(active_mutex_);
    if (active_) active_->loop->reset_emergency();
  }
  if (log_) log_("warn", {{"event", "emergency_reset"}});
  publish_state();
}

bool DroneService::emergency_latched() const {
  std::shared_lock lock(active_mutex_);
  return active_ && active_->loop->arbiter().emergency_latched();
}

std::string DroneService::key(const std::string& k, bool pressed) {
  static const control::KeyboardInput keyboard;
  auto command = keyboard.command_for(k);
  if (!command) return {};
  if (command->type == contracts::CommandType::kEmergencyStop) {
    if (pressed) emergency_stop(contracts::CommandSource::kKeyboard, "key");
    return "EMERGENCY_STOP";
  }
  if (!pressed) {
    // Releasing a movement key stops the movement.
    if (command->type != contracts::CommandType::kMove) return "ignored";
    contracts::DroneCommand hover;
    hover.type = contracts::CommandType::kHover;
    hover.source = contracts::CommandSource::kKeyboard;
    hover.source_id = k;
    command = hover;
  }
  auto d = submit(*command);
  if (!d) return "no drone is connected";
  return d->accepted ? "accepted" : "refused: " + d->reason;
}

std::optional<control::Decision> DroneService::submit(contracts::DroneCommand command) {
  std::shared_lock lock(active_mutex_);
  if (!active_) return std::nullopt;
  return active_->loop->submit(std::move(command));
}

json DroneService::state() const {
  json j;
  {
    std::shared_lock lock(active_mutex_);
    j["adapter"] = adapter_name_;
    j["connected"] = active_ != nullptr;
    j["session_id"] = active_ && active_->session > 0 ? json(active_->session) : json(nullptr);
    auto t = active_ ? active_->loop->latest_telemetry() : std::nullopt;
    j["flight_state"] = std::string(contracts::to_string(
        t ? t->flight_state : (active_ ? active_->adapter->state() : contracts::FlightState::kInit)));
    j["emergency_latched"] = active_ && active_->loop->arbiter().emergency_latched();
    j["vision"]["ready"] = active_ && active_->loop->vision_ready();
    j["drone_view"] = active_ && active_->view != nullptr;
  }
  std::lock_guard s(status_mutex_);
  j["vision"]["healthy"] = vision_healthy_;
  j["vision"]["reason"] = vision_reason_;
  j["vision"]["fps"] = vision_status_.fps;
  j["vision"]["source"] = vision_status_.source;
  j["vision"]["worker_running"] = vision_status_.worker_running;
  j["vision"]["worker_restarts"] = vision_status_.worker_restarts;
  j["clients"] = hub_.client_count();
  j["replay"] = nullptr;
  return j;
}

void DroneService::set_vision_status(const VisionStatus& status) {
  std::lock_guard s(status_mutex_);
  vision_status_ = status;
}

control::GestureProfile DroneService::profile() const {
  std::shared_lock lock(active_mutex_);
  return profile_;
}

void DroneService::set_profile(control::GestureProfile profile) {
  std::unique_lock lock(active_mutex_);
  profile_ = std::move(profile);
  if (active_) active_->translator->set_profile(profile_);
}

std::string DroneService::adapter_name() const {
  std::shared_lock lock(active_mutex_);
  return adapter_name_;
}

json DroneService::adapter_options() const {
  std::shared_lock lock(active_mutex_);
  return adapter_options_;
}

std::optional<std::int64_t> DroneService::session_id() const {
  std::shared_lock lock(active_mutex_);
  if (!active_) return std::nullopt;
  return active_->session;
}

bool DroneService::connected() const {
  std::shared_lock lock(active_mutex_);
  return active_ != nullptr;
}

void DroneService::add_listener(std::shared_ptr<runtime::EventListener> listener) {
  std::lock_guard s(status_mutex_);
  extra_listeners_.push_back(std::move(listener));
}

void DroneService::publish_state() {
  auto s = state();
  {
    std::lock_guard lock(status_mutex_);
    last_state_ = s.dump();
  }
  hub_.broadcast("state", s);
}

void DroneService::tick_loop() {
  const auto state_every = contracts::from_seconds(options_.state_every_s);
  auto next_state = clock_.now();
  std::string previous;
  while (running_) {
    {
      std::shared_lock lock(active_mutex_);
      if (active_) active_->loop->tick();
    }
    hub_.close_expired();
    watch_storage();
    const auto now = clock_.now();
    if (now >= next_state) {
      publish_state();
      next_state = now + state_every;
    }
    std::this_thread::sleep_for(contracts::from_seconds(options_.tick_s));
  }
}

void DroneService::watch_storage() {
  const auto health = storage_.write_health();
  const auto now = clock_.now();
  if (health.episodes > storage_episodes_seen_) {
    // A new failing episode (it may already be over: a single failed write counts too).
    storage_episodes_seen_ = health.episodes;
    storage_failing_ = true;
    storage_next_log_ = now + std::chrono::seconds(10);
    contracts::Alert a;
    a.severity = contracts::Severity::kWarning;
    a.code = health.disk_full ? "STORAGE_DISK_FULL" : "STORAGE_WRITE_FAILING";
    a.cause = health.error.substr(0, 500);
    a.suggestion = (health.suggestion.empty()
                        ? std::string("check the server log for the cause; flying goes on, but "
                                      "nothing is recorded until a write succeeds again")
                        : health.suggestion)
                       .substr(0, 500);
    if (log_) {
      log_("error", {{"event", "storage_failing"}, {"cause", health.error},
                     {"suggestion", a.suggestion}, {"disk_full", health.disk_full}});
    }
    raise_alert(a);  // cannot be stored while writes fail: broadcast with id 0
  } else if (storage_failing_ && !health.ok && now >= storage_next_log_) {
    storage_next_log_ = now + std::chrono::seconds(10);
    if (log_) {
      log_("error", {{"event", "storage_still_failing"}, {"cause", health.error},
                     {"failed_writes", health.episode_failures},
                     {"suggestion", health.suggestion}});
    }
  }
  if (storage_failing_ && health.ok) {
    storage_failing_ = false;
    contracts::Alert a;
    a.severity = contracts::Severity::kInfo;
    a.code = "STORAGE_RECOVERED";
    a.cause = "database writes succeed again after " + std::to_string(health.episode_failures) +
              " failed writes (those rows are missing from the record)";
    a.suggestion = "nothing to do; keep an eye on free disk space";
    if (log_) {
      log_("info", {{"event", "storage_recovered"}, {"failed_writes", health.episode_failures}});
    }
    raise_alert(a);
  }
}

}  // namespace gbdcs::server
