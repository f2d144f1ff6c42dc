// `gbdcs eval FIXTURE_DIR... | RECIPE.json... | --manifest CSV`: how well the tracker and the
// rule-based recogniser do on fixtures (rendered with ground truth, or recorded) and on a
// folder of labelled photos. `eval landmarks` is in vision_commands.cpp.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <optional>
#include <opencv2/core/utils/logger.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "command_registry.hpp"
#include "commands.hpp"
#include "eval_tally.hpp"
#include "fixture_support.hpp"
#include "gbdcs/contracts/codec.hpp"
#include "gbdcs/gesture/hand_features.hpp"
#include "gbdcs/sim/fixture_cache.hpp"
#include "gbdcs/vision/model_files.hpp"
#include "gbdcs/vision/vision_pipeline.hpp"
#include "vision_support.hpp"

namespace gbdcs::app {
namespace {

namespace fs = std::filesystem;
using contracts::GestureType;
using nlohmann::json;

json read_json(const fs::path& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path.string() + ": cannot read (check the path)");
  std::stringstream s;
  s << in.rdbuf();
  return contracts::parse_json(s.str());
}

// Distance between one landmark of two hands, in pixels.
double distance_px(const contracts::Point3& a, const contracts::Point3& b, int w, int h) {
  return std::hypot((a.x - b.x) * w, (a.y - b.y) * h);
}

// Mean distance between two hands in pixels.
double mean_distance_px(const contracts::Landmarks& a, const contracts::Landmarks& b, int w, int h) {
  double sum = 0;
  for (std::size_t i = 0; i < contracts::kLandmarkCount; ++i)
    sum += distance_px(a.points[i], b.points[i], w, h);
  return sum / contracts::kLandmarkCount;
}

// A label's true landmarks ([x, y, z, visible] per point), if it has all 21.
std::optional<contracts::Landmarks> true_landmarks(const json& label) {
  if (!label.contains("landmarks")) return std::nullopt;
  const json& gt = label["landmarks"];
  if (!gt.is_array() || gt.size() != contracts::kLandmarkCount) return std::nullopt;
  contracts::Landmarks hand;
  for (std::size_t k = 0; k < contracts::kLandmarkCount; ++k) {
    const json& q = gt[k];
    hand.points[k] = {q[0].get<double>(), q[1].get<double>(), q.size() > 2 ? q[2].get<double>() : 0.0};
  }
  hand.score = 1;
  return hand;
}

struct EvalOptions {
  std::vector<std::string> inputs;
  std::string manifest;
  std::string cache_dir;
  bool json = false;
  bool check = false;
  bool per_fixture = false;
  std::string frames_out;
  std::string recognizer_file;  // RuleBasedOptions JSON; empty = the defaults
  double min_detection = 0.98;
  double max_landmark_error_pct = 3.0;
  double min_accuracy = 0.97;
  double max_false_positive_rate = 0.005;
  ModelChoice models;
};

// One scored frame for --frames: what was shown, what was read, and the recogniser's
// features on the tracked and on the true landmarks.
json frame_record(const fs::path& dir, const json& label, std::size_t frame, GestureType expected,
                  GestureType predicted, const vision::HandResult* match, double error_pct,
                  const std::optional<contracts::Landmarks>& truth, GestureType truth_read,
                  double aspect) {
  auto features = [aspect](const contracts::Landmarks& h) {
    const auto f = gesture::extract_features(h, aspect, 1.0);
    const auto flat = gesture::extract_features(h, aspect, 0.0);
    return json{{"finger_curl_deg", f.finger_curl_deg},
                {"finger_curl_deg_image_plane", flat.finger_curl_deg},
                {"thumb_bend_deg", f.thumb_bend_deg},
                {"thumb_lateral", f.thumb_lateral},
                {"thumb_direction_deg", f.thumb_direction_deg},
                {"thumb_in_plane", f.thumb_in_plane},
                {"index_direction_deg", f.index_direction_deg},
                {"index_in_plane", f.index_in_plane},
                {"index_middle_spread_deg", f.index_middle_spread_deg}};
  };
  json r = {{"fixture", dir.filename().string()},
            {"frame", frame},
            {"pose", label.value("hand_present", false) ? label.value("pose", "?") : "NO_HAND"},
            {"expected", contracts::to_string(expected)},
            {"predicted", contracts::to_string(predicted)},
            {"found", match != nullptr}};
  if (match != nullptr) {
    r["confidence"] = match->confidence;
    r["tracked_features"] = features(match->landmarks);
    if (truth) r["landmark_error_pct"] = error_pct;
  }
  if (truth) {
    r["truth_read"] = contracts::to_string(truth_read);
    r["truth_features"] = features(*truth);
  }
  return r;
}

// One fixture folder: video.mp4 + labels.json. `frames_out`, when open, gets one JSON line per
// scored frame.
Tally eval_fixture(const fs::path& dir, vision::HandFinder& finder,
                   vision::HandClassifier& classifier, const contracts::Clock& clock,
                   std::ostream* frames_out) {
  const json labels = read_json(dir / "labels.json");
  if (!labels.contains("frames") || !labels["frames"].is_array())
    throw std::runtime_error((dir / "labels.json").string() +
                             ": no \"frames\" array (check it with `gbdcs fixture check`)");
  const auto& frames = labels["frames"];
  auto source = vision::open_video(dir / "video.mp4", clock);
  finder.reset();
  Tally t;
  std::size_t i = 0;
  while (auto frame = source->next()) {
    if (i >= frames.size()) break;
    const json& l = frames[i++];
    cv::Mat rgb;
    cv::cvtColor(frame->rgb, rgb, frame->order == vision::PixelOrder::kBgr ? cv::COLOR_BGR2RGB
                                                                             : cv::COLOR_RGB2BGR);
    if (frame->order == vision::PixelOrder::kRgb) rgb = frame->rgb;
    classifier.set_frame_size(rgb.cols, rgb.rows);
    const auto hands = classifier.classify(finder.find(rgb));
    const bool deliberate = l.value("deliberate", false);
    const bool transition = l.value("in_transition", false);
    const bool fully_visible = l.value("fully_visible", false);
    const auto truth = contracts::gesture_from_string(l.value("gesture", "NONE"))
                           .value_or(GestureType::kNone);
    const std::optional<contracts::Landmarks> true_hand = true_landmarks(l);
    // Which detected hand is the labelled one: the nearest to the ground truth, within half
    // the hand's size; without landmarks (recorded fixtures), the most present hand.
    const vision::HandResult* match = nullptr;
    double match_px = 0;
    if (true_hand) {
      const double size = l.value("hand_size_px", 0.0);
      for (const auto& h : hands) {
        const double d = mean_distance_px(h.landmarks, *true_hand, rgb.cols, rgb.rows);
        if ((match == nullptr || d < match_px) && d < 0.5 * size) {
          match = &h;
          match_px = d;
        }
      }
      if (fully_visible) {
        ++t.visible_frames;
        if (match != nullptr) {
          ++t.detected_frames;
          const double pct = 100.0 * match_px / std::max(1.0, size);
          t.landmark_error_max_pct = std::max(t.landmark_error_max_pct, pct);
          t.offsets.add(*true_hand, match->landmarks, rgb.cols, rgb.rows, std::max(1.0, size));
        }
      }
    } else if (l.value("hand_present", false)) {
      // A recorded fixture: no landmarks; the most present hand is the one shown, and the
      // detection rate counts the frames the script asked for a hand (outside countdowns).
      if (fully_visible && !transition) {
        ++t.visible_frames;
        if (!hands.empty()) ++t.detected_frames;
      }
      if (!hands.empty()) match = &hands.front();
    }
    if (transition) continue;
    GestureType predicted = match != nullptr ? match->gesture : GestureType::kNone;
    if (deliberate) {
      // A gesture is judged where it can be seen whole.
      if (!fully_visible && true_hand) continue;
    } else {
      // Any gesture from any hand on a frame without a deliberate gesture is a false positive.
      for (const auto& h : hands)
        if (h.gesture != GestureType::kNone) predicted = h.gesture;
    }
    const GestureType expected = deliberate ? truth : GestureType::kNone;
    t.score(expected, predicted, deliberate);
    GestureType truth_read = GestureType::kNone;
    if (true_hand) {
      truth_read = classifier.recognize(*true_hand).gesture;
      t.truth_reads.score(expected, truth_read, deliberate);
    }
    if (frames_out != nullptr) {
      const double size = std::max(1.0, l.value("hand_size_px", 0.0));
      *frames_out << frame_record(dir, l, i - 1, expected, predicted, match,
                                  100.0 * match_px / size, true_hand, truth_read,
                                  static_cast<double>(rgb.cols) / rgb.rows)
                         .dump()
                  << "\n";
    }
    const std::string pose = l.value("hand_present", false) ? l.value("pose", "?") : "NO_HAND";
    ++t.by_pose[pose][std::string(contracts::to_string(predicted))];
  }
  return t;
}

std::optional<GestureType> mediapipe_to_ours(std::string name) {
  static const std::map<std::string, GestureType> kMap = {
      {"Closed_Fist", GestureType::kFist},     {"Open_Palm", GestureType::kOpenPalm},
      {"Pointing_Up", GestureType::kPointUp},  {"Thumb_Up", GestureType::kThumbUp},
      {"Thumb_Down", GestureType::kThumbDown}, {"Victory", GestureType::kVictory},
      {"ILoveYou", GestureType::kILoveYou},    {"None", GestureType::kNone},
      {"NO_HAND", GestureType::kNone}};
  if (auto it = kMap.find(name); it != kMap.end()) return it->second;
  if (auto ours = contracts::gesture_from_string(name)) return *ours;
  // Annotated labels: "NO_GESTURE (people, ...)" and a bare comment "(2 hands, ...)" mean no
  // gesture; otherwise the first word decides ("Victory (left hand)").
  if (name.rfind("NO_GESTURE", 0) == 0 || name.rfind("(", 0) == 0) return GestureType::kNone;
  if (const auto cut = name.find_first_of(" ("); cut != std::string::npos && cut > 0)
    return mediapipe_to_ours(name.substr(0, cut));
  return std::nullopt;
}

std::vector<std::string> split_csv_line(const std::string& line) {
  std::vector<std::string> out;
  std::string cell;
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        cell += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        cell += c;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      out.push_back(cell);
      cell.clear();
    } else if (c != '\r') {
      cell += c;
    }
  }
  out.push_back(cell);
  return out;
}

Tally eval_manifest(const fs::path& csv, vision::HandFinder& finder,
                    vision::HandClassifier& classifier, json& rows_out) {
  std::ifstream in(csv);
  if (!in) throw std::runtime_error(csv.string() + ": cannot read (check the path)");
  std::string line;
  if (!std::getline(in, line)) throw std::runtime_error(csv.string() + ": empty manifest");
  const auto header = split_csv_line(line);
  const auto col = [&](const std::string& name) -> std::size_t {
    const auto it = std::find(header.begin(), header.end(), name);
    if (it == header.end())
      throw std::runtime_error(csv.string() + ": no \"" + name +
                               "\" column; the header must name path and "
                               "expected_mediapipe_gesture");
    return static_cast<std::size_t>(it - header.begin());
  };
  const std::size_t path_col = col("path");
  const std::size_t gesture_col = col("expected_mediapipe_gesture");
  Tally t;
  int row = 1;
  while (std::getline(in, line)) {
    ++row;
    if (line.empty()) continue;
    const auto cells = split_csv_line(line);
    if (cells.size() <= std::max(path_col, gesture_col))
      throw std::runtime_error(csv.string() + ": row " + std::to_string(row) + " has too few cells");
    const auto expected = mediapipe_to_ours(cells[gesture_col]);
    if (!expected)
      throw std::runtime_error(csv.string() + ": row " + std::to_string(row) + ": unknown gesture \"" +
                               cells[gesture_col] + "\" (MediaPipe's names or ours)");
    fs::path image = cells[path_col];
    if (image.is_relative()) image = csv.parent_path() / image;
    cv::Mat bgr = cv::imread(image.string(), cv::IMREAD_COLOR);
    if (bgr.empty())
      throw std::runtime_error(image.string() + ": cannot decode (row " + std::to_string(row) + ")");
    cv::Mat rgb;
    cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
    classifier.set_frame_size(rgb.cols, rgb.rows);
    const auto hands = classifier.classify(finder.find(rgb));
    // A hand is expected unless the row says there is none (or only incidental ones).
    const bool hand_expected =
        cells[gesture_col] != "NO_HAND" && cells[gesture_col].rfind("NO_GESTURE", 0) != 0;
    if (hand_expected) {
      ++t.visible_frames;
      if (!hands.empty()) ++t.detected_frames;
    }
    GestureType predicted = GestureType::kNone;
    for (const auto& h : hands) {
      if (h.gesture != GestureType::kNone) {
        predicted = h.gesture;
        break;
      }
    }
    const bool deliberate = *expected != GestureType::kNone;
    t.score(*expected, predicted, deliberate);
    rows_out.push_back({{"path", cells[path_col]},
                        {"expected", contracts::to_string(*expected)},
                        {"predicted", contracts::to_string(predicted)},
                        {"hands", hands.size()}});
  }
  return t;
}

int run_eval(const EvalOptions& o) {
  cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_ERROR);
  if (o.inputs.empty() && o.manifest.empty()) {
    std::cerr << "gbdcs eval: give fixture folders, recipes, or --manifest CSV "
                 "(see gbdcs eval --help)\n";
    return 2;
  }
  contracts::SteadyClock clock;
  gesture::RuleBasedOptions recognizer;
  if (!o.recognizer_file.empty()) {
    const json doc = read_json(o.recognizer_file);
    const bool pipeline_file = doc.is_object() && doc.contains("recognizer");
    try {
      recognizer = gesture::rule_based_options_from_json(pipeline_file ? doc["recognizer"] : doc);
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(o.recognizer_file + ": " + e.what());
    }
  }
  vision::HandClassifier classifier(recognizer);
  Tally total;
  json sources = json::array();
  // Resolve the inputs: fixture folders, recipes (rendered into the cache), folders of
  // recipes.
  std::vector<fs::path> fixtures;
  std::vector<fs::path> recipes;
  for (const auto& in : o.inputs) {
    const fs::path p(in);
    if (fs::is_directory(p) && fs::exists(p / "labels.json")) {
      fixtures.push_back(p);
    } else if (fs::is_directory(p)) {
      std::vector<fs::path> found;
      for (const auto& e : fs::directory_iterator(p))
        if (e.path().extension() == ".json" && e.path().filename() != "recipe.schema.json")
          found.push_back(e.path());
      std::sort(found.begin(), found.end());
      if (found.empty())
        throw std::runtime_error(in + ": neither a fixture (no labels.json) nor a folder of recipes");
      recipes.insert(recipes.end(), found.begin(), found.end());
    } else if (p.extension() == ".json" && fs::is_regular_file(p)) {
      recipes.push_back(p);
    } else {
      throw std::runtime_error(in + ": not a fixture folder, a recipe or a folder of recipes "
                                    "(check the path)");
    }
  }
  if (!recipes.empty()) {
    const fs::path cache = o.cache_dir.empty() ? sim::default_fixture_cache_dir()
                                               : fs::path(o.cache_dir);
    for (const auto& r : recipes) {
      fixtures.push_back(cached_fixture(r, cache, terminal_progress("render " + r.stem().string())));
    }
  }
  std::ofstream frames_file;
  if (!o.frames_out.empty()) {
    frames_file.open(o.frames_out, std::ios::trunc);
    if (!frames_file)
      throw std::runtime_error(o.frames_out + ": cannot write the --frames file (check the folder)");
  }
  if (!fixtures.empty()) {
    auto finder = vision::make_tracker_finder(tracker_options(o.models, false), clock);
    for (const auto& dir : fixtures) {
      const Tally t =
          eval_fixture(dir, *finder, classifier, clock, frames_file.is_open() ? &frames_file : nullptr);
      total.add(t);
      json s = summary_json(t);
      s["fixture"] = dir.string();
      if (!o.json && o.per_fixture) print_summary(dir.string(), s);
      sources.push_back(s);
    }
  }
  json rows = json::array();
  if (!o.manifest.empty()) {
    auto finder = vision::make_tracker_finder(tracker_options(o.models, true), clock);
    const Tally t = eval_manifest(o.manifest, *finder, classifier, rows);
    total.add(t);
    json s = summary_json(t);
    s["manifest"] = o.manifest;
    sources.push_back(s);
  }
  json doc = summary_json(total);
  bool pass = true;
  json failures = json::array();
  if (o.check) {
    auto need = [&](const char* key, bool ok, const std::string& what) {
      if (!ok) {
        pass = false;
        failures.push_back(std::string(key) + ": " + what);
      }
    };
    const auto& d = doc;
    need("detection_rate", !d["detection_rate"].is_null() && d["detection_rate"] >= o.min_detection,
         "below " + std::to_string(o.min_detection));
    if (!d["landmark_error_pct_mean"].is_null())
      need("landmark_error_pct_mean", d["landmark_error_pct_mean"] <= o.max_landmark_error_pct,
           "above " + std::to_string(o.max_landmark_error_pct) + " %");
    need("deliberate_accuracy",
         !d["deliberate_accuracy"].is_null() && d["deliberate_accuracy"] >= o.min_accuracy,
         "below " + std::to_string(o.min_accuracy));
    if (!d["false_positive_rate"].is_null())
      need("false_positive_rate", d["false_positive_rate"] <= o.max_false_positive_rate,
           "above " + std::to_string(o.max_false_positive_rate));
    doc["pass"] = pass;
    doc["failures"] = failures;
  }
  doc["sources"] = sources;
  if (!rows.empty()) doc["manifest_rows"] = rows;
  if (o.json) {
    std::cout << doc.dump(1) << "\n";
  } else {
    print_summary("overall (" + std::to_string(sources.size()) + " sources)", doc);
    print_classes(doc);
    if (o.check) {
      for (const auto& f : failures) std::cout << "  MISSED " << f.get<std::string>() << "\n";
      std::cout << (pass ? "PASS" : "FAIL") << "\n";
    }
  }
  return pass ? 0 : 1;
}

void add_eval_command(CLI::App& app) {
  static EvalOptions o;
  auto* eval = group_command(app, "eval", "Compare results against a reference");
  eval->require_subcommand(0, 1);
  eval->description(
      "Measure the tracker and the recogniser on fixtures (folders with video.mp4 + "
      "labels.json, recipes rendered on demand, folders of recipes) and/or a manifest of "
      "labelled photos: detection rate, landmark error, per-class precision/recall, "
      "confusion matrix, accuracy, false-positive rate. `eval landmarks` compares two "
      "recognize outputs");
  eval->add_option("INPUTS", o.inputs, "Fixture folders, recipe .json files or folders of recipes");
  eval->add_option("--manifest", o.manifest,
                   "CSV with columns path, expected_mediapipe_gesture (MediaPipe's names: "
                   "Closed_Fist, Open_Palm, ..., None, NO_HAND; paths relative to the CSV)");
  eval->add_option("--cache", o.cache_dir,
                   "Where recipes are rendered, keyed by recipe hash (default: "
                   "$TMPDIR/gbdcs-fixture-cache)");
  eval->add_flag("--json", o.json, "One JSON object");
  eval->add_flag("--per-fixture", o.per_fixture, "Also print each fixture's figures");
  eval->add_option("--frames", o.frames_out,
                   "Write one JSON line per scored fixture frame to this file: pose, expected and "
                   "predicted gesture, the recogniser's features on the tracked and on the true "
                   "landmarks, landmark error (to find why a pose is misread)");
  eval->add_option("--recognizer", o.recognizer_file,
                   "The rule-based recogniser's options (JSON: an object of RuleBasedOptions, or "
                   "a PipelineOptions file with a \"recognizer\" key; docs/GESTURES.md), to "
                   "measure a change of them before it goes into a profile")
      ->check(CLI::ExistingFile);
  eval->add_flag("--check", o.check,
                 "Exit 1 unless the targets are met (docs/ACCURACY.md): detection, landmark "
                 "error, deliberate accuracy, false positives");
  eval->add_option("--min-detection", o.min_detection, "Target: detection rate (fraction)")
      ->capture_default_str();
  eval->add_option("--max-landmark-error-pct", o.max_landmark_error_pct,
                   "Target: mean landmark error, % of the hand's bounding-box diagonal")
      ->capture_default_str();
  eval->add_option("--min-accuracy", o.min_accuracy,
                   "Target: accuracy on deliberate frames (fraction)")
      ->capture_default_str();
  eval->add_option("--max-fp-rate", o.max_false_positive_rate,
                   "Target: false positives on non-deliberate frames (fraction)")
      ->capture_default_str();
  add_model_options(eval, o.models);
  eval->callback([eval] {
    if (!eval->get_subcommands().empty()) return;  // `eval landmarks` ran
    try {
      g_exit_code = run_eval(o);
    } catch (const std::exception& e) {
      std::cerr << "gbdcs eval: " << e.what() << "\n";
      g_exit_code = 2;
    }
  });
}

const CommandRegistration kEval{45, &add_eval_command};

}  // namespace
}  // namespace gbdcs::app
