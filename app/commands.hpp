// Subcommands of the gbdcs binary. Each registers itself on the CLI11 app and returns the
// exit code through the callback it installs.
#pragma once

#include <CLI/CLI.hpp>

namespace gbdcs::app {

// Set by the subcommand that ran.
inline int g_exit_code = 0;

void add_version_command(CLI::App& app);
void add_fly_command(CLI::App& app);
void add_profile_command(CLI::App& app);
void add_schema_command(CLI::App& app);
// vision, recognize, bench (vision), eval (landmarks): vision_commands.cpp
void add_vision_commands(CLI::App& app);
// twin, bench twin: twin_command.cpp (registered after add_vision_commands)
void add_twin_command(CLI::App& app);

}  // namespace gbdcs::app
