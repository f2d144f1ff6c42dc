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

// recipe:PATH[?live=1] as a capture source: rendered on the fly on the capture thread;
// live=1 loops the recipe forever at its frame rate (a camera), otherwise the frames are
// produced as fast as they are read and the stream ends with the recipe.
std::unique_ptr<vision::CaptureSource> open_recipe_source(std::string_view spec,
                                                          const contracts::Clock& clock);

// A progress bar on stderr when it is a terminal (nothing otherwise).
Progress terminal_progress(std::string label);

}  // namespace gbdcs::app
