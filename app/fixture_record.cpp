// `gbdcs fixture record` (a person's own hand, prompted step by step) and `gbdcs fixture
// check` (validate a fixture folder). docs/FIXTURES.md.
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <opencv2/core/utils/logger.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <set>
#include <sstream>

#include "command_registry.hpp"
#include "commands.hpp"
#include "gbdcs/contracts/codec.hpp"
#include "gbdcs/sim/recipe.hpp"
#include "gbdcs/sim/video_recorder.hpp"
#include "source_factory.hpp"

namespace gbdcs::app {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

json read_json_doc(const fs::path& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path.string() + ": cannot read (check the path)");
  std::stringstream s;
  s << in.rdbuf();
  try {
    return contracts::parse_json(s.str());
  } catch (const std::exception& e) {
    throw std::runtime_error(path.string() + ": " + e.what());
  }
}

// ---- the recording script -----------------------------------------------------------------
struct Step {
  std::string show;  // a pose name or NO_HAND
  double duration_s = 3;
  std::string prompt;
};
struct Script {
  std::string name;
  double countdown_s = 3;
  std::vector<Step> steps;
};

Script load_script(const fs::path& path) {
  const json doc = read_json_doc(path);
  const std::string src = path.string();
  auto fail = [&](const std::string& field, const std::string& problem) {
    throw std::runtime_error(src + ": " + field + " " + problem);
  };
  if (!doc.is_object()) fail("the document", "must be a JSON object");
  Script s;
  for (const auto& [key, value] : doc.items()) {
    if (key == "name") {
      if (!value.is_string()) fail("name", "must be a string");
      s.name = value;
    } else if (key == "description" || key == "$schema") {
      continue;
    } else if (key == "countdown_s") {
      if (!value.is_number() || value.get<double>() < 0 || value.get<double>() > 10)
        fail("countdown_s", "must be a number from 0 to 10");
      s.countdown_s = value;
    } else if (key == "steps") {
      if (!value.is_array() || value.empty()) fail("steps", "must be a non-empty array");
    } else {
      fail(key, "is not a script field; use name, description, countdown_s, steps");
    }
  }
  if (!doc.contains("steps")) fail("steps", "is missing; list the gestures to show");
  const auto names = sim::segment_pose_names();
  for (std::size_t i = 0; i < doc["steps"].size(); ++i) {
    const json& j = doc["steps"][i];
    const std::string at = "steps[" + std::to_string(i) + "]";
    if (!j.is_object()) fail(at, "must be an object {show, duration_s, prompt}");
    Step step;
    for (const auto& [key, value] : j.items()) {
      if (key == "show") {
        if (!value.is_string()) fail(at + ".show", "must be a pose name or NO_HAND");
        step.show = value;
      } else if (key == "duration_s") {
        if (!value.is_number() || value.get<double>() <= 0 || value.get<double>() > 600)
          fail(at + ".duration_s", "must be a number of seconds from 0 to 600");
        step.duration_s = value;
      } else if (key == "prompt") {
        if (!value.is_string()) fail(at + ".prompt", "must be a string");
        step.prompt = value;
      } else {
        fail(at + "." + key, "is not a step field; use show, duration_s, prompt");
      }
    }
    if (step.show != "NO_HAND" && !sim::segment_pose_from_string(step.show)) {
      std::string all = "NO_HAND";
      for (const auto& n : names) all += ", " + n;
      fail(at + ".show", "is \"" + step.show + "\"; use one of " + all);
    }
    if (step.prompt.empty()) step.prompt = step.show;
    s.steps.push_back(step);
  }
  if (s.name.empty()) s.name = path.stem().string();
  return s;
}

// ---- gbdcs fixture record ------------------------------------------------------------------
struct RecordOptions {
  std::string camera = "0";
  std::string script;
  std::string output;
  double fps = 30;
};

int run_record(const RecordOptions& o) {
  cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_ERROR);
  const Script script = load_script(o.script);
  // --camera N is a camera index; a spec (video:PATH, images:DIR, recipe:PATH) or a plain
  // video file stands in for a camera (for tests and machines without one).
  std::string spec = o.camera;
  if (!spec.empty() && spec.find_first_not_of("0123456789") == std::string::npos) {
    spec = "camera:" + spec;
  } else if (!is_source_spec(spec)) {
    spec = "video:" + spec;
  }
  contracts::SteadyClock clock;
  auto source = open_any_source(spec, clock);
  fs::create_directories(o.output);

  // Time of a frame: the clock for a live camera; frame_id / fps for a file, which is read
  // as fast as it decodes.
  const bool live = source->live();
  std::optional<contracts::Duration> t0;
  auto frame_time = [&](const vision::Frame& f) {
    if (!live) return static_cast<double>(f.frame_id) / o.fps;
    if (!t0) t0 = f.capture_time;
    return contracts::to_seconds(f.capture_time - *t0);
  };

  // The schedule: per step a countdown (the prompt on screen, frames labelled as a
  // transition) then the gesture.
  struct Slot {
    double start, onset, end;
  };
  std::vector<Slot> slots;
  double t = 0;
  for (const auto& s : script.steps) {
    slots.push_back({t, t + script.countdown_s, t + script.countdown_s + s.duration_s});
    t = slots.back().end;
  }
  const double total = t;
  const bool tty = isatty(STDERR_FILENO) != 0;

  std::unique_ptr<sim::VideoRecorder> video;
  json frames = json::array();
  std::size_t current = 0;
  int last_second = -1;
  std::size_t announced = static_cast<std::size_t>(-1);
  std::int64_t written = 0;
  while (true) {
    auto frame = source->next();
    if (!frame) break;
    const double ft = frame_time(*frame);
    if (ft >= total) break;
    while (current + 1 < slots.size() && ft >= slots[current].end) ++current;
    const Step& step = script.steps[current];
    const Slot& slot = slots[current];
    const bool counting = ft < slot.onset;
    if (announced != current) {
      std::cerr << (tty ? "\n" : "") << "[" << current + 1 << "/" << script.steps.size()
                << "] " << step.prompt << "\n";
      announced = current;
      last_second = -1;
    }
    if (counting) {
      const int left = static_cast<int>(std::ceil(slot.onset - ft));
      if (left != last_second) {
        std::cerr << (tty ? "\r  " : "  ") << "in " << left << " ..." << (tty ? "" : "\n")
                  << std::flush;
        last_second = left;
      }
    } else if (last_second != 0) {
      std::cerr << (tty ? "\r  " : "  ") << "now! hold it for " << step.duration_s << " s"
                << (tty ? "" : "\n") << std::flush;
      last_second = 0;
    }
    cv::Mat bgr = frame->rgb;
    if (frame->order == vision::PixelOrder::kRgb) cv::cvtColor(frame->rgb, bgr, cv::COLOR_RGB2BGR);
    if (!video) {
      sim::VideoRecorderOptions vo;
      vo.fps = o.fps;
      video = std::make_unique<sim::VideoRecorder>(fs::path(o.output) / "video.partial.mp4",
                                                   bgr.size(), vo);
    }
    video->write(bgr);
    const auto pose = sim::segment_pose_from_string(step.show);
    const auto gesture = pose ? pose->gesture() : std::nullopt;
    frames.push_back({{"frame", written},
                      {"time_s", std::round(ft * 1e6) / 1e6},
                      {"segment", current},
                      {"pose", step.show},
                      {"gesture", contracts::to_string(gesture.value_or(contracts::GestureType::kNone))},
                      {"deliberate", gesture.has_value()},
                      {"in_transition", counting},
                      {"hand_present", step.show != "NO_HAND"},
                      {"fully_visible", step.show != "NO_HAND"},
                      {"landmarks", nullptr}});
    ++written;
  }
  if (tty) std::cerr << "\n";
  if (!video || written == 0) {
    std::cerr << "gbdcs fixture record: " << spec << " gave no frames (check the camera)\n";
    return 1;
  }
  video->close();
  const bool complete = !frames.empty() && frames.back()["time_s"].get<double>() >= total - 2.0 / o.fps;
  json segments = json::array();
  for (std::size_t i = 0; i < slots.size(); ++i) {
    const auto pose = sim::segment_pose_from_string(script.steps[i].show);
    const auto gesture = pose ? pose->gesture() : std::nullopt;
    segments.push_back({{"index", i},
                        {"pose", script.steps[i].show},
                        {"gesture", contracts::to_string(gesture.value_or(contracts::GestureType::kNone))},
                        {"deliberate", gesture.has_value()},
                        {"start_s", slots[i].start},
                        {"onset_s", slots[i].onset},
                        {"end_s", slots[i].end},
                        {"prompt", script.steps[i].prompt}});
  }
  const json labels{{"format", "gbdcs-fixture-labels/1"},
                    {"kind", "recorded"},
                    {"video", "video.mp4"},
                    {"source", spec},
                    {"script", script.name},
                    {"fps", o.fps},
                    {"frame_count", written},
                    {"complete", complete},
                    {"segments", segments},
                    {"frames", frames}};
  json fixed = labels;
  {
    cv::VideoCapture cap((fs::path(o.output) / "video.partial.mp4").string());
    fixed["width"] = static_cast<int>(cap.get(cv::CAP_PROP_FRAME_WIDTH));
    fixed["height"] = static_cast<int>(cap.get(cv::CAP_PROP_FRAME_HEIGHT));
  }
  std::ofstream((fs::path(o.output) / "labels.partial.json")) << fixed.dump(1) << "\n";
  fs::rename(fs::path(o.output) / "video.partial.mp4", fs::path(o.output) / "video.mp4");
  fs::rename(fs::path(o.output) / "labels.partial.json", fs::path(o.output) / "labels.json");
  std::cout << o.output << "/video.mp4\n" << o.output << "/labels.json\n";
  if (!complete) {
    std::cerr << "gbdcs fixture record: the camera stopped after " << frames.back()["time_s"]
              << " s of " << total << " s; the fixture holds what was recorded\n";
    return 1;
  }
  return 0;
}

// ---- gbdcs fixture check ---------------------------------------------------------------------
int run_check(const std::string& dir, bool as_json) {
  cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_ERROR);
  std::vector<std::string> problems;
  auto problem = [&](const std::string& p) { problems.push_back(p); };
  const fs::path labels_path = fs::path(dir) / "labels.json";
  const fs::path video_path = fs::path(dir) / "video.mp4";
  json labels;
  std::int64_t video_frames = -1;
  try {
    labels = read_json_doc(labels_path);
  } catch (const std::exception& e) {
    problem(std::string(e.what()) + " (render or record the fixture again)");
  }
  if (!fs::exists(video_path)) {
    problem(video_path.string() + ": missing");
  } else {
    cv::VideoCapture cap(video_path.string());
    if (!cap.isOpened()) {
      problem(video_path.string() + ": cannot be decoded (damaged?)");
    } else {
      video_frames = 0;
      cv::Mat m;
      while (cap.read(m)) {
        ++video_frames;
        if (labels.is_object() && labels.contains("width") &&
            (m.cols != labels.value("width", m.cols) || m.rows != labels.value("height", m.rows))) {
          problem("video frame " + std::to_string(video_frames - 1) + " is " +
                  std::to_string(m.cols) + "x" + std::to_string(m.rows) +
                  ", labels say " + labels["width"].dump() + "x" + labels["height"].dump());
          break;
        }
      }
    }
  }
  std::int64_t n = 0;
  if (labels.is_object()) {
    if (labels.value("format", "") != "gbdcs-fixture-labels/1")
      problem("labels.json: format is not \"gbdcs-fixture-labels/1\"");
    const std::string kind = labels.value("kind", "");
    if (kind != "rendered" && kind != "recorded")
      problem("labels.json: kind must be \"rendered\" or \"recorded\"");
    if (!labels.contains("frames") || !labels["frames"].is_array()) {
      problem("labels.json: no frames array");
    } else {
      const auto& frames = labels["frames"];
      n = static_cast<std::int64_t>(frames.size());
      if (labels.value("frame_count", -1) != n)
        problem("labels.json: frame_count " + labels["frame_count"].dump() + " but " +
                std::to_string(n) + " frames listed");
      if (video_frames >= 0 && video_frames != n)
        problem("video.mp4 has " + std::to_string(video_frames) + " frames, labels.json " +
                std::to_string(n));
      const std::size_t segments = labels.contains("segments") && labels["segments"].is_array()
                                       ? labels["segments"].size()
                                       : 0;
      if (segments == 0) problem("labels.json: no segments");
      double last_t = -1;
      for (std::int64_t i = 0; i < n && problems.size() < 20; ++i) {
        const json& f = frames[static_cast<std::size_t>(i)];
        const std::string at = "labels.json: frames[" + std::to_string(i) + "]";
        if (!f.is_object()) {
          problem(at + " is not an object");
          continue;
        }
        for (const char* key : {"frame", "time_s", "segment", "pose", "gesture", "deliberate",
                                "in_transition", "hand_present", "fully_visible"}) {
          if (!f.contains(key)) problem(at + " has no \"" + key + "\"");
        }
        if (f.value("frame", -1) != i) problem(at + ".frame is not " + std::to_string(i));
        const double t = f.value("time_s", -1.0);
        if (t <= last_t) problem(at + ".time_s does not increase");
        last_t = t;
        if (!contracts::gesture_from_string(f.value("gesture", "?")))
          problem(at + ".gesture \"" + f.value("gesture", "?") + "\" is not a gesture");
        if (f.value("segment", -1) < 0 || f.value("segment", 0) >= static_cast<int>(segments))
          problem(at + ".segment is not a segment index");
        if (f.contains("landmarks") && !f["landmarks"].is_null()) {
          const json& l = f["landmarks"];
          bool ok = l.is_array() && l.size() == contracts::kLandmarkCount;
          for (std::size_t k = 0; ok && k < l.size(); ++k)
            ok = l[k].is_array() && l[k].size() == 4 && l[k][0].is_number() &&
                 l[k][1].is_number() && l[k][2].is_number();
          if (!ok) problem(at + ".landmarks must be 21 rows of [x, y, z, visible]");
        } else if (kind == "rendered" && f.value("hand_present", false)) {
          problem(at + " has a hand but no landmarks");
        }
      }
    }
  }
  if (as_json) {
    std::cout << json{{"fixture", dir}, {"ok", problems.empty()}, {"frames", n},
                      {"problems", problems}}
                     .dump(1)
              << "\n";
  } else if (problems.empty()) {
    std::cout << dir << ": OK (" << labels.value("kind", "?") << ", " << n << " frames, "
              << labels["segments"].size() << " segments)\n";
  } else {
    for (const auto& p : problems) std::cout << dir << ": " << p << "\n";
  }
  return problems.empty() ? 0 : 1;
}

void add_record_commands(CLI::App& app) {
  auto* fixture = group_command(app, "fixture", "Hand-video fixtures: render, record, check");
  static RecordOptions r;
  auto* record = fixture->add_subcommand(
      "record",
      "Record your own hand: prompts each step of a script on the terminal with a countdown, "
      "records the camera, and writes DIR/video.mp4 + labels.json (the fixture format, "
      "without landmarks) so your recordings join `gbdcs eval`");
  record->add_option("--camera", r.camera,
                     "Camera index (0 = /dev/video0), or a video file / source spec to stand in "
                     "for one")
      ->capture_default_str();
  record->add_option("--script", r.script, "Script JSON (fixtures/scripts/basic.json)")->required();
  record->add_option("-o,--output", r.output, "Output folder (created)")->required();
  record->add_option("--fps", r.fps, "Frame rate of the video written (and of a file camera)")
      ->capture_default_str()
      ->check(CLI::Range(1.0, 120.0));
  record->callback([] {
    try {
      g_exit_code = run_record(r);
    } catch (const std::exception& e) {
      std::cerr << "gbdcs fixture record: " << e.what() << "\n";
      g_exit_code = 2;
    }
  });

  static std::string check_dir;
  static bool check_json = false;
  auto* check = fixture->add_subcommand(
      "check", "Validate a fixture folder: labels.json well formed and consistent with video.mp4");
  check->add_option("DIR", check_dir, "Fixture folder")->required();
  check->add_flag("--json", check_json, "One JSON object");
  check->callback([] {
    try {
      g_exit_code = run_check(check_dir, check_json);
    } catch (const std::exception& e) {
      std::cerr << "gbdcs fixture check: " << e.what() << "\n";
      g_exit_code = 2;
    }
  });
}

const CommandRegistration kRecord{41, &add_record_commands};

}  // namespace
}  // namespace gbdcs::app
