#include "fixture_support.hpp"

#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>
#include <thread>

#include "gbdcs/contracts/json_file.hpp"
#include "gbdcs/sim/fixture_cache.hpp"
#include "gbdcs/sim/fixture_renderer.hpp"
#include "gbdcs/sim/hand_scene.hpp"
#include "gbdcs/sim/recipe.hpp"
#include "gbdcs/vision/source_option.hpp"

namespace gbdcs::app {

namespace fs = std::filesystem;

void render_fixture(const std::filesystem::path& recipe_path,
                    const std::filesystem::path& out_dir, const Progress& progress) {
  sim::render_fixture(recipe_path, out_dir, progress);
}

std::filesystem::path cached_fixture(const std::filesystem::path& recipe_path,
                                     const std::filesystem::path& cache_dir,
                                     const Progress& progress) {
  return sim::cached_fixture(recipe_path, cache_dir, progress);
}

namespace {

// The recipe with its "fps" replaced, as <cache>/recipes/<stem>@<fps>fps.json (rewritten only
// when it differs), so it gets a cache entry of its own.
fs::path recipe_at_fps(const fs::path& recipe_path, double fps, const fs::path& cache_dir) {
  auto doc = contracts::read_json_file<vision::CaptureError>(recipe_path.string(), "recipe");
  if (!doc.is_object()) throw vision::CaptureError(recipe_path.string() + ": not a recipe object");
  doc["fps"] = fps;
  doc.erase("$schema");
  char name[64];
  std::snprintf(name, sizeof name, "@%gfps.json", fps);
  const fs::path out = cache_dir / "recipes" / (recipe_path.stem().string() + name);
  const std::string text = doc.dump(1) + "\n";
  std::ifstream old(out, std::ios::binary);
  std::stringstream current;
  current << old.rdbuf();
  if (current.str() != text) {
    std::error_code ec;
    fs::create_directories(out.parent_path(), ec);
    const fs::path tmp = out.string() + ".partial-" + std::to_string(::getpid());
    std::ofstream(tmp, std::ios::binary) << text;
    fs::rename(tmp, out, ec);
    if (ec) throw std::runtime_error(out.string() + ": cannot write: " + ec.message());
  }
  return out;
}

}  // namespace

fs::path fixture_cache_dir() {
  if (const char* env = std::getenv("GBDCS_FIXTURE_CACHE"); env && *env) return env;
  std::error_code ec;
  if (fs::is_directory(GBDCS_BUILD_DIR, ec)) return fs::path(GBDCS_BUILD_DIR) / "fixture-cache";
  return fs::temp_directory_path(ec) / "gbdcs-fixture-cache";
}

std::unique_ptr<vision::CaptureSource> open_recipe_source(std::string_view spec,
                                                          const contracts::Clock& clock,
                                                          const Progress& preparing) {
  std::string rest(spec.substr(7));  // after "recipe:"
  bool live = false;
  bool cache = true;
  double fps = 0;  // 0: the recipe's own
  if (const auto q = rest.find('?'); q != std::string::npos) {
    std::stringstream query(rest.substr(q + 1));
    rest = rest.substr(0, q);
    for (std::string option; std::getline(query, option, '&');) {
      if (option == "live=1" || option == "live=true") {
        live = true;
      } else if (option == "cache=0" || option == "cache=false") {
        cache = false;
      } else if (option.rfind("fps=", 0) == 0) {
        fps = vision::number_option(option, "fps").value_or(-1);
        if (!(fps >= 1 && fps <= 120)) {
          throw vision::CaptureError(std::string(spec) +
                                     ": fps must be a number from 1 to 120, as in fps=30");
        }
      } else if (option != "live=0" && option != "live=false" && option != "cache=1" &&
                 option != "cache=true") {
        throw vision::CaptureError(std::string(spec) + ": unknown option \"" + option +
                                   "\"; the options are live=1, fps=N and cache=0");
      }
    }
  }
  if (fps > 0 && !(live && cache)) {
    throw vision::CaptureError(std::string(spec) + ": fps=N needs live=1 (and the cache)");
  }
  if (live && cache) {
    fs::path recipe_path = sim::resolve_fixture_path(rest);
    fs::path dir;
    try {
      if (fps > 0) recipe_path = recipe_at_fps(recipe_path, fps, fixture_cache_dir());
      dir = cached_fixture(recipe_path, fixture_cache_dir(), preparing);
    } catch (const sim::RecipeError& e) {
      throw vision::CaptureError(e.what());
    } catch (const std::exception& e) {
      throw vision::CaptureError(std::string(spec) + ": cannot render the recipe into " +
                                 fixture_cache_dir().string() + ": " + e.what() +
                                 " (set GBDCS_FIXTURE_CACHE to a writable folder, or add " +
                                 "&cache=0 to render live)");
    }
    // The recipe's rate, not the container's (which may round it).
    return vision::open_live_video(dir / "video.mp4", clock, sim::load_recipe(recipe_path).fps,
                                   std::string(spec));
  }
  sim::Recipe recipe;
  try {
    recipe = sim::load_recipe(sim::resolve_fixture_path(rest));
  } catch (const sim::RecipeError& e) {
    throw vision::CaptureError(e.what());
  }
  // The renderer (and its GL context) is made on the capture thread, on the first frame.
  // Live: the recipe's frame is the one due by the clock (frames are skipped when rendering
  // falls behind real time, as a camera's are), looping forever.
  struct State {
    std::unique_ptr<sim::FixtureRenderer> renderer;
    contracts::Duration start{};
    std::int64_t last = -1;
  };
  auto state = std::make_shared<State>();
  const contracts::Clock* c = &clock;
  auto generate = [state, recipe, live, c](std::int64_t id) -> std::optional<cv::Mat> {
    if (!state->renderer) {
      state->renderer = std::make_unique<sim::FixtureRenderer>(recipe);
      state->start = c->now();
    }
    sim::FixtureRenderer& r = *state->renderer;
    const auto n = r.frame_count();
    if (!live) {
      if (id >= n) return std::nullopt;
      return r.frame(id).bgr;
    }
    std::int64_t next = state->last + 1;
    const auto due = state->start + contracts::from_seconds(static_cast<double>(next) / recipe.fps);
    const auto now = c->now();
    if (due > now) {
      std::this_thread::sleep_for(due - now);
    } else {
      next = std::max(next, static_cast<std::int64_t>(contracts::to_seconds(now - state->start) *
                                                      recipe.fps));
    }
    state->last = next;
    return r.frame(next % n).bgr;
  };
  return std::make_unique<vision::GeneratorSource>(generate, clock, std::string(spec), live,
                                                   vision::PixelOrder::kBgr);
}

Progress terminal_progress(std::string label) {
  if (isatty(STDERR_FILENO) == 0) return {};
  return [label = std::move(label)](std::int64_t done, std::int64_t total) {
    constexpr int kWidth = 30;
    const int filled = total > 0 ? static_cast<int>(kWidth * done / total) : kWidth;
    std::cerr << "\r" << label << " [" << std::string(filled, '#')
              << std::string(kWidth - filled, ' ') << "] " << done << "/" << total << " frames"
              << (done == total ? "\n" : "") << std::flush;
  };
}

}  // namespace gbdcs::app
