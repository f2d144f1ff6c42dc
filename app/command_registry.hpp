// Subcommands register themselves, so adding one is one new file in app/ and no shared list:
//
//   namespace { const gbdcs::app::CommandRegistration kServe{50, &add_serve_command}; }
//
// main() calls every registration in ascending `order` (ties: in registration order, which
// across files is unspecified). Orders in use: 10 version/fly/profile/schema, 20 vision, 30
// twin. Groups shared by several files (`bench`, `eval`) are reached with group_command(),
// which creates the group the first time, so order does not matter for them.
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <utility>
#include <vector>

namespace gbdcs::app {

using AddCommand = void (*)(CLI::App&);

struct CommandEntry {
  int order;
  AddCommand add;
};

// Function-local static: safe to use from other translation units' static initialisers.
inline std::vector<CommandEntry>& command_entries() {
  static std::vector<CommandEntry> entries;
  return entries;
}

struct CommandRegistration {
  CommandRegistration(int order, AddCommand add) { command_entries().push_back({order, add}); }
};

// The subcommand `name` of app (e.g. "bench"), created with `description` if it is not there
// yet. A new group requires one of its subcommands.
inline CLI::App* group_command(CLI::App& app, const std::string& name,
                               const std::string& description) {
  auto found = app.get_subcommands([&](CLI::App* a) { return a->get_name() == name; });
  if (!found.empty()) return found.front();
  auto* group = app.add_subcommand(name, description);
  group->require_subcommand(1);
  return group;
}

}  // namespace gbdcs::app
