// Scenario::from_json: the strict loader (scenarios/schema.json says the same in JSON Schema;
// tests/scenario checks that the two agree on every file of the suite). This part reads the
// document, its drone, camera and profile; events are read in event_loader.cpp, criteria in
// criteria_loader.cpp.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "gbdcs/contracts/codec.hpp"
#include "gbdcs/control/command_translator.hpp"
#include "gbdcs/sim/gesture_timeline.hpp"
#include "gbdcs/sim/scenario.hpp"
#include "gbdcs/telemetry/failsafe_monitor.hpp"
#include "json_fields.hpp"
#include "loader_parts.hpp"

namespace gbdcs::sim {

using detail::Fields;
using detail::find_in;
using detail::join;
using detail::name_in;
using detail::names_of;
using detail::read_criterion;
using detail::read_event;

namespace {

namespace fs = std::filesystem;

constexpr std::array<std::pair<DroneKind, std::string_view>, 5> kDrones{{
    {DroneKind::kTwin, "twin"},
    {DroneKind::kDummy, "dummy"},
    {DroneKind::kTelloEmulator, "tello-emulator"},
    {DroneKind::kAirsimEmulator, "airsim-emulator"},
    {DroneKind::kXflyEmulator, "xfly-emulator"},
}};

std::string read_text(const std::string& path, const std::string& what) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ScenarioError(what + ": cannot read '" + path + "' (check the path)");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

nlohmann::json read_json(const std::string& path, const std::string& what) {
  const auto text = read_text(path, what);
  try {
    return contracts::parse_json(text);
  } catch (const std::exception& e) {
    throw ScenarioError(what + ": '" + path + "' is not valid JSON: " + e.what());
  }
}

std::string resolve(const std::string& base_dir, const std::string& p) {
  fs::path path(p);
  if (path.is_absolute()) return path.lexically_normal().string();
  return (fs::path(base_dir) / path).lexically_normal().string();
}

DroneSpec read_drone(Fields& f) {
  DroneSpec d;
  const auto& v = f.get("drone");
  auto parse_kind = [&](const std::string& name, const std::string& key) {
    auto k = find_in(kDrones, name);
    if (!k) f.fail(key, "unknown drone '" + name + "'; use one of: " + join(names_of(kDrones)));
    return *k;
  };
  if (v.is_string()) {
    d.kind = parse_kind(v.get<std::string>(), "drone");
    return d;
  }
  Fields g(v, f.origin(), f.field("drone"));
  d.kind = parse_kind(g.string("type"), "drone.type");
  if (g.has("options")) {
    d.options = g.get("options");
    if (!d.options.is_object()) g.fail("options", "must be an object of the adapter's options");
  }
  g.finish("the drone");
  return d;
}

CameraSpec read_camera(Fields& f, const std::string& base_dir) {
  CameraSpec c;
  Fields g(f.get("camera"), f.origin(), f.field("camera"));
  const bool has_timeline = g.has("timeline");
  const bool has_timeline_file = g.has("timeline_file");
  const bool has_recipe = g.has("recipe");
  const bool has_video = g.has("video");
  const int kinds = int{has_timeline} + int{has_timeline_file} + int{has_recipe} + int{has_video};
  if (kinds != 1) {
    g.fail("", "give exactly one of timeline (inline), timeline_file, recipe or video");
  }
  if (has_timeline || has_timeline_file) {
    c.kind = CameraKind::kTimeline;
    if (has_timeline) {
      c.timeline = g.get("timeline");
    } else {
      c.path = resolve(base_dir, g.string("timeline_file"));
      c.timeline = read_json(c.path, g.origin() + ": " + g.field("timeline_file"));
    }
    try {
      (void)GestureTimeline::from_json(c.timeline);
    } catch (const std::exception& e) {
      g.fail(has_timeline ? "timeline" : "timeline_file", e.what());
    }
  } else if (has_recipe) {
    c.kind = CameraKind::kRecipe;
    c.path = resolve(base_dir, g.string("recipe"));
    if (!fs::is_regular_file(c.path)) {
      g.fail("recipe", "no such file '" + c.path +
                           "'; give the path of a fixture recipe (fixtures/recipes/*.json, "
                           "docs/FIXTURES.md), relative to the scenario file");
    }
  } else {
    c.kind = CameraKind::kRecorded;
    c.path = resolve(base_dir, g.string("video"));
    if (!fs::is_regular_file(c.path)) {
      g.fail("video", "no such file '" + c.path +
                          "'; give the video.mp4 of a recorded fixture folder (`gbdcs fixture "
                          "record` or `gbdcs fixture render`), relative to the scenario file");
    }
    if (!g.has("labels")) {
      g.fail("labels", "missing; a video needs the labels.json of its fixture folder (the "
                       "segment truth the criteria are judged against)");
    }
    c.labels_path = resolve(base_dir, g.string("labels"));
    if (!fs::is_regular_file(c.labels_path)) {
      g.fail("labels", "no such file '" + c.labels_path +
                           "'; give the labels.json beside the video, relative to the scenario "
                           "file");
    }
    c.fps = g.opt_number("fps", 1, 240).value_or(0);
  }
  if (c.kind != CameraKind::kRecorded) {
    if (g.has("labels")) g.fail("labels", "only a recorded video takes labels");
  }
  g.finish("the camera");
  return c;
}

nlohmann::json read_profile(Fields& f, const std::string& base_dir) {
  nlohmann::json doc;
  std::string key = "profile";
  if (!f.has("profile")) return control::GestureProfile::builtin_default().to_json();
  const auto& v = f.get("profile");
  if (v.is_string()) {
    const auto s = v.get<std::string>();
    if (s == "default") return control::GestureProfile::builtin_default().to_json();
    doc = read_json(resolve(base_dir, s), f.origin() + ": profile");
  } else if (v.is_object()) {
    doc = v;
  } else {
    f.fail(key, "must be \"default\", a profile file's path or a profile object");
  }
  try {
    (void)control::GestureProfile::from_json(doc);
  } catch (const std::exception& e) {
    f.fail(key, e.what());
  }
  return doc;
}

}  // namespace

std::string_view to_string(DroneKind k) { return name_in(kDrones, k); }
std::optional<DroneKind> drone_kind_from_string(std::string_view s) { return find_in(kDrones, s); }
std::string_view to_string(CameraKind k) {
  switch (k) {
    case CameraKind::kTimeline: return "timeline";
    case CameraKind::kRecipe: return "recipe";
    case CameraKind::kRecorded: return "video";
  }
  return "?";
}

Scenario Scenario::from_json(const nlohmann::json& doc, const std::string& base_dir,
                             const std::string& origin) {
  Fields f(doc, origin, "");
  Scenario s;
  f.has("$schema");
  s.name = f.string("name");
  if (s.name.empty() || s.name.find_first_of("/\\ \t") != std::string::npos) {
    f.fail("name", "must be a non-empty identifier without spaces or slashes (it names the "
                   "report's folder and the JUnit test)");
  }
  s.description = f.string("description");
  s.timeout_s = f.number("timeout_s", 0.1, 3600);
  s.drone = read_drone(f);
  s.camera = read_camera(f, base_dir);
  s.profile = read_profile(f, base_dir);
  if (f.has("failsafe")) {
    s.failsafe = f.get("failsafe");
    try {
      (void)telemetry::FailsafeOptions::from_json(s.failsafe);
    } catch (const std::exception& e) {
      f.fail("failsafe", e.what());
    }
  } else {
    s.failsafe = nlohmann::json::object();
  }
  if (f.has("events")) {
    const auto& events = f.get("events");
    if (!events.is_array()) f.fail("events", "must be an array of timed events");
    for (std::size_t i = 0; i < events.size(); ++i) {
      s.events.push_back(
          read_event(events[i], origin, "events[" + std::to_string(i) + "]", s.timeout_s));
    }
    std::stable_sort(s.events.begin(), s.events.end(),
                     [](const auto& a, const auto& b) { return a.at_s < b.at_s; });
  }
  const auto& criteria = f.get("criteria");
  if (!criteria.is_array() || criteria.empty()) {
    f.fail("criteria", "must be a non-empty array: a scenario without criteria checks nothing");
  }
  for (std::size_t i = 0; i < criteria.size(); ++i) {
    s.criteria.push_back(
        read_criterion(criteria[i], origin, "criteria[" + std::to_string(i) + "]", i, s));
  }
  for (std::size_t i = 0; i < s.criteria.size(); ++i) {
    for (std::size_t j = 0; j < i; ++j) {
      if (s.criteria[i].name == s.criteria[j].name) {
        f.fail("criteria[" + std::to_string(i) + "].name",
               "'" + s.criteria[i].name + "' is used twice; give each criterion its own name");
      }
    }
  }
  f.finish("a scenario");
  return s;
}

Scenario Scenario::load_file(const std::string& path) {
  const auto doc = read_json(path, path);
  auto base = fs::path(path).parent_path().string();
  if (base.empty()) base = ".";
  auto s = from_json(doc, base, path);
  s.path = path;
  return s;
}

std::vector<std::string> scenario_files(const std::string& path) {
  std::error_code ec;
  if (fs::is_regular_file(path, ec)) return {path};
  if (!fs::is_directory(path, ec)) {
    throw ScenarioError(path + ": no such scenario file or folder");
  }
  std::vector<std::string> out;
  for (const auto& entry : fs::directory_iterator(path)) {
    if (!entry.is_regular_file() || entry.path().extension() != ".json") continue;
    if (entry.path().filename() == "schema.json") continue;
    out.push_back(entry.path().string());
  }
  std::sort(out.begin(), out.end());
  if (out.empty()) throw ScenarioError(path + ": no scenario files (*.json) in this folder");
  return out;
}

}  // namespace gbdcs::sim
