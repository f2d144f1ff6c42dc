// Small subcommands: version, profile, schema.
#include <fstream>
#include <iostream>
#include <sstream>

#include "commands.hpp"
#include "gbdcs/contracts/codec.hpp"
#include "gbdcs/control/command_translator.hpp"

namespace gbdcs::app {

void add_version_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("version", "Print the version of gbdcs");
  cmd->callback([] { std::cout << "gbdcs " << GBDCS_VERSION << "\n"; });
}

void add_profile_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("profile", "Show or check a gesture -> command profile");
  cmd->require_subcommand(1);
  auto* show = cmd->add_subcommand("show", "Print the built-in default profile as JSON");
  show->callback([] {
    std::cout << control::GestureProfile::builtin_default().to_json().dump(2) << "\n";
  });
  auto* check = cmd->add_subcommand("check", "Check a profile file; prints the first error");
  static std::string path;
  check->add_option("FILE", path, "Profile JSON file")->required();
  check->callback([] {
    try {
      auto p = control::GestureProfile::load_file(path);
      std::cout << path << ": ok, profile '" << p.name << "' maps " << p.mappings.size()
                << " gestures\n";
    } catch (const control::ProfileError& e) {
      std::cerr << e.what() << "\n";
      g_exit_code = 2;
    }
  });
}

void add_schema_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("schema", "List the message schemas or validate a JSON file");
  cmd->require_subcommand(1);
  auto* list = cmd->add_subcommand("list", "List the schema names");
  list->callback([] {
    for (const auto& n : contracts::schema_names()) std::cout << n << "\n";
  });
  auto* validate = cmd->add_subcommand("validate", "Validate a JSON file against a schema");
  static std::string name;
  static std::string file;
  validate->add_option("SCHEMA", name, "Schema name (see `gbdcs schema list`)")->required();
  validate->add_option("FILE", file, "JSON file")->required();
  validate->callback([] {
    std::ifstream in(file);
    if (!in) {
      std::cerr << file << ": cannot read (check the path)\n";
      g_exit_code = 2;
      return;
    }
    std::stringstream text;
    text << in.rdbuf();
    try {
      auto doc = contracts::parse_json(text.str());
      auto problems = contracts::violations(name, doc);
      if (problems.empty()) {
        std::cout << file << ": valid " << name << "\n";
        return;
      }
      for (const auto& p : problems) std::cerr << file << ": " << p << "\n";
      g_exit_code = 1;
    } catch (const std::exception& e) {
      std::cerr << file << ": " << e.what() << "\n";
      g_exit_code = 2;
    }
  });
}

}  // namespace gbdcs::app
