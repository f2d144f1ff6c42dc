#include "fixture_support.hpp"

#include <unistd.h>

#include <chrono>
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
void render_fixture(const std::filesystem::path& recipe_path,
                    const std::filesystem::path& out_dir, const Progress& progress) {
  sim::render_fixture(recipe_path, out_dir, progress);
}

std::filesystem::path cached_fixture(const std::filesystem::path& recipe_path,
                                     const std::filesystem::path& cache_dir,
                                     const Progress& progress) {
  return sim::cached_fixture(recipe_path, cache_dir, progress);
}

std::unique_ptr<vision::CaptureSource> open_recipe_source(std::string_view spec,
                                                          const contracts::Clock& clock) {
  std::string rest(spec.substr(7));  // after "recipe:"
  bool live = false;
  if (const auto q = rest.find('?'); q != std::string::npos) {
    const std::string query = rest.substr(q + 1);
    rest = rest.substr(0, q);
    if (query == "live=1" || query == "live=true") {
      live = true;
    } else if (query != "live=0" && query != "live=false") {
      throw vision::CaptureError(std::string(spec) + ": unknown option \"" + query +
                                 "\"; the only option is ?live=1");
    }
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
