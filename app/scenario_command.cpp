// `gbdcs scenario run PATH...`: runs scenario files (scenarios/*.json, docs/SCENARIOS.md)
// through the production core, lockstep on simulated time; prints a progress line per
// scenario and a table, writes JUnit XML / JSON reports and, for failed scenarios (all with
// --out), the twin's video beside the hand video, the trajectory plot and the event log.
// `gbdcs scenario validate PATH...`: loads the files only and reports what is wrong.
#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <mutex>
#include <thread>

#include "command_registry.hpp"
#include "commands.hpp"
#include "gbdcs/contracts/codec.hpp"
#include "gbdcs/sim/scenario.hpp"
#include "gbdcs/sim/scenario_report.hpp"
#include "gbdcs/sim/scenario_runner.hpp"
#include "vision_support.hpp"

namespace gbdcs::app {
namespace {

struct ScenarioCmdOptions {
  std::vector<std::string> paths;
  std::string junit;
  std::string json;
  std::string out;
  std::string artifacts = "scenario-results";
  bool no_artifacts = false;
  int jobs = 1;
  std::string failsafe;
  bool quiet_table = false;
  std::string cache;
  ModelChoice models;
};

std::vector<std::string> expand(const std::vector<std::string>& paths) {
  std::vector<std::string> files;
  for (const auto& p : paths) {
    auto found = sim::scenario_files(p);
    files.insert(files.end(), found.begin(), found.end());
  }
  return files;
}

void write_file(const std::string& path, const std::string& text) {
  const auto parent = std::filesystem::path(path).parent_path();
  if (!parent.empty()) std::filesystem::create_directories(parent);
  std::ofstream out(path, std::ios::binary);
  if (!out) throw std::runtime_error("cannot write '" + path + "' (check the folder exists and is writable)");
  out << text;
  if (!out) throw std::runtime_error("writing '" + path + "' failed");
}

int run_scenarios(const ScenarioCmdOptions& o) {
  const auto files = expand(o.paths);
  sim::RunOptions ro;
  ro.fixture_cache_dir = o.cache;
  ro.model = o.models.model;
  ro.model_dir = o.models.model_dir;
  if (!o.out.empty()) {
    ro.artifacts_dir = o.out;
    ro.artifacts_always = true;
  } else if (!o.no_artifacts) {
    ro.artifacts_dir = o.artifacts;
  }
  if (!o.failsafe.empty()) {
    try {
      ro.failsafe_override = contracts::parse_json(o.failsafe);
    } catch (const std::exception& e) {
      throw std::invalid_argument(std::string("--failsafe: ") + e.what());
    }
    if (!ro.failsafe_override.is_object()) {
      throw std::invalid_argument("--failsafe: give a JSON object, e.g. '{\"idle_timeout_s\": 30}'");
    }
  }

  const auto wall_start = std::chrono::steady_clock::now();
  std::vector<sim::ScenarioResult> results(files.size());
  std::atomic<std::size_t> next{0};
  std::atomic<std::size_t> done{0};
  std::mutex out_mutex;
  auto worker = [&] {
    for (auto i = next++; i < files.size(); i = next++) {
      results[i] = sim::run_scenario_file(files[i], ro);
      std::lock_guard lock(out_mutex);
      std::cout << "[" << ++done << "/" << files.size() << "] " << sim::progress_line(results[i])
                << std::endl;
    }
  };
  const int jobs = std::max(1, std::min<int>(o.jobs, static_cast<int>(files.size())));
  std::vector<std::thread> threads;
  for (int j = 1; j < jobs; ++j) threads.emplace_back(worker);
  worker();
  for (auto& t : threads) t.join();
  const double wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();

  std::cout << "\n";
  sim::print_table(std::cout, results);
  for (const auto& r : results) {
    if (!r.artifacts.empty()) {
      std::cout << "artifacts of " << r.name << ":";
      for (const auto& a : r.artifacts) std::cout << " " << a;
      std::cout << "\n";
    }
  }
  if (!o.junit.empty()) write_file(o.junit, sim::report_junit(results, wall_s));
  if (!o.json.empty()) write_file(o.json, sim::report_json(results, wall_s).dump(2) + "\n");
  const bool all_passed = std::all_of(results.begin(), results.end(), [](const auto& r) {
    return r.passed && r.error.empty();
  });
  std::cout << "wall time " << wall_s << " s\n";
  return all_passed ? 0 : 1;
}

int validate_scenarios(const std::vector<std::string>& paths) {
  int bad = 0;
  for (const auto& file : expand(paths)) {
    try {
      const auto s = sim::Scenario::load_file(file);
      std::cout << "ok     " << file << " (" << s.name << ": " << s.events.size() << " events, "
                << s.criteria.size() << " criteria)\n";
    } catch (const std::exception& e) {
      ++bad;
      std::cout << "ERROR  " << e.what() << "\n";
    }
  }
  return bad == 0 ? 0 : 1;
}

void add_scenario_command(CLI::App& app) {
  auto* group = group_command(app, "scenario",
                              "End-to-end scenarios: the production core flying the twin from a "
                              "scripted camera, judged by criteria (docs/SCENARIOS.md)");
  static ScenarioCmdOptions o;
  auto* run = group->add_subcommand(
      "run",
      "Run scenario files (or folders of them) lockstep on simulated time, faster than real "
      "time; exit 0 only when every criterion of every scenario passed");
  run->add_option("paths", o.paths, "Scenario files or folders (e.g. scenarios/)")->required();
  run->add_option("--junit", o.junit, "Write a JUnit XML report (one test case per criterion)");
  run->add_option("--json", o.json, "Write a JSON report");
  run->add_option("--out", o.out,
                  "Write the artifacts (video, trajectory plot, event log) of every scenario "
                  "into this folder, passed or failed");
  run->add_option("--artifacts", o.artifacts,
                  "Folder for the artifacts of failed scenarios (without --out)")
      ->capture_default_str();
  run->add_flag("--no-artifacts", o.no_artifacts, "Write no artifacts, not even for failures");
  run->add_option("--jobs,-j", o.jobs, "Scenarios to run in parallel")
      ->capture_default_str()
      ->check(CLI::Range(1, 64));
  run->add_option("--failsafe", o.failsafe,
                  "JSON merged over every scenario's failsafe options, to check that the suite "
                  "catches a broken build (e.g. '{\"idle_timeout_s\": 30}')");
  run->add_option("--cache", o.cache,
                  "Folder where recipe cameras are rendered once and kept (the cache `gbdcs "
                  "eval --cache` uses; default: <temp>/gbdcs-fixture-cache)");
  add_model_options(run, o.models);
  run->callback([] {
    try {
      g_exit_code = run_scenarios(o);
    } catch (const std::exception& e) {
      std::cerr << "gbdcs scenario run: " << e.what() << "\n";
      g_exit_code = 2;
    }
  });

  static std::vector<std::string> validate_paths;
  auto* validate = group->add_subcommand(
      "validate", "Load scenario files and report what is wrong, without running them");
  validate->add_option("paths", validate_paths, "Scenario files or folders")->required();
  validate->callback([] {
    try {
      g_exit_code = validate_scenarios(validate_paths);
    } catch (const std::exception& e) {
      std::cerr << "gbdcs scenario validate: " << e.what() << "\n";
      g_exit_code = 2;
    }
  });
}

const CommandRegistration kScenario{40, &add_scenario_command};

}  // namespace
}  // namespace gbdcs::app
