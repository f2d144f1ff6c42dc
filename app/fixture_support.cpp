#include "fixture_support.hpp"

#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>
#include <thread>

#include "gbdcs/sim/fixture_cache.hpp"
#include "gbdcs/sim/fixture_renderer.hpp"
#include "gbdcs/sim/hand_scene.hpp"
#include "gbdcs/sim/recipe.hpp"

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
  if (const auto q = rest.find('?'); q != std::string::npos) {
    std::stringstream query(rest.substr(q + 1));
    rest = rest.substr(0, q);
    for (std::string option; std::getline(query, option, '&');) {
      if (option == "live=1" || option == "live=true") {
        live = true;
      } else if (option == "cache=0" || option == "cache=false") {
        cache = false;
      } else if (option != "live=0" && option != "live=false" && option != "cache=1" &&
                 option != "cache=true") {
        throw vision::CaptureError(std::string(spec) + ": unknown option \"" + option +
                                   "\"; the options are live=1 and cache=0");
      }
    }
  }
  if (live && cache) {
    const fs::path recipe_path = sim::resolve_fixture_path(rest);
    fs::path dir;
    try {
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
