// gbdcs: the gesture-based drone control system, one binary with subcommands.
#include <algorithm>
#include <iostream>

#include "command_registry.hpp"
#include "commands.hpp"

namespace {
using gbdcs::app::CommandRegistration;
const CommandRegistration kVersion{10, &gbdcs::app::add_version_command};
const CommandRegistration kFly{10, &gbdcs::app::add_fly_command};
const CommandRegistration kProfile{10, &gbdcs::app::add_profile_command};
const CommandRegistration kSchema{10, &gbdcs::app::add_schema_command};
const CommandRegistration kVision{20, &gbdcs::app::add_vision_commands};
const CommandRegistration kTwin{30, &gbdcs::app::add_twin_command};
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "gbdcs - fly a drone with hand gestures (Tello, AirSim, the MuJoCo twin, or the dummy).\n"
      "Run `gbdcs SUBCOMMAND --help` for each subcommand's options."};
  app.require_subcommand(1);
  app.set_help_all_flag("--help-all", "Show help for every subcommand");
  auto entries = gbdcs::app::command_entries();
  std::stable_sort(entries.begin(), entries.end(),
                   [](const auto& a, const auto& b) { return a.order < b.order; });
  for (const auto& entry : entries) entry.add(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const std::exception& e) {
    std::cerr << "gbdcs: " << e.what() << "\n";
    return 1;
  }
  return gbdcs::app::g_exit_code;
}
