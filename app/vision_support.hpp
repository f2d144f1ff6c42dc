// Shared by the vision subcommands (vision_commands.cpp, vision_bench_command.cpp).
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "gbdcs/vision/hand_tracker.hpp"

namespace gbdcs::app {

struct ModelChoice {
  std::string model = "full";  // lite | full
  std::string model_dir;       // empty: $GBDCS_MODEL_DIR or the build tree's models folder
};

inline void add_model_options(CLI::App* cmd, ModelChoice& m) {
  cmd->add_option("--model", m.model, "Hand models: lite or full")
      ->capture_default_str()
      ->check(CLI::IsMember({"lite", "full"}));
  cmd->add_option("--model-dir", m.model_dir,
                  "Folder of the .tflite models (default: $GBDCS_MODEL_DIR, else the build "
                  "tree's models/, filled by ci/fetch-models)");
}

inline vision::TrackerOptions tracker_options(const ModelChoice& m, bool static_images) {
  vision::TrackerOptions o;
  o.full_model = m.model == "full";
  o.model_dir = m.model_dir;
  o.static_images = static_images;
  return o;
}

void add_bench_vision_command(CLI::App& bench);

}  // namespace gbdcs::app
