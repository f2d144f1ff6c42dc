// Rendering recipes to fixture folders, shared by `fixture render`, `eval` and the recipe:
// capture source.
#pragma once

#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <string_view>

#include "gbdcs/contracts/clock.hpp"
#include "gbdcs/vision/capture.hpp"

namespace gbdcs::app {

// Called after each frame with (frames done, frames total).
using Progress = std::function<void(std::int64_t, std::int64_t)>;

// Renders the recipe at `recipe_path` into `out_dir` (created): video.mp4 and labels.json.
// Throws sim::RecipeError for a bad recipe, std::runtime_error for I/O failures. Both this and
// cached_fixture live in sim/fixtures (gbdcs/sim/fixture_cache.hpp), which the scenario
// runner shares.
void render_fixture(const std::filesystem::path& recipe_path, const std::filesystem::path& out_dir,
                    const Progress& progress = {});

// The folder under `cache_dir` that holds the recipe's rendering: <stem>-<hash>, the hash over
// the recipe's canonical form, the hand model and the renderer's version. Renders it when it
// is missing or incomplete; returns the folder.
std::filesystem::path cached_fixture(const std::filesystem::path& recipe_path,
                                     const std::filesystem::path& cache_dir,
                                     const Progress& progress = {});

// recipe:PATH[?live=1[&fps=N][&cache=0]] as a capture source.
//   live=1    a camera: the recipe's video, rendered once into the fixture cache
//             (fixture_cache_dir(); `preparing` is told the progress while it renders) and
//             played back in a loop at the recipe's frame rate with real timing
//             (vision::open_live_video), so the camera keeps its rate on a busy CPU.
//   fps=N     with live=1: the recipe rendered at N frames a second instead of its own rate
//             (its own cache entry; the motion is defined in seconds, so the same video).
//   cache=0   with live=1: render every frame on the capture thread instead (no cache; the
//             rate is whatever the CPU renders, ~17 FPS at 640x480 on two idle cores).
//   neither   the frames rendered as fast as they are read; the stream ends with the recipe.
std::unique_ptr<vision::CaptureSource> open_recipe_source(std::string_view spec,
                                                          const contracts::Clock& clock,
                                                          const Progress& preparing = {});

// Where rendered recipes are cached for recipe:...?live=1: $GBDCS_FIXTURE_CACHE, else
// <build dir>/fixture-cache when the build folder exists, else <tmp>/gbdcs-fixture-cache.
std::filesystem::path fixture_cache_dir();

// A progress bar on stderr when it is a terminal (nothing otherwise).
Progress terminal_progress(std::string label);

}  // namespace gbdcs::app
