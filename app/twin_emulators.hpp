// `gbdcs twin --tello/--airsim/--xfly`: the twin served over the real protocols
// (twin_emulators_command.cpp). twin_command.cpp adds these options to `gbdcs twin` and hands
// over when one of them is given.
#pragma once

#include <CLI/CLI.hpp>

namespace gbdcs::app {

void add_twin_emulator_options(CLI::App* twin);
bool twin_emulators_requested();
int run_twin_emulators();

}  // namespace gbdcs::app
