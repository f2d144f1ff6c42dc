#include "fixture_support.hpp"

#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>
#include <thread>

#include "gbdcs/sim/fixture_renderer.hpp"
#include "gbdcs/sim/hand_scene.hpp"
#include "gbdcs/sim/recipe.hpp"
#include "gbdcs/sim/video_recorder.hpp"

namespace gbdcs::app {
namespace {

namespace fs = std::filesystem;

// Bump when the renderer or the pose library changes what a recipe renders to (invalidates
// caches: the key covers the recipe and hand.xml, not the code). 2: RELAXED and WAVING at the
// rest cascade.
constexpr std::string_view kRendererVersion = "fixture-renderer/2";

std::uint64_t fnv1a(std::string_view text, std::uint64_t h = 1469598103934665603ULL) {
  for (unsigned char c : text) {
    h ^= c;
    h *= 1099511628211ULL;
  }
  return h;
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace

void render_fixture(const fs::path& recipe_path, const fs::path& out_dir,
                    const Progress& progress) {
  sim::Recipe recipe = sim::load_recipe(recipe_path);
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (ec) throw std::runtime_error(out_dir.string() + ": cannot create the folder: " + ec.message());
  sim::FixtureRenderer renderer(recipe);
  // Per-process names: two processes may render the same recipe into the same cache at once.
  const std::string tag = "partial." + std::to_string(::getpid());
  const fs::path video_tmp = out_dir / ("video." + tag + ".mp4");
  std::vector<sim::FrameLabel> labels;
  {
    sim::VideoRecorderOptions vo;
    vo.fps = recipe.fps;
    sim::VideoRecorder video(video_tmp, cv::Size(recipe.width, recipe.height), vo);
    const auto n = renderer.frame_count();
    for (std::int64_t i = 0; i < n; ++i) {
      auto frame = renderer.frame(i);
      video.write(frame.bgr);
      labels.push_back(std::move(frame.label));
      if (progress) progress(i + 1, n);
    }
    video.close();
  }
  const fs::path labels_tmp = out_dir / ("labels." + tag + ".json");
  {
    std::ofstream out(labels_tmp, std::ios::binary);
    out << renderer.labels_json(labels).dump(1) << "\n";
    if (!out) throw std::runtime_error(labels_tmp.string() + ": cannot write (disk full?)");
  }
  // The labels last: a folder with labels.json is complete.
  fs::rename(video_tmp, out_dir / "video.mp4");
  fs::rename(labels_tmp, out_dir / "labels.json");
}

fs::path cached_fixture(const fs::path& recipe_path, const fs::path& cache_dir,
                        const Progress& progress) {
  const sim::Recipe recipe = sim::load_recipe(recipe_path);
  std::uint64_t h = fnv1a(sim::to_json(recipe).dump());
  h = fnv1a(read_text(sim::default_hand_model_path()), h);
  h = fnv1a(kRendererVersion, h);
  char hex[17];
  std::snprintf(hex, sizeof(hex), "%016llx", static_cast<unsigned long long>(h));
  const fs::path dir = cache_dir / (recipe_path.stem().string() + "-" + std::string(hex, 12));
  if (fs::exists(dir / "labels.json") && fs::exists(dir / "video.mp4")) return dir;
  render_fixture(recipe_path, dir, progress);
  return dir;
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
