// gbdcs: the gesture-based drone control system, one binary with subcommands.
#include <iostream>

#include "commands.hpp"

int main(int argc, char** argv) {
  CLI::App app{
      "gbdcs - fly a drone with hand gestures (Tello, AirSim, the MuJoCo twin, or the dummy).\n"
      "Run `gbdcs SUBCOMMAND --help` for each subcommand's options."};
  app.require_subcommand(1);
  app.set_help_all_flag("--help-all", "Show help for every subcommand");
  gbdcs::app::add_version_command(app);
  gbdcs::app::add_fly_command(app);
  gbdcs::app::add_profile_command(app);
  gbdcs::app::add_schema_command(app);
  gbdcs::app::add_vision_commands(app);
  gbdcs::app::add_twin_command(app);  // after vision: it adds `bench twin` to `bench`
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
